// The clear-coat, sheen and specular textures' texels at a point, each
// channel as hikari_core::texture::LayerTextures::apply reads it (1 where
// the surface lacks that texture or the point has no coordinates): the
// G-buffer's fifth target keeps them (`pack_layer_texels`, 16 bits a
// factor, 10 a colour channel; layer_texels.rs is the Rust half), and
// `with_layer_texels` multiplies a surface's factors by them.

struct LayerTexels {
    clearcoat: f32,
    clearcoat_roughness: f32,
    sheen_roughness: f32,
    specular: f32,
    sheen_color: vec3<f32>,
    specular_color: vec3<f32>,
}

fn no_layer_texels() -> LayerTexels {
    return LayerTexels(1.0, 1.0, 1.0, 1.0, vec3<f32>(1.0), vec3<f32>(1.0));
}

fn pack_unorm10x3(c: vec3<f32>) -> u32 {
    let q = vec3<u32>(round(clamp(c, vec3<f32>(0.0), vec3<f32>(1.0)) * 1023.0));
    return q.x | (q.y << 10u) | (q.z << 20u);
}

fn unpack_unorm10x3(w: u32) -> vec3<f32> {
    return vec3<f32>(f32(w & 1023u), f32((w >> 10u) & 1023u), f32((w >> 20u) & 1023u)) / 1023.0;
}

fn pack_layer_texels(t: LayerTexels) -> vec4<u32> {
    return vec4<u32>(
        pack2x16unorm(vec2<f32>(t.clearcoat, t.clearcoat_roughness)),
        pack2x16unorm(vec2<f32>(t.sheen_roughness, t.specular)),
        pack_unorm10x3(t.sheen_color),
        pack_unorm10x3(t.specular_color),
    );
}

fn unpack_layer_texels(w: vec4<u32>) -> LayerTexels {
    let coat = unpack2x16unorm(w.x);
    let sheen_specular = unpack2x16unorm(w.y);
    return LayerTexels(coat.x, coat.y, sheen_specular.x, sheen_specular.y, unpack_unorm10x3(w.z),
        unpack_unorm10x3(w.w));
}

// Surface `s` with its layer factors times the texels `t`, clamped as
// LayerTextures::apply clamps them (Bsdf::with_specular_color: a colour
// of at least 0).
fn with_layer_texels(s: Surface, t: LayerTexels) -> Surface {
    var out = s;
    out.clearcoat = clamp(s.clearcoat * t.clearcoat, 0.0, 1.0);
    out.clearcoat_roughness = clamp(s.clearcoat_roughness * t.clearcoat_roughness, 0.0, 1.0);
    out.sheen_color = s.sheen_color * t.sheen_color;
    out.sheen_roughness = clamp(s.sheen_roughness * t.sheen_roughness, 0.0, 1.0);
    out.specular_factor = clamp(s.specular_factor * t.specular, 0.0, 1.0);
    out.specular_color = max(s.specular_color * t.specular_color, vec3<f32>(0.0));
    return out;
}

// Surface `s` as seen at a G-buffer pixel whose fifth target holds `words`:
// its layer textures applied where it has some (LAYERED scenes only).
fn pixel_surface(s: Surface, words: vec4<u32>) -> Surface {
    if (!LAYERED || s.layer_textures == 0xffffffffu) {
        return s;
    }
    return with_layer_texels(s, unpack_layer_texels(words));
}

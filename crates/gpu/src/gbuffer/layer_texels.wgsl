// The clear-coat, sheen and specular textures' texels at a point, each
// channel as hikari_core::texture::LayerTextures::apply reads it (1 where
// the surface lacks that texture or the point has no coordinates), and the
// coat's own normal (clearcoatNormalTexture) in the shading frame: the
// G-buffer's fifth target keeps them (`pack_layer_texels`: 8 bits a
// factor, as the images hold them; the coat normal's x and y at 16; 10
// bits a colour channel; layer_texels.rs is the Rust half),
// `with_layer_texels` multiplies a surface's factors by them and
// `pixel_coat` turns a pixel's coat.

struct LayerTexels {
    clearcoat: f32,
    clearcoat_roughness: f32,
    sheen_roughness: f32,
    specular: f32,
    sheen_color: vec3<f32>,
    specular_color: vec3<f32>,
    // +z: the base's normal.
    coat_normal: vec3<f32>,
    // The coat lies on the unbent normal over a normal texture (no texture
    // of its own tilts it: Bsdf::with_unbent_coat).
    coat_unbent: bool,
}

// The sheen colour word's bit marking `coat_unbent`.
const COAT_UNBENT_BIT: u32 = 0x40000000u;

fn no_layer_texels() -> LayerTexels {
    return LayerTexels(1.0, 1.0, 1.0, 1.0, vec3<f32>(1.0), vec3<f32>(1.0), vec3<f32>(0.0, 0.0, 1.0), false);
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
        pack4x8unorm(vec4<f32>(t.clearcoat, t.clearcoat_roughness, t.sheen_roughness, t.specular)),
        pack2x16snorm(t.coat_normal.xy),
        pack_unorm10x3(t.sheen_color) | select(0u, COAT_UNBENT_BIT, t.coat_unbent),
        pack_unorm10x3(t.specular_color),
    );
}

// The coat normal of the target's second word: z from x and y (≥ 0).
fn unpack_coat_normal(w: u32) -> vec3<f32> {
    let xy = unpack2x16snorm(w);
    return vec3<f32>(xy, sqrt(max(1.0 - dot(xy, xy), 0.0)));
}

fn unpack_layer_texels(w: vec4<u32>) -> LayerTexels {
    let factors = unpack4x8unorm(w.x);
    return LayerTexels(factors.x, factors.y, factors.z, factors.w, unpack_unorm10x3(w.z), unpack_unorm10x3(w.w),
        unpack_coat_normal(w.y), (w.z & COAT_UNBENT_BIT) != 0u);
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

// The BRDF `b` of surface `s` at a G-buffer pixel whose fifth target holds
// `words`: its coat on the coat's own normal there (LAYERED scenes only;
// +z, the base's, but where a clearcoatNormalTexture bends it).
fn pixel_coat(b: Bsdf, s: Surface, words: vec4<u32>) -> Bsdf {
    if (!LAYERED || s.layer_textures == 0xffffffffu || words.y == 0u) {
        return b;
    }
    if ((words.z & COAT_UNBENT_BIT) != 0u) {
        return with_unbent_coat(b, unpack_coat_normal(words.y));
    }
    return with_coat_normal(b, unpack_coat_normal(words.y));
}

// A surface at one point, its textures applied: hikari_core::texture::
// Texturing::apply (base colour, metallic, roughness), opaque_at (MASK)
// and emission_scale (the emissive texture), in one lookup of each texture.
// `uv` is the point's texture coordinates (xy) and z = 1 where the
// primitive has them (z = 0: the factors alone, as on the CPU); `dx` and
// `dy` its change to the next pixel (zero: level 0, as the CPU reads).

struct SurfacePoint {
    base: vec3<f32>,
    metallic: f32,
    emission: vec3<f32>,
    roughness: f32,
    opaque: bool,
}

struct TextureLookup {
    value: vec4<f32>,
    found: bool,
}

fn texture_lookup(t: u32, uv: vec3<f32>, dx: vec2<f32>, dy: vec2<f32>) -> TextureLookup {
    if (t == NO_TEXTURE || uv.z == 0.0) {
        return TextureLookup(vec4<f32>(1.0), false);
    }
    if (all(dx == vec2<f32>(0.0)) && all(dy == vec2<f32>(0.0))) {
        return TextureLookup(sample_texture(t, uv.xy), true);
    }
    return TextureLookup(sample_texture_footprint(t, uv.xy, dx, dy), true);
}

// TEXTURED and CUT_OUTS (features.wgsl) leave out what no surface has.
fn surface_point(s: Surface, uv: vec3<f32>, dx: vec2<f32>, dy: vec2<f32>) -> SurfacePoint {
    var p = SurfacePoint(s.albedo, s.metallic, s.emission, s.roughness, true);
    if (!TEXTURED) {
        p.opaque = !CUT_OUTS || s.alpha_cutoff < 0.0 || s.alpha_factor >= s.alpha_cutoff;
        return p;
    }
    let base = texture_lookup(s.base_color_texture, uv, dx, dy);
    p.base *= base.value.rgb;
    if (CUT_OUTS && s.alpha_cutoff >= 0.0) {
        p.opaque = s.alpha_factor * base.value.a >= s.alpha_cutoff;
    }
    let mr = texture_lookup(s.metallic_roughness_texture, uv, dx, dy);
    if (mr.found) {
        p.metallic = clamp(p.metallic * mr.value.b, 0.0, 1.0);
        p.roughness = clamp(p.roughness * mr.value.g, 0.0, 1.0);
    }
    let emission = texture_lookup(s.emissive_texture, uv, dx, dy);
    if (emission.found) {
        p.emission = s.emission_per_texel * emission.value.rgb;
    }
    return p;
}

// Metallic and roughness in one f32 of the G-buffer (emission.w), 12 bits
// each, exact as an integer-valued float. Read back (bsdf.wgsl's
// `pixel_bsdf`) only for surfaces with a metallic–roughness texture: the
// others' come from `Surface` unrounded.
fn pack_metal_rough(metallic: f32, roughness: f32) -> f32 {
    return f32(u32(round(metallic * 4095.0)) * 4096u + u32(round(roughness * 4095.0)));
}

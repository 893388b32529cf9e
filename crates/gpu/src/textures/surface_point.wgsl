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

// The surface has a normal texture and the point coordinates to read it at.
fn reads_normal_texture(s: Surface, uv: vec3<f32>) -> bool {
    return TEXTURED && s.normal_texture != NO_TEXTURE && uv.z != 0.0;
}

// The shading normal `n` bent by the surface's normal texture:
// hikari_core::texture::Texturing::shading_normal, its tangent frame here
// solved from the fragment's derivatives (`px`, `py` of the position, `dx`,
// `dy` of the coordinates): both are affine over a triangle, so dp/du and
// dp/dv come out as the triangle's own. The coordinates' change is taken
// through the texture's transform, as the CPU's is.
fn bent_normal(
    s: Surface,
    uv: vec3<f32>,
    dx: vec2<f32>,
    dy: vec2<f32>,
    px: vec3<f32>,
    py: vec3<f32>,
    n: vec3<f32>,
) -> vec3<f32> {
    if (!reads_normal_texture(s, uv)) {
        return n;
    }
    return bend_by_texel(s, texture_lookup(s.normal_texture, uv, dx, dy).value, dx, dy, px, py, n);
}

// `bent_normal` at a ray's hit on a triangle of corner coordinates' deltas
// `du1`, `du2` along its edges `e1`, `e2` (the same frame: the triangle's
// own dp/du and dp/dv), the texel read at level 0 as the CPU reads it.
fn bent_normal_at_hit(
    s: Surface,
    uv: vec3<f32>,
    du1: vec2<f32>,
    du2: vec2<f32>,
    e1: vec3<f32>,
    e2: vec3<f32>,
    n: vec3<f32>,
) -> vec3<f32> {
    if (!reads_normal_texture(s, uv)) {
        return n;
    }
    let texel = texture_lookup(s.normal_texture, uv, vec2<f32>(0.0), vec2<f32>(0.0)).value;
    return bend_by_texel(s, texel, du1, du2, e1, e2, n);
}

// `n` bent by the normal texture's `texel`, in the tangent frame whose
// position changes `px`, `py` go with coordinate changes `dx`, `dy`.
fn bend_by_texel(
    s: Surface,
    texel: vec4<f32>,
    dx: vec2<f32>,
    dy: vec2<f32>,
    px: vec3<f32>,
    py: vec3<f32>,
    n: vec3<f32>,
) -> vec3<f32> {
    let local = vec3<f32>(
        (2.0 * texel.x - 1.0) * s.normal_scale,
        (2.0 * texel.y - 1.0) * s.normal_scale,
        2.0 * texel.z - 1.0,
    );
    let header = texture_header(s.normal_texture);
    var linear = mat2x2<f32>(vec2<f32>(1.0, 0.0), vec2<f32>(0.0, 1.0));
    if ((texture_data[header + 3u] & TEXTURE_TRANSFORMED) != 0u) {
        linear = texture_linear(header);
    }
    let d1 = linear * dx;
    let d2 = linear * dy;
    let det = d1.x * d2.y - d2.x * d1.y;
    if (abs(det) < 1e-20) {
        return n;
    }
    let tangent = (px * d2.y - py * d1.y) / det;
    let bitangent = (py * d1.x - px * d2.x) / det;
    // Gram–Schmidt against the shading normal; the bitangent keeps the side
    // the coordinates give it (mirrored textures). Normalised as glam's
    // normalize_or_zero (× the reciprocal length), so the tracer keeps the
    // CPU tracer's bits.
    let t_raw = tangent - n * dot(n, tangent);
    let t_recip = 1.0 / sqrt(dot(t_raw, t_raw));
    if (!(t_recip > 0.0) || t_recip > 3.0e38) {
        return n;
    }
    let t_axis = t_raw * t_recip;
    let handed = select(1.0, -1.0, dot(cross(n, t_axis), bitangent) < 0.0);
    let b_axis = cross(n, t_axis) * handed;
    let bent = t_axis * local.x + b_axis * local.y + n * local.z;
    let b_recip = 1.0 / sqrt(dot(bent, bent));
    if (!(b_recip > 0.0) || b_recip > 3.0e38) {
        return n;
    }
    return bent * b_recip;
}

// Metallic and roughness in one f32 of the G-buffer (emission.w), 12 bits
// each, exact as an integer-valued float. Read back (bsdf.wgsl's
// `pixel_bsdf`) only for surfaces with a metallic–roughness texture: the
// others' come from `Surface` unrounded.
fn pack_metal_rough(metallic: f32, roughness: f32) -> f32 {
    return f32(u32(round(metallic * 4095.0)) * 4096u + u32(round(roughness * 4095.0)));
}

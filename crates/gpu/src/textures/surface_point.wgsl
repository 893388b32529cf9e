// A surface at one point, its textures applied: hikari_core::texture::
// Texturing::apply (base colour, metallic, roughness), the alpha is_there_at
// reads (`is_there` decides with it)
// and emission_scale (the emissive texture), in one lookup of each texture.
// `uv` is the point's texture coordinates (xy) and z = 1 where the
// primitive has them (z = 0: the factors alone, as on the CPU); `dx` and
// `dy` its change to the next pixel (zero: level 0, as the CPU reads).

struct SurfacePoint {
    base: vec3<f32>,
    metallic: f32,
    emission: vec3<f32>,
    roughness: f32,
    // The base colour's alpha (factor × texture), for `is_there`.
    alpha: f32,
    // The share let through as glass (`Surface::transmission` × the
    // texture's R; 0: none), which `draw_layer` draws.
    transmission: f32,
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
    var p = SurfacePoint(s.albedo, s.metallic, s.emission, s.roughness, s.alpha_factor, s.transmission);
    if (!TEXTURED) {
        return p;
    }
    if (MIXED && s.transmission > 0.0) {
        p.transmission *= texture_lookup(s.transmission_texture, uv, dx, dy).value.r;
    }
    let base = texture_lookup(s.base_color_texture, uv, dx, dy);
    p.base *= base.value.rgb;
    p.alpha *= base.value.a;
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

// The clear-coat, sheen and specular textures' texels at the point
// (Texturing::apply's `LayerTextures::apply`), from the first six
// references at `s.layer_textures` (textures/mod.rs's layer-texture
// tables); the coat normal is the caller's (`coat_normal`, `coat_normal_at_hit`).
fn layer_texels(s: Surface, uv: vec3<f32>, dx: vec2<f32>, dy: vec2<f32>) -> LayerTexels {
    var t = no_layer_texels();
    if (!LAYERED || s.layer_textures == NO_TEXTURE || uv.z == 0.0) {
        return t;
    }
    let table = s.layer_textures;
    t.clearcoat = texture_lookup(texture_data[table], uv, dx, dy).value.r;
    t.clearcoat_roughness = texture_lookup(texture_data[table + 1u], uv, dx, dy).value.g;
    t.sheen_color = texture_lookup(texture_data[table + 2u], uv, dx, dy).value.rgb;
    t.sheen_roughness = texture_lookup(texture_data[table + 3u], uv, dx, dy).value.a;
    t.specular = texture_lookup(texture_data[table + 4u], uv, dx, dy).value.a;
    t.specular_color = texture_lookup(texture_data[table + 5u], uv, dx, dy).value.rgb;
    return t;
}

// scene_upload::ALPHA_BLEND: the cut-off of an alphaMode BLEND surface.
const ALPHA_BLEND: f32 = 2.0;

// hikari_core::texture::AlphaMode::is_there: whether surface `s` of alpha
// `alpha` is there for a ray (or fragment) of BLEND threshold `u`: always
// where opaque (a negative cut-off), where alpha reaches a MASK's cut-off,
// with probability alpha for BLEND.
fn is_there(s: Surface, alpha: f32, u: f32) -> bool {
    if (!CUT_OUTS || s.alpha_cutoff < 0.0) {
        return true;
    }
    if (s.alpha_cutoff == ALPHA_BLEND) {
        return alpha > u;
    }
    return alpha >= s.alpha_cutoff;
}

// hikari_core::texture::blend_threshold: a BLEND surface's threshold for
// the ray from `o` along `d` at primitive `prim`, a hash of the ray's bits.
fn blend_threshold(o: vec3<f32>, d: vec3<f32>, prim: u32) -> f32 {
    var h = hash_u32(prim ^ 0x2545f491u);
    h = hash_u32(h ^ bitcast<u32>(o.x));
    h = hash_u32(h ^ bitcast<u32>(o.y));
    h = hash_u32(h ^ bitcast<u32>(o.z));
    h = hash_u32(h ^ bitcast<u32>(d.x));
    h = hash_u32(h ^ bitcast<u32>(d.y));
    h = hash_u32(h ^ bitcast<u32>(d.z));
    return f32(h >> 8u) * (1.0 / 16777216.0);
}

// `is_there` for the ray from `o` along `d` at BVH primitive `source`
// (its index in Accel's joint primitive space), hashing the ray only for
// BLEND surfaces.
fn is_there_for_ray(s: Surface, alpha: f32, o: vec3<f32>, d: vec3<f32>, source: u32) -> bool {
    if (CUT_OUTS && s.alpha_cutoff == ALPHA_BLEND) {
        return alpha > blend_threshold(o, d, source);
    }
    return is_there(s, alpha, 0.0);
}

// `is_there` for a rasterized fragment at `position` (its
// `@builtin(position)`) in a drawing of BLEND seed `seed`.
fn is_there_for_fragment(s: Surface, alpha: f32, position: vec4<f32>, seed: u32) -> bool {
    if (CUT_OUTS && s.alpha_cutoff == ALPHA_BLEND) {
        return alpha > fragment_blend_threshold(position, seed);
    }
    return is_there(s, alpha, 0.0);
}

// A rasterized fragment's BLEND threshold: a hash of its window position
// and depth (`@builtin(position)`, the same in every draw of it) and a
// seed that changes from pass to pass, so each pass decides afresh and
// layers behind one another independently. No CPU twin: the CPU decides
// by the eye ray (`blend_threshold`); both are uniform.
fn fragment_blend_threshold(position: vec4<f32>, seed: u32) -> f32 {
    var h = hash_u32(seed ^ 0x68e31da4u);
    h = hash_u32(h ^ bitcast<u32>(position.x));
    h = hash_u32(h ^ bitcast<u32>(position.y));
    h = hash_u32(h ^ bitcast<u32>(position.z));
    return f32(h >> 8u) * (1.0 / 16777216.0);
}

// The surface has a normal texture and the point coordinates to read it at.
fn reads_normal_texture(s: Surface, uv: vec3<f32>) -> bool {
    return TEXTURED && s.normal_texture != NO_TEXTURE && uv.z != 0.0;
}

// The shading normal `n` bent by the surface's normal texture, seen along
// `dir` on a surface of geometric normal `ng`: hikari_core::scene::Scene::
// shading_normal_at. Its frame is the
// fragment's interpolated `tangent` (xyz; w the side of its triangle's
// first corner) where the triangle has stored tangents, else solved from
// the fragment's derivatives (`px`, `py` of the position, `dx`, `dy` of the
// coordinates): both are affine over a triangle, so dp/du and dp/dv come
// out as the triangle's own.
fn bent_normal(
    s: Surface,
    uv: vec3<f32>,
    dx: vec2<f32>,
    dy: vec2<f32>,
    px: vec3<f32>,
    py: vec3<f32>,
    tangent: vec4<f32>,
    n: vec3<f32>,
    ng: vec3<f32>,
    dir: vec3<f32>,
) -> vec3<f32> {
    if (!reads_normal_texture(s, uv)) {
        return n;
    }
    let axes = fragment_uv_axes(dx, dy, px, py, tangent, n);
    let bent = bend_by_texel(s, texture_lookup(s.normal_texture, uv, dx, dy).value, axes, n);
    return lifted_for_view(bent, n, ng, dir);
}

// A fragment's texture frame: its interpolated `tangent` (w its triangle's
// side) where the triangle has stored tangents, else solved from the
// fragment's derivatives.
fn fragment_uv_axes(dx: vec2<f32>, dy: vec2<f32>, px: vec3<f32>, py: vec3<f32>, tangent: vec4<f32>, n: vec3<f32>) -> UvAxes {
    let stored = stored_uv_axes(tangent.xyz, tangent.w, n);
    if (stored.found) {
        return stored;
    }
    return derived_uv_axes(dx, dy, px, py);
}

// The texture frame at a ray's hit on BVH primitive `prim` (barycentrics
// `b`, edges `e1`, `e2`): its stored tangents interpolated, else the frame
// of its corners' coordinates.
fn hit_uv_axes(prim: u32, b: vec2<f32>, e1: vec3<f32>, e2: vec3<f32>, n: vec3<f32>) -> UvAxes {
    let t = primitive_corner_tangents(prim);
    let tangent = t.t0.xyz * (1.0 - b.x - b.y) + t.t1.xyz * b.x + t.t2.xyz * b.y;
    let stored = stored_uv_axes(tangent, t.t0.w, n);
    if (stored.found) {
        return stored;
    }
    let edges = primitive_uv_edges(prim);
    return derived_uv_axes(edges.xy, edges.zw, e1, e2);
}

// Surface `s`'s clearcoatNormalTexture (the seventh word of its layer
// table; NO_TEXTURE: none) and its scale (the eighth, as f32 bits).
fn coat_normal_texture(s: Surface) -> u32 {
    if (!LAYERED || s.layer_textures == NO_TEXTURE) {
        return NO_TEXTURE;
    }
    return texture_data[s.layer_textures + 6u];
}

fn coat_normal_scale(s: Surface) -> f32 {
    return bitcast<f32>(texture_data[s.layer_textures + 7u]);
}

// The surface's coat lies apart from its base's shading normal at a point
// of coordinates `uv` (MaterialTextures::coat_apart): a layer table, and
// a clear-coat normal texture or a normal texture (a coat over a normal
// texture lies on the unbent normal).
fn coat_apart(s: Surface, uv: vec3<f32>) -> bool {
    // Parenthesised: WGSL (Chromium's compiler, unlike naga) refuses && and || mixed bare.
    return (coat_normal_texture(s) != NO_TEXTURE && uv.z != 0.0)
        || (LAYERED && s.layer_textures != NO_TEXTURE && reads_normal_texture(s, uv));
}

// The BRDF `b` of surface `s` with its coat apart on `n` (shading frame;
// Scene::coat_tilted): tilted by its own texture, or lying on the unbent
// normal over a normal texture.
fn with_coat_apart(b: Bsdf, s: Surface, n: vec3<f32>) -> Bsdf {
    if (coat_normal_texture(s) != NO_TEXTURE) {
        return with_coat_normal(b, n);
    }
    return with_unbent_coat(b, n);
}

// The clear coat's own normal at a fragment (`bent_normal`'s arguments):
// the unbent `n` bent by the coat normal texture and lifted for the view
// (hikari_core::texture::Texturing::coat_normal and Scene::coat_tilted);
// `n` where the surface has none (a coat over a normal texture).
fn coat_normal(
    s: Surface,
    uv: vec3<f32>,
    dx: vec2<f32>,
    dy: vec2<f32>,
    px: vec3<f32>,
    py: vec3<f32>,
    tangent: vec4<f32>,
    n: vec3<f32>,
    ng: vec3<f32>,
    dir: vec3<f32>,
) -> vec3<f32> {
    if (coat_normal_texture(s) == NO_TEXTURE || uv.z == 0.0) {
        return n;
    }
    let axes = fragment_uv_axes(dx, dy, px, py, tangent, n);
    let t = coat_normal_texture(s);
    let bent = bend_by(t, coat_normal_scale(s), texture_lookup(t, uv, dx, dy).value, axes, n);
    return lifted_for_view(bent, n, ng, dir);
}

// Scene::shading_normal_at's last step: the bent normal lifted where the
// eye, looking along `dir`, would see it reflect below the surface of
// geometric normal `ng`; `n` (unbent) where the texture did not bend it.
fn lifted_for_view(bent: vec3<f32>, n: vec3<f32>, ng: vec3<f32>, dir: vec3<f32>) -> vec3<f32> {
    if (all(bent == n)) {
        return bent;
    }
    let facing = select(-1.0, 1.0, dot(dir, ng) < 0.0);
    return valid_reflection_normal(ng * facing, -dir, bent * facing) * facing;
}

// hikari_core::texture::valid_reflection_normal (Cycles'
// ensure_valid_specular_reflection).
fn valid_reflection_normal(ng: vec3<f32>, wo: vec3<f32>, n: vec3<f32>) -> vec3<f32> {
    let reflected = 2.0 * dot(n, wo) * n - wo;
    let iz = dot(wo, ng);
    let threshold = min(0.9 * iz, 0.01);
    if (dot(reflected, ng) >= threshold) {
        return n;
    }
    // glam's try_normalize, else n.
    let x_raw = n - dot(n, ng) * ng;
    let recip = 1.0 / sqrt(dot(x_raw, x_raw));
    var x = n;
    if (recip > 0.0 && recip <= F32_MAX) {
        x = x_raw * recip;
    }
    let ix = dot(wo, x);
    let a = ix * ix + iz * iz;
    if (!(a > 0.0)) {
        return ng;
    }
    let b = 2.0 * (a + iz * threshold);
    let c = (threshold + iz) * (threshold + iz);
    let root = sqrt(max(b * b - 4.0 * a * c, 0.0));
    let z2 = select(0.25 * (b - root) / a, 0.25 * (b + root) / a, ix < 0.0);
    return x * sqrt(max(1.0 - z2, 0.0)) + ng * sqrt(max(z2, 0.0));
}

// `bent_normal` at a ray's hit (travelling along `dir`) on BVH primitive
// `prim` (barycentrics `b`, edges `e1`, `e2`, geometric normal `ng`): its
// stored tangents interpolated, else the frame of its corners'
// coordinates; the texel read at level 0 as the CPU reads it.
fn bent_normal_at_hit(
    s: Surface,
    uv: vec3<f32>,
    prim: u32,
    b: vec2<f32>,
    e1: vec3<f32>,
    e2: vec3<f32>,
    n: vec3<f32>,
    ng: vec3<f32>,
    dir: vec3<f32>,
) -> vec3<f32> {
    if (!reads_normal_texture(s, uv)) {
        return n;
    }
    let axes = hit_uv_axes(prim, b, e1, e2, n);
    let texel = texture_lookup(s.normal_texture, uv, vec2<f32>(0.0), vec2<f32>(0.0)).value;
    return lifted_for_view(bend_by_texel(s, texel, axes, n), n, ng, dir);
}

// `coat_normal` at a ray's hit (`bent_normal_at_hit`'s arguments; `n` unbent).
fn coat_normal_at_hit(
    s: Surface,
    uv: vec3<f32>,
    prim: u32,
    b: vec2<f32>,
    e1: vec3<f32>,
    e2: vec3<f32>,
    n: vec3<f32>,
    ng: vec3<f32>,
    dir: vec3<f32>,
) -> vec3<f32> {
    if (coat_normal_texture(s) == NO_TEXTURE || uv.z == 0.0) {
        return n;
    }
    let axes = hit_uv_axes(prim, b, e1, e2, n);
    let texture = coat_normal_texture(s);
    let texel = texture_lookup(texture, uv, vec2<f32>(0.0), vec2<f32>(0.0)).value;
    return lifted_for_view(bend_by(texture, coat_normal_scale(s), texel, axes, n), n, ng, dir);
}

// The largest finite f32 (f32::MAX): `x <= F32_MAX` is Rust's is_finite for
// a number. Written 3.4028234e38, which rounds to it: Chromium's WGSL
// compiler refuses f32::MAX's own shortest decimal, 3.4028235e38, as
// beyond f32 (naga takes both).
const F32_MAX: f32 = 3.4028234e38;

// hikari_core::texture::UvAxes: the directions of growing u and of the
// image's up (−v), unnormalised; `found` false where there is no frame.
struct UvAxes {
    tangent: vec3<f32>,
    up: vec3<f32>,
    found: bool,
}

// hikari_core::texture::stored_uv_axes: an interpolated stored tangent and
// its triangle's side.
fn stored_uv_axes(tangent: vec3<f32>, side: f32, n: vec3<f32>) -> UvAxes {
    let sign = select(1.0, -1.0, side < 0.0);
    return UvAxes(tangent, cross(n, tangent) * sign, any(tangent != vec3<f32>(0.0)));
}

// hikari_core::texture::triangle_uv_axes: the frame in which position
// changes `px`, `py` go with coordinate changes `dx`, `dy` (a triangle's
// edges, or a fragment's derivatives).
fn derived_uv_axes(dx: vec2<f32>, dy: vec2<f32>, px: vec3<f32>, py: vec3<f32>) -> UvAxes {
    let det = dx.x * dy.y - dy.x * dx.y;
    if (abs(det) < 1e-20) {
        return UvAxes(vec3<f32>(0.0), vec3<f32>(0.0), false);
    }
    let tangent = (px * dy.y - py * dx.y) / det;
    let dp_dv = (py * dx.x - px * dy.x) / det;
    return UvAxes(tangent, -dp_dv, true);
}

// hikari_core::texture::image_axes: the axes of the image texture `t`
// reads, through its transform.
fn image_axes(t: u32, axes: UvAxes) -> UvAxes {
    let header = texture_header(t);
    if ((texture_data[header + 3u] & TEXTURE_TRANSFORMED) == 0u) {
        return axes;
    }
    let m = texture_linear(header);
    let det = m[0].x * m[1].y - m[1].x * m[0].y;
    if (!(abs(det) >= 1e-20) || abs(det) > F32_MAX) {
        return UvAxes(vec3<f32>(0.0), vec3<f32>(0.0), false);
    }
    // glam's Mat2::inverse, in its order of operations.
    let inv_det = 1.0 / det;
    let inverse_x = vec2<f32>(m[1].y * inv_det, m[0].y * -inv_det);
    let inverse_y = vec2<f32>(m[1].x * -inv_det, m[0].x * inv_det);
    let dp_dv = -axes.up;
    let tangent = axes.tangent * inverse_x.x + dp_dv * inverse_x.y;
    let up = -(axes.tangent * inverse_y.x + dp_dv * inverse_y.y);
    return UvAxes(tangent, up, true);
}

// `n` bent by the normal texture's `texel` in the frame `axes` of the
// surface's coordinates: hikari_core::texture::bend, after image_axes.
fn bend_by_texel(s: Surface, texel: vec4<f32>, surface_axes: UvAxes, n: vec3<f32>) -> vec3<f32> {
    return bend_by(s.normal_texture, s.normal_scale, texel, surface_axes, n);
}

// `bend_by_texel` for the tangent-space normal texture `texture` of x and
// y scale `scale` (the base's or the clear coat's).
fn bend_by(texture: u32, scale: f32, texel: vec4<f32>, surface_axes: UvAxes, n: vec3<f32>) -> vec3<f32> {
    if (!surface_axes.found) {
        return n;
    }
    let axes = image_axes(texture, surface_axes);
    if (!axes.found) {
        return n;
    }
    let local = vec3<f32>((2.0 * texel.x - 1.0) * scale, (2.0 * texel.y - 1.0) * scale, 2.0 * texel.z - 1.0);
    // Gram–Schmidt against the shading normal; the bitangent keeps the side
    // of the image's up (mirrored textures). Normalised as glam's
    // normalize_or_zero (× the reciprocal length), so the tracer keeps the
    // CPU tracer's bits.
    let t_raw = axes.tangent - n * dot(n, axes.tangent);
    let t_recip = 1.0 / sqrt(dot(t_raw, t_raw));
    if (!(t_recip > 0.0) || t_recip > 3.0e38) {
        return n;
    }
    let t_axis = t_raw * t_recip;
    let handed = select(1.0, -1.0, dot(cross(n, t_axis), axes.up) < 0.0);
    let b_axis = cross(n, t_axis) * handed;
    let bent = t_axis * local.x + b_axis * local.y + n * local.z;
    let b_recip = 1.0 / sqrt(dot(bent, bent));
    if (!(b_recip > 0.0) || b_recip > 3.0e38) {
        return n;
    }
    return bent * b_recip;
}


// hikari_core::texture::Texturing::apply's draw where the file mixes glass
// into a glTF material (`texture::Transmission`): with probability
// p = T·(1 − m) the glass of the base's colour and roughness
// (kind 2, IOR `transmission_ior`, no absorption), else the base with
// metallic m / (1 − p). `u` is uniform in [0, 1); `probability` that of
// the drawn one (a photon stored on the base weighs 1 / it).
struct DrawnLayer {
    surface: Surface,
    point: SurfacePoint,
    probability: f32,
}

fn draw_layer(s: Surface, point: SurfacePoint, u: f32) -> DrawnLayer {
    var drawn = DrawnLayer(s, point, 1.0);
    if (!MIXED || s.kind != 0u || point.transmission <= 0.0) {
        return drawn;
    }
    let p_glass = clamp(point.transmission * (1.0 - point.metallic), 0.0, 1.0);
    if (p_glass <= 0.0) {
        return drawn;
    }
    if (u < p_glass) {
        drawn.surface = mixed_glass(s);
        drawn.probability = p_glass;
    } else {
        if (p_glass < 1.0) {
            drawn.point.metallic = min(point.metallic / (1.0 - p_glass), 1.0);
        }
        drawn.probability = 1.0 - p_glass;
    }
    return drawn;
}

// The glass mixed into surface `s` (`Transmission::glass`): its colour and
// roughness are the point's base's.
fn mixed_glass(s: Surface) -> Surface {
    var glass = s;
    glass.kind = 2u;
    glass.ior = s.transmission_ior;
    glass.specular_color = vec3<f32>(0.0);
    return glass;
}

// hikari_core::texture::mix_threshold: the uniform number that draws a
// mixed material at a hit on primitive `prim` (Accel's index, FlatPrim's
// `source`) at `x`, a hash of their bits.
fn mix_threshold(prim: u32, x: vec3<f32>) -> f32 {
    var h = hash_u32(prim ^ 0x6a09e667u);
    h = hash_u32(h ^ bitcast<u32>(x.x));
    h = hash_u32(h ^ bitcast<u32>(x.y));
    h = hash_u32(h ^ bitcast<u32>(x.z));
    return f32(h >> 8u) * (1.0 / 16777216.0);
}

// The draw for a rasterized fragment at `position` (its
// `@builtin(position)`) in a pass of seed `seed`: afresh each pass, as
// `fragment_blend_threshold` (no CPU twin: the CPU draws per hit).
fn fragment_mix_threshold(position: vec4<f32>, seed: u32) -> f32 {
    return fragment_blend_threshold(position, seed ^ 0x3c6ef372u);
}

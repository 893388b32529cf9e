// Specular surfaces seen by the camera (METHOD.md §4: the seed ray-traces
// them). For every pixel whose first surface is a mirror or glass, cast the
// same primary ray as photon-cpu, follow reflection and refraction (Fresnel,
// total internal reflection) through the scene BVH up to `max_depth`
// bounces, and shade each diffuse hit, weighted by its throughput, with
// direct light (light_eval.wgsl) and fixed-radius gathers over both photon
// maps (estimate.wgsl). Emitting surfaces add their light, rays that leave
// the scene the sky's. In media every segment of the path is attenuated
// and adds the in-scattering along it from the volume map, as photon-cpu's
// recursion does. Composed with estimate.wgsl, media.wgsl,
// light_eval.wgsl, loop_budget.wgsl, bvh.wgsl and optics.wgsl.
//
// The photon gathers can be split over several dispatches ("slices"):
// slice k reads photons k, k + S, k + 2S, … of every cell, adding to the
// pixel's sum in `accum`; direct light and emission are added by slice 0.
// Each dispatch retraces the same rays, so the sum over slices is the
// unsplit sum, and no invocation runs more than its loop budget.

struct SpecularParams {
    // First, values that stay from frame to frame: Mesa 22.3's lavapipe
    // bakes this buffer's first word into the shader at every dispatch (its
    // uniform inlining reads offset 0 of any buffer but the first), and a
    // camera value there compiled the pass anew each time the camera moved
    // (5 s a frame on showcase.glb).
    width: u32,
    height: u32,
    normal_test: u32,
    power_unit: f32,
    camera_position: vec3<f32>,
    tan_half_fov: f32,
    camera_right: vec3<f32>,
    aspect: f32,
    camera_up: vec3<f32>,
    epsilon: f32,
    camera_forward: vec3<f32>,
    max_depth: u32,
    global_radius: f32,
    global_buckets: u32,
    global_start_offset: u32,
    global_photon_offset: u32,
    caustic_radius: f32,
    caustic_buckets: u32,
    caustic_start_offset: u32,
    caustic_photon_offset: u32,
    volume_radius: f32,
    volume_buckets: u32,
    volume_start_offset: u32,
    volume_photon_offset: u32,
    // Bounds of the volume photons' positions.
    volume_min: vec3<f32>,
    // The camera's sub-pixel jitter (hikari_core::camera::Camera::jitter).
    jitter_x: f32,
    volume_max: vec3<f32>,
    jitter_y: f32,
    // Radiance of rays that leave the scene (the sky's; zero without one).
    sky_radiance: vec3<f32>,
    // Word offsets in `tables` (specular::SpecularTables).
    light_table: u32,
    sample_table: u32,
    view_table: u32,
    region_table: u32,
    environment_table: u32,
    shading_table: u32,
    _pad0: u32,
    _pad1: u32,
    _pad2: u32,
}


@group(0) @binding(0) var<uniform> params: SpecularParams;
@group(0) @binding(1) var<storage, read> nodes: array<FlatNode>;
@group(0) @binding(2) var<storage, read> prims: array<FlatPrim>;
@group(0) @binding(3) var<storage, read> surfaces: Surfaces;
// The three photon grids (global, caustic, volume) in one buffer: their
// bucket starts, then their photons (5 words each); the offsets are words.
@group(0) @binding(4) var<storage, read> grid: array<u32>;
// The lights, light samples, shadow views, region triangles and sky image,
// one after another (the readers below), so that the pass binds no more
// than WebGPU's default of 8 storage buffers.
@group(0) @binding(5) var<storage, read> tables: array<u32>;
@group(0) @binding(6) var<uniform> direct_params: DirectParams;
@group(0) @binding(10) var shadow_maps: texture_2d_array<f32>;
@group(0) @binding(11) var gbuffer_normal: texture_2d<f32>;
// Its albedo.a and emission.w: the kind and metallic the pixel drew where
// its material mixes in glass.
@group(0) @binding(18) var gbuffer_albedo: texture_2d<f32>;
@group(0) @binding(19) var gbuffer_emission: texture_2d<f32>;
@group(0) @binding(12) var output: texture_storage_2d<rgba32float, write>;
@group(0) @binding(13) var<uniform> media: MediaParams;
// Running sum over slices per pixel; w > 0 once any slice ran over budget.
@group(0) @binding(14) var<storage, read_write> accum: array<vec4<f32>>;
// [pixels over budget, most iterations one invocation ran, unused, unused].
@group(0) @binding(15) var<storage, read_write> status: array<atomic<u32>, 4>;
@group(0) @binding(16) var<uniform> slice: SliceParams;
@group(0) @binding(17) var<storage, read> texture_data: array<u32>;

fn table_word(at: u32) -> u32 {
    return tables[at];
}

// hit_normals.wgsl's vertex normals: the flat BVH's FlatShading records
// (16 words each) in the tables.
fn flat_shading(index: u32) -> FlatShading {
    let at = params.shading_table + 16u * index;
    let normals = array<vec4<f32>, 3>(table_vec4(at + 4u), table_vec4(at + 8u), table_vec4(at + 12u));
    return FlatShading(table_vec3(at), table_u32(at + 3u), normals);
}

// The tables' records (tables.wgsl), field by field as the Rust structs
// (GpuLight, GpuLightSample, ShadowViewParams, RegionTriangle) lay them out.
fn light_record(i: u32) -> Light {
    let at = params.light_table + i * 24u;
    return Light(
        table_vec3(at), table_u32(at + 3u),
        table_vec3(at + 4u), table_u32(at + 7u),
        table_vec3(at + 8u), table_u32(at + 11u),
        table_vec3(at + 12u), table_f32(at + 15u),
        table_f32(at + 16u), table_f32(at + 17u), table_u32(at + 18u), table_u32(at + 19u),
        table_u32(at + 20u), table_u32(at + 21u),
    );
}

fn light_sample(i: u32) -> LightSample {
    let at = params.sample_table + i * 12u;
    return LightSample(table_vec3(at), table_u32(at + 3u), table_vec3(at + 4u), table_u32(at + 7u), table_vec3(at + 8u), 0u);
}

fn shadow_view(i: u32) -> ShadowView {
    // ShadowViewParams: 28 words (the BLEND seed, unused here, last).
    let at = params.view_table + i * 28u;
    let clip_from_world = mat4x4<f32>(table_vec4(at), table_vec4(at + 4u), table_vec4(at + 8u), table_vec4(at + 12u));
    return ShadowView(clip_from_world, table_vec4(at + 16u), table_vec4(at + 20u), vec4<u32>(0u));
}

fn region_triangle(i: u32) -> RegionTriangle {
    let at = params.region_table + i * 16u;
    return RegionTriangle(table_vec4(at), table_vec4(at + 4u), table_vec4(at + 8u), table_vec4(at + 12u));
}

fn environment_word(i: u32) -> u32 {
    return tables[params.environment_table + i];
}

// Which slice this dispatch computes (mirrors specular::SliceParams).
struct SliceParams {
    index: u32,
    count: u32,
    iteration_budget: u32,
    // The progressive pass (from 1): seeds the pixels' random streams.
    pass_index: u32,
}

// The spatial hash of photon_grid.rs.
fn bucket_of(cell: vec3<i32>, buckets: u32) -> u32 {
    let h = (u32(cell.x) * 73856093u) ^ (u32(cell.y) * 19349663u) ^ (u32(cell.z) * 83492791u);
    return h & (buckets - 1u);
}

// Fixed-radius estimate at x from one photon grid (PhotonGrid::for_each_within),
// over this dispatch's slice of each cell's photons. A bucket shared by two
// of the 27 cells is read twice: a photon counts only from its own cell
// (which costs no loop, unlike remembering the buckets read). A glossy
// surface weights each photon by its BRDF `bsdf` seen from `eye`; a
// Lambertian one takes its base colour as its albedo. With `bent` (the
// shading normal `n` is not the geometric `ng`), each photon also weighs
// shading_normal_factor (photon-cpu's gathers) and, at a normal-mapped
// point, the bump shadowing `bump` of its side (the diffuse and sheen lobes
// alone at a glossy one). Callers pass `bent` as a
// literal in each branch of an `if`: drivers inline the call and fold the
// test out of the loop, where a per-photon test of a run-time flag cost the
// pass 13-16% on lavapipe (BENCHMARKS.md).
fn gather(x: vec3<f32>, n: vec3<f32>, ng: vec3<f32>, bent: bool, bump: BumpShadow, glossy: bool, bsdf: Bsdf, eye: vec3<f32>, radius: f32, buckets: u32, start_offset: u32, photon_offset: u32) -> vec3<f32> {
    let centre = vec3<i32>(floor(x / radius));
    var power = vec3<f32>(0.0);
    for (var k = 0u; k < 27u; k++) {
        if (!loop_iteration()) {
            break;
        }
        let cell = centre + vec3<i32>(i32(k % 3u) - 1, i32((k / 3u) % 3u) - 1, i32(k / 9u) - 1);
        let b = bucket_of(cell, buckets);
        let start = grid[start_offset + b];
        let end = grid[start_offset + b + 1u];
        for (var i = start + slice.index; i < end; i += slice.count) {
            if (!loop_iteration()) {
                break;
            }
            let base = photon_offset + 5u * i;
            let p = vec3<f32>(bitcast<f32>(grid[base]), bitcast<f32>(grid[base + 1u]), bitcast<f32>(grid[base + 2u]));
            if (any(vec3<i32>(floor(p / radius)) != cell)) {
                continue;
            }
            let d = p - x;
            let dir = decode_octahedral_15(grid[base + 4u] & 0x3fffffffu);
            if (photon_accepted(dot(d, d), dir, n, radius, params.normal_test != 0u)) {
                power += gathered_power(decode_rgb9e5(grid[base + 3u]), dir, n, ng, bent, bump, glossy, bsdf, eye);
            }
        }
    }
    if (glossy) {
        return power * (radiance_per_weighted_power(radius) * params.power_unit);
    }
    return radiance_per_power(bsdf.base_color, radius) * power * params.power_unit;
}

fn has_media() -> bool {
    return any(media.global_sigma_t > vec3<f32>(0.0)) || media.region_triangles > 0u;
}

// Transmittance from o to o + s·d: closed form for media filling the scene,
// the exact region-crossing sum otherwise.
fn transmittance_along(o: vec3<f32>, d: vec3<f32>, s: f32) -> vec3<f32> {
    if (media.region_triangles == 0u) {
        return exp(-media.global_sigma_t * s);
    }
    return exp(-segment_optical_depth(o, d, s));
}

// The photons of the volume grid in the 27 cells around `cell` whose chord
// point s_p (the point of the segment nearest the photon) lies in
// [t_enter, t_exit): hikari_core::estimate::volume_radiance_along's terms.
// The DDA below hands consecutive cells adjoining intervals, so each photon
// within r of the segment is counted once, by the cell its s_p falls in.
fn volume_cell(o: vec3<f32>, d: vec3<f32>, len: f32, cell: vec3<i32>, t_enter: f32, t_exit: f32) -> vec3<f32> {
    let r = params.volume_radius;
    let r2 = r * r;
    var sum = vec3<f32>(0.0);
    for (var k = 0u; k < 27u; k++) {
        if (!loop_iteration()) {
            break;
        }
        let neighbour = cell + vec3<i32>(i32(k % 3u) - 1, i32((k / 3u) % 3u) - 1, i32(k / 9u) - 1);
        let b = bucket_of(neighbour, params.volume_buckets);
        let start = grid[params.volume_start_offset + b];
        let end = grid[params.volume_start_offset + b + 1u];
        for (var i = start + slice.index; i < end; i += slice.count) {
            if (!loop_iteration()) {
                break;
            }
            let base = params.volume_photon_offset + 5u * i;
            let p = vec3<f32>(bitcast<f32>(grid[base]), bitcast<f32>(grid[base + 1u]), bitcast<f32>(grid[base + 2u]));
            // A bucket shared by two of the 27 cells is read twice: count a
            // photon only from its own cell (cheaper than remembering the
            // buckets read, which costs loop iterations lavapipe caps).
            if (any(vec3<i32>(floor(p / r)) != neighbour)) {
                continue;
            }
            let chord = volume_chord(o, d, len, p, r2);
            if (chord.y <= chord.x || chord.z < t_enter || chord.z >= t_exit) {
                continue;
            }
            sum += transmittance_along(o, d, chord.z) * chord_scattering(grid[base + 3u], grid[base + 4u], d, chord);
        }
    }
    return sum;
}

// In-scattered radiance reaching o along the segment o + t·d, t in [0, len]
// (photon-cpu's volume_radiance_along): the grid's cells (`volume_radius`
// wide) are walked in order along the segment (Amanatides–Woo).
fn volume_along(o: vec3<f32>, d: vec3<f32>, len: f32) -> vec3<f32> {
    if (params.volume_buckets == 0u) {
        return vec3<f32>(0.0);
    }
    let r = params.volume_radius;
    let inv = safe_inverse(d);
    // Only the part of the segment within r of the photons' bounding box
    // can gather anything: walk that part (escaping rays would otherwise
    // walk up to `max_distance`).
    let t_lo = (params.volume_min - vec3<f32>(r) - o) * inv;
    let t_hi = (params.volume_max + vec3<f32>(r) - o) * inv;
    let t_start = max(max(max(min(t_lo.x, t_hi.x), min(t_lo.y, t_hi.y)), min(t_lo.z, t_hi.z)), 0.0);
    let t_end = min(min(min(max(t_lo.x, t_hi.x), max(t_lo.y, t_hi.y)), max(t_lo.z, t_hi.z)), len);
    if (t_start > t_end) {
        return vec3<f32>(0.0);
    }
    var cell = vec3<i32>(floor((o + d * t_start) / r));
    let step = vec3<i32>(select(vec3<i32>(-1), vec3<i32>(1), d >= vec3<f32>(0.0)));
    let next_plane = (vec3<f32>(cell) + select(vec3<f32>(0.0), vec3<f32>(1.0), d >= vec3<f32>(0.0))) * r;
    var t_next = (next_plane - o) * inv;
    let t_delta = abs(inv) * r;
    // Photons whose chord point lies before t_start (or after t_end) are
    // more than r from the box, so the first and last cells take all
    // chord points on their side.
    var t_enter = -1.0;
    var sum = vec3<f32>(0.0);
    // Bounded walk: a segment crosses at most 3 · len / r + 3 cells.
    for (var n = 0u; n < 100000u; n++) {
        if (!loop_iteration()) {
            break;
        }
        let t_exit = min(t_next.x, min(t_next.y, t_next.z));
        let last = t_exit >= t_end;
        sum += volume_cell(o, d, len, cell, t_enter, select(t_exit, NO_HIT, last));
        if (last) {
            break;
        }
        t_enter = t_exit;
        if (t_next.x == t_exit) {
            cell.x += step.x;
            t_next.x += t_delta.x;
        } else if (t_next.y == t_exit) {
            cell.y += step.y;
            t_next.y += t_delta.y;
        } else {
            cell.z += step.z;
            t_next.z += t_delta.z;
        }
    }
    let norm = volume_kernel(r);
    return sum * norm * params.power_unit;
}

struct Branch {
    origin: vec3<f32>,
    depth: u32,
    dir: vec3<f32>,
    // 0 along a glossy (non-delta) lobe's sample: what it sees emitted (and
    // the sky) is left out, since the direct light at its start counted it
    // (photon-cpu's `radiance_seen` without emission).
    sees_emission: u32,
    weight: vec3<f32>,
}

// A glossy surface of BRDF `b` (textures applied) whose specular lobe the
// eye follows (smoother than GATHER_ROUGHNESS; the photon maps stand for
// rougher ones).
fn follows_lobe(s: Surface, b: Bsdf) -> bool {
    return GLOSSY && s.kind == 0u && s.glossy != 0u && bsdf_follows_any(b);
}

// Whether surface `s` may follow its lobe somewhere: smooth enough, or
// made so by a metallic–roughness texture, or a coat made so by its
// roughness texture (the layer textures only lower the factors).
fn may_follow_lobe(s: Surface) -> bool {
    let coat_may_be_smooth = s.clearcoat_roughness < GATHER_ROUGHNESS || (LAYERED && s.layer_textures != NO_TEXTURE);
    return GLOSSY && s.kind == 0u && s.glossy != 0u
        && (s.roughness < GATHER_ROUGHNESS || s.metallic_roughness_texture != NO_TEXTURE
            || (COATED && s.clearcoat > 0.0 && coat_may_be_smooth));
}

// Point, spot and sun light reaching rough glass `g` at x from either side
// of its outward normal `ng`, through its reflection and transmission
// (glass_f in radiance mode; `wo` toward the viewer in ng's frame): the
// lights no sampled direction meets. Area lights and skies are left to the
// sampled directions (photon-cpu's `LitSides::FrontAndDeltaBehind`, which
// samples those on the viewer's side instead: the same expectation).
fn delta_light_through_glass(x: vec3<f32>, ng: vec3<f32>, g: Dielectric, wo: vec3<f32>) -> vec3<f32> {
    var sum = vec3<f32>(0.0);
    for (var i = 0u; i < direct_params.light_count; i++) {
        if (!loop_iteration()) {
            break;
        }
        let l = light_record(i);
        if (l.kind != 0u && l.kind != 1u && l.kind != KIND_SUN) {
            continue;
        }
        var wi = l.axis;
        if (l.kind != KIND_SUN) {
            wi = unit(l.position - x);
        }
        // The side the light is on: its irradiance there is E |cos θ|.
        let side = select(-ng, ng, dot(wi, ng) >= 0.0);
        let e = unshadowed_irradiance(l, x, side);
        if (all(e == vec3<f32>(0.0))) {
            continue;
        }
        sum += glass_f(g, wo, to_shading(wi, ng), true) * e * shadowed_fraction(l, x, side, no_bump());
    }
    return sum;
}

const STACK: u32 = 16u;

// Workgroups of WORKGROUP × WORKGROUP pixels (set by the pipeline).
override WORKGROUP: u32;

@compute @workgroup_size(WORKGROUP, WORKGROUP)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    if (id.x >= params.width || id.y >= params.height) {
        return;
    }
    let pixel = vec2<i32>(id.xy);
    // The G-buffer's normal.w is the surface id (the background's is 0 with
    // w = 0 everywhere, so check coverage through the normal's length).
    let g = textureLoad(gbuffer_normal, pixel, 0);
    let first = surfaces.all[u32(g.w)];
    // Where the material mixes in glass, the kind the G-buffer's pixel drew.
    var first_kind = first.kind;
    if (MIXED && first.transmission > 0.0) {
        first_kind = pixel_kind(textureLoad(gbuffer_albedo, pixel, 0).a);
    }
    // (A mixed surface's base draws show its back face by a sampled bounce.)
    let base = first_kind == 0u || first_kind == KIND_MIXED_INSIDE;
    let mirror_part = base
        && (any(first.specular > vec3<f32>(0.0)) || may_follow_lobe(first) || (MIXED && first.transmission > 0.0));
    if (dot(g.xyz, g.xyz) == 0.0 || (first_kind != 1u && first_kind != 2u && !mirror_part)) {
        if (slice.index + 1u == slice.count) {
            textureStore(output, pixel, vec4<f32>(0.0));
        }
        return;
    }
    // The primary ray through the pixel centre, as Camera::ray builds it.
    let px = vec2<f32>(f32(id.x) + 0.5 + params.jitter_x, f32(id.y) + 0.5 + params.jitter_y);
    let sx = (2.0 * px.x / f32(params.width) - 1.0) * params.tan_half_fov * params.aspect;
    let sy = (1.0 - 2.0 * px.y / f32(params.height)) * params.tan_half_fov;
    let primary = normalize(params.camera_forward + params.camera_right * sx + params.camera_up * sy);

    var stack: array<Branch, STACK>;
    stack[0] = Branch(params.camera_position, 0u, primary, 1u, vec3<f32>(1.0));
    var top = 1u;
    // Glossy lobes are sampled from the pixel's stream of this pass: the
    // same draws in every slice, so every slice retraces the same rays.
    var path_rng = pixel_stream(id.xy, slice.pass_index, 2u);
    var radiance = vec3<f32>(0.0);
    while (top > 0u) {
        if (!loop_iteration()) {
            break;
        }
        top -= 1u;
        let b = stack[top];
        let hit = trace_bvh(b.origin, b.dir, params.epsilon);
        // Media along this segment (photon-cpu's `radiance`): a ray that
        // hits nothing still crosses `escape_distance` of them. The segment
        // from the eye (depth 0) is the raster passes' (volume splat, resolve).
        var weight = b.weight;
        if (b.depth > 0u && has_media()) {
            let len = select(hit.t, escape_distance(b.origin, b.dir), hit.t >= NO_HIT);
            radiance += b.weight * volume_along(b.origin, b.dir, len);
            weight *= transmittance_along(b.origin, b.dir, len);
        }
        if (hit.t >= NO_HIT) {
            // Out of the scene: the sky (a primary ray's is the resolve's).
            if (b.depth > 0u && slice.index == 0u && b.sees_emission != 0u) {
                radiance += weight * params.sky_radiance * environment_radiance(b.dir);
            }
            continue;
        }
        let p = prims[hit.prim];
        let x = b.origin + b.dir * hit.t;
        // Glass refracts about the geometric normal, the rest reflects about
        // the smooth shading one, as the CPU renderers do.
        let normals = hit_normals(hit.prim, b.origin, b.dir, x);
        let ng = normals.geometric;
        var s = surfaces.all[p.surface];
        // The surface here with its textures (level 0, as the CPU reads).
        let uv = primitive_uv(hit.prim, hit.b);
        var point = surface_point(s, uv, vec2<f32>(0.0), vec2<f32>(0.0));
        if (LAYERED) {
            s = with_layer_texels(s, layer_texels(s, uv, vec2<f32>(0.0), vec2<f32>(0.0)));
        }
        let front = dot(b.dir, ng) < 0.0;
        // Glass mixed into the material: the eye's first hit is what the
        // G-buffer's pixel drew, the others draw per hit as the CPU
        // renderers do (Scene::material_at's hash).
        let mixed = MIXED && s.transmission > 0.0;
        if (mixed) {
            if (b.depth == 0u && p.surface == u32(g.w)) {
                // The pixel's own draw, as the G-buffer made it (at the
                // pixel's footprint), which the raster passes shade.
                if (first_kind == 2u) {
                    s = mixed_glass(s);
                } else {
                    point.metallic = unpack_metal_rough(textureLoad(gbuffer_emission, pixel, 0).w).x;
                }
            } else {
                let drawn = draw_layer(s, point, mix_threshold(p.source, x));
                s = drawn.surface;
                point = drawn.point;
            }
        }
        if (s.kind == 2u) {
            // Arriving from inside: what the glass absorbed on the way.
            weight *= glass_interior_transmittance(glass_absorption(s), b.dir, ng, hit.t);
        }
        let n = select(-ng, ng, front);
        // Bent by a normal texture before it turns to the ray's side, as
        // Scene::shading_normal_at and the G-buffer bend it.
        var shading = normals.shading;
        if (TEXTURED && s.normal_texture != NO_TEXTURE && p.is_sphere == 0u) {
            shading = bent_normal_at_hit(s, uv, hit.prim, hit.b, p.b, p.c, shading, ng, b.dir);
        }
        let ns = select(-shading, shading, front);
        // A normal-mapped point's diffuse lobes: the bump shadowing.
        var bump = no_bump();
        if (bump_mapped() && any(shading != normals.shading)) {
            bump = bump_shadow(normals.shading, shading);
        }
        let can_bounce = b.depth < params.max_depth;
        // Emitted light (Light::emitted_radiance), besides what the surface
        // reflects; a primary hit's is the G-buffer's.
        if ((b.depth > 0u || s.kind == 3u) && slice.index == 0u && (front || s.two_sided != 0u) && b.sees_emission != 0u) {
            radiance += weight * point.emission;
        }
        switch s.kind {
            case 0u: {
                // A diffuse primary hit is shaded by the raster passes; here
                // only its mirror part or followed lobe is.
                let eye = -b.dir;
                var bsdf = point_bsdf(s, point.base, point.metallic, point.roughness);
                // The coat on its own normal (Scene::coat_tilted).
                if (coat_apart(s, uv) && p.is_sphere == 0u) {
                    let coat = coat_normal_at_hit(s, uv, hit.prim, hit.b, p.b, p.c, normals.shading, ng, b.dir);
                    bsdf = with_coat_apart(bsdf, s, to_shading(select(-coat, coat, front), ns));
                }
                let glossy = GLOSSY && s.glossy != 0u;
                if (b.depth > 0u) {
                    if (slice.index == 0u) {
                        // Its own stream, so slice 0's draws leave the path's alone.
                        var light_rng = hash_u32(path_rng ^ 0x68bc21ebu);
                        var r = surface_reflector(s, bsdf, eye, ns);
                        r.bump = bump;
                        // No light from below the geometric surface (light_eval.wgsl).
                        shaded_geometric_normal = select(vec3<f32>(0.0), n, is_bent(ns, n));
                        radiance += weight * direct_radiance(x, ns, r, &light_rng);
                    }
                    // Behind a partly transmissive surface (inside its body)
                    // no photon is stored (trace.wgsl): a sampled bounce below
                    // shows the light there, as photon-cpu.
                    var gathered = vec3<f32>(0.0);
                    if (!mixed || front) {
                        if (is_bent(ns, n)) {
                            gathered = gather(x, ns, n, true, bump, glossy, bsdf, eye, params.global_radius, params.global_buckets, params.global_start_offset, params.global_photon_offset)
                                + gather(x, ns, n, true, bump, glossy, bsdf, eye, params.caustic_radius, params.caustic_buckets, params.caustic_start_offset, params.caustic_photon_offset);
                        } else {
                            gathered = gather(x, ns, n, false, bump, glossy, bsdf, eye, params.global_radius, params.global_buckets, params.global_start_offset, params.global_photon_offset)
                                + gather(x, ns, n, false, bump, glossy, bsdf, eye, params.caustic_radius, params.caustic_buckets, params.caustic_start_offset, params.caustic_photon_offset);
                        }
                    }
                    radiance += weight * gathered;
                }
                if (mixed && !front) {
                    // One direction of the whole BRDF per pass.
                    let u_lobe = stream_next_f32(&path_rng);
                    let wo = to_shading(eye, ns);
                    var sample = bsdf_sample(bsdf, wo, u_lobe, stream_next_2d(&path_rng));
                    if (bump_mapped() && bump.alpha >= 0.0) {
                        sample = bsdf_reweigh(bsdf, wo, sample, bump_term(bump, local_to_world(sample.wi, ns)));
                    }
                    if (sample.valid && can_bounce && top < STACK) {
                        let dir = local_to_world(sample.wi, ns);
                        stack[top] = Branch(x, b.depth + 1u, dir, select(0u, 1u, sample.is_delta), weight * sample.weight);
                        top += 1u;
                    }
                } else if (follows_lobe(s, bsdf)) {
                    // One direction of the specular lobe per pass.
                    let sample = bsdf_sample_followed(bsdf, to_shading(eye, ns), stream_next_2d(&path_rng));
                    if (sample.valid && can_bounce && top < STACK) {
                        let dir = local_to_world(sample.wi, ns);
                        stack[top] = Branch(x, b.depth + 1u, dir, select(0u, 1u, sample.is_delta), weight * sample.weight);
                        top += 1u;
                    }
                } else if (any(s.specular > vec3<f32>(0.0)) && can_bounce && top < STACK) {
                    stack[top] = Branch(x, b.depth + 1u, reflect(b.dir, ns), 1u, weight * s.specular);
                    top += 1u;
                }
            }
            case 1u: {
                if (can_bounce && top < STACK) {
                    stack[top] = Branch(x, b.depth + 1u, reflect(b.dir, ns), 1u, weight * s.albedo);
                    top += 1u;
                }
            }
            case 2u: {
                let g = Dielectric(s.ior, point.roughness, point.base);
                if (!glass_is_smooth(g)) {
                    // Rough glass: point, spot and sun light through it by
                    // shadow maps (slice 0 alone: each slice would add it),
                    // then one sampled direction per pass, which sees the
                    // area lights and skies it meets emitted.
                    if (slice.index == 0u) {
                        radiance += weight * delta_light_through_glass(x, ng, g, to_shading(-b.dir, ng));
                    }
                    let u_lobe = stream_next_f32(&path_rng);
                    let u = stream_next_2d(&path_rng);
                    let sample = glass_sample_rough(g, to_shading(-b.dir, ng), u_lobe, u, true);
                    if (sample.valid && can_bounce && top < STACK) {
                        stack[top] = Branch(x, b.depth + 1u, local_to_world(sample.wi, ng), 1u, weight * sample.weight);
                        top += 1u;
                    }
                } else if (can_bounce) {
                    // hikari_core::material::dielectric_split
                    let eta = select(s.ior, 1.0 / s.ior, front);
                    let cos_i = -dot(b.dir, n);
                    let fresnel = fresnel_dielectric(cos_i, eta);
                    let reflectance = fresnel.x;
                    if (reflectance < 1.0 && top < STACK) {
                        let refracted = refract_direction(b.dir, n, eta, cos_i, fresnel.y);
                        // Dielectric::smooth_branches (radiance): √tint, and
                        // over η'² = 1/eta² for radiance crossing.
                        let crossing = (1.0 - reflectance) * glass_transmission_factor(g, 1.0 / eta, true);
                        stack[top] = Branch(x, b.depth + 1u, refracted, 1u, weight * crossing);
                        top += 1u;
                    }
                    if (reflectance > 0.0 && top < STACK) {
                        stack[top] = Branch(x, b.depth + 1u, reflect(b.dir, n), 1u, weight * reflectance);
                        top += 1u;
                    }
                }
            }
            default: {
                // An area light's black body: its emission only (added above).
            }
        }
    }
    finish_pixel(id.xy, radiance);
}

// Adds this slice's radiance to the pixel's sum; the last slice stores it.
fn finish_pixel(id: vec2<u32>, radiance: vec3<f32>) {
    let index = id.y * params.width + id.x;
    var sum = vec4<f32>(radiance, f32(over_budget));
    if (slice.index > 0u) {
        let before = accum[index];
        sum = vec4<f32>(before.xyz + radiance, max(before.w, sum.w));
    }
    accum[index] = sum;
    if (slice.index + 1u == slice.count) {
        textureStore(output, vec2<i32>(id), vec4<f32>(sum.xyz, 1.0));
    }
    if (over_budget) {
        atomicAdd(&status[0], 1u);
    }
    atomicMax(&status[1], iterations_spent);
}

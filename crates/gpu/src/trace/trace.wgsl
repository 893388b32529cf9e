// Photon tracing on the GPU (METHOD.md §2): one invocation per photon path,
// step for step hikari_core::photon::trace's `trace_one`, drawing from the
// same per-path random stream (random.wgsl), so a path takes the CPU's
// decisions wherever float rounding does not tip one.
//
// A stored photon goes to `records` at a slot taken by an atomic counter,
// tagged with its path, map and sequence number within the path; the path
// also writes how many photons it stored in each map. compact.wgsl then
// puts every photon at its place in path order, so the maps do not depend
// on the order in which invocations ran.

struct TraceParams {
    mixed_seed: vec2<u32>,
    increment: vec2<u32>,
    // Index of this dispatch's first path (a u64).
    first_path: vec2<u32>,
    paths: u32,
    max_bounces: u32,
    light_count: u32,
    epsilon: f32,
    record_capacity: u32,
    iteration_budget: u32,
    // Media (0: none), the mask of those filling the scene, and the
    // triangles of the region meshes bounding the others.
    medium_count: u32,
    global_mask: u32,
    region_triangles: u32,
    _pad0: u32,
    // The disc distant lights' photons start from (xyz centre, w radius;
    // w = 0 without distant lights): photons that leave the scene fly
    // through the media up to its plane (Scene::escape_distance).
    distant_disc: vec4<f32>,
    // Word offsets of the tables behind the texture words (tables/mod.rs):
    // the lights (rewritten each dispatch), media, region triangles and
    // emissive triangles.
    light_table: u32,
    medium_table: u32,
    region_table: u32,
    emissive_table: u32,
}

// A light as the tracer emits from it (trace::TraceLight).
struct TraceLight {
    // Point or spot position, sphere centre, quad corner, or the centre of
    // a distant light's disc.
    origin: vec3<f32>,
    // 0 point, 1 spot, 2 sphere, 3 quad, 4 sun, 5 sky, 6 emissive mesh.
    kind: u32,
    // Spot axis, the quad's edge_u, or the direction the sun's light travels.
    axis: vec3<f32>,
    // Sphere radius, a distant light's disc radius, or a mesh's area.
    radius: f32,
    edge_v: vec3<f32>,
    cos_cutoff: f32,
    // The quad's unit normal, normalised on the host as Light::emit does.
    normal: vec3<f32>,
    cutoff: f32,
    // Each photon's starting power in power units: Φ_l / (p_l n) / unit.
    power: vec3<f32>,
    falloff_start: f32,
    probability: f32,
    // An emissive mesh's triangles in `emissive`, and whether it emits
    // from both faces.
    first_triangle: u32,
    triangle_count: u32,
    two_sided: u32,
    // A sky image's sampling block in `texture_data` (0: a uniform sky).
    sky_image: u32,
    _pad0: u32,
    _pad1: u32,
    _pad2: u32,
}

// A triangle of an emissive mesh (trace::TraceTriangle), with its mesh's
// cumulative area up to it (EmissiveMesh::cumulative_areas) and before it.
struct TraceTriangle {
    v0: vec3<f32>,
    cumulative_area: f32,
    v1: vec3<f32>,
    start_area: f32,
    v2: vec3<f32>,
    _pad0: u32,
    // Its unit winding normal, normalised on the host as Light::emit does.
    normal: vec3<f32>,
    _pad1: u32,
}

// A medium, in the order of hikari_core's Media entries (its bit in a mask).
struct TraceMedium {
    sigma_t: vec3<f32>,
    phase_slot: u32,
    sigma_s: vec3<f32>,
    phase_kind: f32,
    phase_parameter: f32,
    _pad0: u32,
    _pad1: u32,
    _pad2: u32,
}

// A triangle of a region mesh, wound with its normal out of the medium.
struct TraceRegionTriangle {
    a: vec3<f32>,
    medium: u32,
    b: vec3<f32>,
    _pad0: u32,
    c: vec3<f32>,
    _pad1: u32,
}



@group(0) @binding(0) var<uniform> params: TraceParams;
@group(0) @binding(1) var<storage, read> nodes: array<FlatNode>;
@group(0) @binding(2) var<storage, read> prims: array<FlatPrim>;
@group(0) @binding(3) var<storage, read> shading: array<FlatShading>;
@group(0) @binding(4) var<storage, read> surfaces: Surfaces;
@group(0) @binding(5) var<storage, read_write> records: array<PhotonRecord>;
// Photons stored per path: global map, then caustic, then volume (each `paths` long).
@group(0) @binding(6) var<storage, read_write> counts: array<u32>;
// [records taken (may pass the capacity), paths truncated, paths over the
// loop budget, most loop iterations one path ran].
@group(0) @binding(7) var<storage, read_write> status: array<atomic<u32>, 4>;
// The packed textures, then the lights, media, region and emissive
// triangles (`light_at` and the others below read them).
@group(0) @binding(8) var<storage, read> texture_data: array<u32>;

fn table_word(at: u32) -> u32 {
    return texture_data[at];
}

// hit_normals.wgsl's source of vertex normals.
fn flat_shading(index: u32) -> FlatShading {
    return shading[index];
}

// The tables' records, field by field as the Rust structs lay them out.
fn light_at(i: u32) -> TraceLight {
    let at = params.light_table + i * 28u;
    return TraceLight(
        table_vec3(at), table_u32(at + 3u),
        table_vec3(at + 4u), table_f32(at + 7u),
        table_vec3(at + 8u), table_f32(at + 11u),
        table_vec3(at + 12u), table_f32(at + 15u),
        table_vec3(at + 16u), table_f32(at + 19u),
        table_f32(at + 20u), table_u32(at + 21u), table_u32(at + 22u), table_u32(at + 23u),
        table_u32(at + 24u), 0u, 0u, 0u,
    );
}

fn medium_at(i: u32) -> TraceMedium {
    let at = params.medium_table + i * 12u;
    return TraceMedium(table_vec3(at), table_u32(at + 3u), table_vec3(at + 4u), table_f32(at + 7u), table_f32(at + 8u), 0u, 0u, 0u);
}

fn region_at(i: u32) -> TraceRegionTriangle {
    let at = params.region_table + i * 12u;
    return TraceRegionTriangle(table_vec3(at), table_u32(at + 3u), table_vec3(at + 4u), 0u, table_vec3(at + 8u), 0u);
}

fn emissive_at(i: u32) -> TraceTriangle {
    let at = params.emissive_table + i * 16u;
    return TraceTriangle(table_vec3(at), table_f32(at + 3u), table_vec3(at + 4u), table_f32(at + 7u), table_vec3(at + 8u), 0u, table_vec3(at + 12u), 0u);
}

const GLOBAL_MAP: u32 = 0u;
const CAUSTIC_MAP: u32 = 1u;
const VOLUME_MAP: u32 = 2u;

override WORKGROUP_SIZE: u32 = 64u;

var<private> iterations_spent: u32 = 0u;
var<private> over_budget: bool = false;
var<private> path_index: u32;
var<private> stored: array<u32, 3>;
// The emitted photon's power factor (EmittedRay::weight): not 1 only for a
// sky image's colours.
var<private> emission_weight: vec3<f32>;

// Loop accounting (capabilities::loop_budget): a path that would run past
// the budget stops and is counted, and the host falls back to the CPU.
fn loop_iteration() -> bool {
    iterations_spent += 1u;
    if (iterations_spent > params.iteration_budget) {
        over_budget = true;
    }
    return !over_budget;
}

// material::reflect, written out (WGSL's reflect may round differently).
fn mirror(dir: vec3<f32>, n: vec3<f32>) -> vec3<f32> {
    return dir - 2.0 * dot(dir, n) * n;
}

fn store(map: u32, bounces: u32, x: vec3<f32>, power: vec3<f32>, dir: vec3<f32>, top_bits: u32) {
    let sequence = stored[map];
    stored[map] = sequence + 1u;
    let slot = atomicAdd(&status[0], 1u);
    if (slot < params.record_capacity) {
        records[slot] = PhotonRecord(
            path_index,
            map | (min(bounces, 255u) << 8u) | (sequence << 16u),
            x.x,
            x.y,
            x.z,
            encode_rgb9e5(power),
            encode_octahedral_15(dir) | (top_bits << 30u),
            0u,
        );
    }
}

// The surface-map store of trace.rs: class by the path so far.
fn store_surface(x: vec3<f32>, power: vec3<f32>, dir: vec3<f32>, diffuse_bounces: u32, specular_bounces: u32) {
    var path_class = 2u;
    if (diffuse_bounces == 0u) {
        path_class = select(1u, 0u, specular_bounces == 0u);
    }
    store(GLOBAL_MAP, diffuse_bounces, x, power, dir, path_class);
    if (path_class == 1u) {
        store(CAUSTIC_MAP, diffuse_bounces, x, power, dir, path_class);
    }
}

fn choose_light(xi: f32) -> u32 {
    var acc = 0.0;
    var index = params.light_count - 1u;
    for (var i = 0u; i < params.light_count; i++) {
        if (!loop_iteration()) {
            break;
        }
        acc += light_at(i).probability;
        if (xi < acc) {
            index = i;
            break;
        }
    }
    return index;
}

struct Ray {
    origin: vec3<f32>,
    dir: vec3<f32>,
}

// Light::emit.
fn emit(l: TraceLight, rng: ptr<function, Rng>) -> Ray {
    switch l.kind {
        case 0u: {
            return Ray(l.origin, uniform_sphere(rng_next_2d(rng)));
        }
        case 1u: {
            // sample_spot_direction: uniform in the cutoff cone, accepted by falloff.
            var w = vec3<f32>(0.0, 0.0, 1.0);
            loop {
                if (!loop_iteration()) {
                    break;
                }
                w = uniform_cone(rng_next_2d(rng), l.cos_cutoff);
                let f = spot_falloff(acos(clamp(w.z, -1.0, 1.0)), l.cutoff, l.falloff_start);
                if (rng_next_f32(rng) < f) {
                    break;
                }
            }
            return Ray(l.origin, local_to_world(w, l.axis));
        }
        case 2u: {
            let n = uniform_sphere(rng_next_2d(rng));
            let dir = local_to_world(cosine_hemisphere(rng_next_2d(rng)), n);
            return Ray(l.origin + n * l.radius, dir);
        }
        case 3u: {
            let u = rng_next_2d(rng);
            let dir = local_to_world(cosine_hemisphere(rng_next_2d(rng)), l.normal);
            return Ray(l.origin + l.axis * u.x + l.edge_v * u.y, dir);
        }
        case 4u: {
            return Ray(disc_origin(l, l.axis, rng_next_2d(rng)), l.axis);
        }
        case 5u: {
            if (!SAMPLED_LIGHTS) {
                // No sky in the scene (features.wgsl): never reached.
                return Ray(l.origin, l.axis);
            }
            if (SKY_IMAGE && l.sky_image != 0u) {
                // From the image's sky direction ω, the photon travels along −ω.
                let sky = sample_sky_image(l.sky_image, rng_next_2d(rng));
                emission_weight = sky.weight;
                return Ray(disc_origin(l, -sky.dir, rng_next_2d(rng)), -sky.dir);
            }
            let dir = uniform_sphere(rng_next_2d(rng));
            return Ray(disc_origin(l, dir, rng_next_2d(rng)), dir);
        }
        default: {
            if (!SAMPLED_LIGHTS) {
                // No emissive mesh in the scene: never reached.
                return Ray(l.origin, l.axis);
            }
            let point = mesh_point(l, rng_next_2d(rng));
            // Two-sided: either face, each with half the power.
            var n = point.normal;
            if (l.two_sided != 0u) {
                if (rng_next_f32(rng) < 0.5) {
                    n = -n;
                }
            }
            return Ray(point.position, local_to_world(cosine_hemisphere(rng_next_2d(rng)), n));
        }
    }
}

// Disc::emission_origin: a uniform point of the distant light's disc turned
// perpendicular to `dir` and set back by its radius.
// The entry i of the CDF of n + 1 entries at word `at` with
// cdf[i] ≤ x < cdf[i + 1], and where x lies in it (envmap.rs's sample_cdf).
fn sky_cdf_pick(at: u32, n: u32, x: f32) -> vec2<f32> {
    // partition_point(c ≤ x): the first entry above x.
    var lo = 0u;
    var hi = n + 1u;
    while (lo < hi) {
        if (!loop_iteration()) {
            break;
        }
        let mid = (lo + hi) / 2u;
        if (bitcast<f32>(texture_data[at + mid]) <= x) {
            lo = mid + 1u;
        } else {
            hi = mid;
        }
    }
    let i = clamp(lo, 1u, n) - 1u;
    let c0 = bitcast<f32>(texture_data[at + i]);
    let width = bitcast<f32>(texture_data[at + i + 1u]) - c0;
    var t = 0.5;
    if (width > 0.0) {
        t = clamp((x - c0) / width, 0.0, 1.0);
    }
    return vec2<f32>(f32(i), t);
}

struct SkySample {
    // Toward the sky.
    dir: vec3<f32>,
    // L(ω)/(p(ω)·∫L dω) per channel.
    weight: vec3<f32>,
}

// EnvironmentMap::sample from the block at `at` (textures::sky_block).
fn sample_sky_image(at: u32, u: vec2<f32>) -> SkySample {
    let w = texture_data[at];
    let h = texture_data[at + 1u];
    let integral = vec3<f32>(bitcast<f32>(texture_data[at + 2u]), bitcast<f32>(texture_data[at + 3u]), bitcast<f32>(texture_data[at + 4u]));
    let rows = at + 5u;
    let row_pick = sky_cdf_pick(rows, h, u.y);
    let row = u32(row_pick.x);
    let columns = rows + h + 1u + row * (w + 1u);
    let column_pick = sky_cdf_pick(columns, w, u.x);
    let column = u32(column_pick.x);
    let inside = vec2<f32>(clamp(column_pick.y, 1.0e-4, 1.0 - 1.0e-4), clamp(row_pick.y, 1.0e-4, 1.0 - 1.0e-4));
    let uv = vec2<f32>((f32(column) + inside.x) / f32(w), (f32(row) + inside.y) / f32(h));
    // The texel's probability over its area of the unit square, over 2π² sin θ.
    let p_row = bitcast<f32>(texture_data[rows + row + 1u]) - bitcast<f32>(texture_data[rows + row]);
    let p_column = bitcast<f32>(texture_data[columns + column + 1u]) - bitcast<f32>(texture_data[columns + column]);
    let sin_theta = sin(uv.y * PI);
    let pdf = p_row * p_column * f32(w * h) / (2.0 * PI * PI * sin_theta);
    let texel = rows + h + 1u + h * (w + 1u) + 3u * (row * w + column);
    let radiance = vec3<f32>(bitcast<f32>(texture_data[texel]), bitcast<f32>(texture_data[texel + 1u]), bitcast<f32>(texture_data[texel + 2u]));
    let phi = (uv.x - 0.5) * 2.0 * PI;
    let theta = uv.y * PI;
    let dir = vec3<f32>(sin(theta) * cos(phi), cos(theta), sin(theta) * sin(phi));
    var weight = vec3<f32>(0.0);
    if (pdf > 0.0) {
        weight = select(vec3<f32>(0.0), radiance / (pdf * max(integral, vec3<f32>(1.0e-38))), integral > vec3<f32>(0.0));
    }
    return SkySample(dir, weight);
}

fn disc_origin(l: TraceLight, dir: vec3<f32>, u: vec2<f32>) -> vec3<f32> {
    let basis = orthonormal_basis(dir);
    let p = unit_circle(u.y) * sqrt(u.x) * l.radius;
    return l.origin - dir * l.radius + basis.t * p.x + basis.b * p.y;
}

struct MeshPoint {
    position: vec3<f32>,
    normal: vec3<f32>,
}

// EmissiveMesh::sample_point: a triangle ∝ its area by binary search of the
// cumulative areas (`partition_point`), u.x reused, rescaled, inside it.
fn mesh_point(l: TraceLight, u: vec2<f32>) -> MeshPoint {
    let target_area = u.x * l.radius;
    // The first triangle whose cumulative area exceeds the target.
    var lo = 0u;
    var hi = l.triangle_count;
    while (lo < hi) {
        if (!loop_iteration()) {
            break;
        }
        let mid = (lo + hi) / 2u;
        if (emissive_at(l.first_triangle + mid).cumulative_area <= target_area) {
            lo = mid + 1u;
        } else {
            hi = mid;
        }
    }
    let tri = emissive_at(l.first_triangle + min(lo, l.triangle_count - 1u));
    let width = tri.cumulative_area - tri.start_area;
    var ux = 0.5;
    if (width > 0.0) {
        ux = clamp((target_area - tri.start_area) / width, 0.0, 1.0);
    }
    // Uniform on the triangle (pbrt's square-root mapping).
    let s = sqrt(ux);
    let b1 = s * (1.0 - u.y);
    let b2 = s * u.y;
    return MeshPoint(tri.v0 * (1.0 - b1 - b2) + tri.v1 * b1 + tri.v2 * b2, tri.normal);
}

@compute @workgroup_size(WORKGROUP_SIZE)
fn trace_paths(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) groups: vec3<u32>) {
    let path = gid.y * groups.x * WORKGROUP_SIZE + gid.x;
    if (path >= params.paths) {
        return;
    }
    path_index = path;
    var rng = rng_for_item(params.mixed_seed, params.increment, add_u64(params.first_path, vec2<u32>(path, 0u)));
    trace_one(&rng);
    counts[path] = stored[GLOBAL_MAP];
    counts[params.paths + path] = stored[CAUSTIC_MAP];
    counts[2u * params.paths + path] = stored[VOLUME_MAP];
    if (over_budget) {
        atomicAdd(&status[2], 1u);
    }
    atomicMax(&status[3], iterations_spent);
}

fn trace_one(rng: ptr<function, Rng>) {
    let light = light_at(choose_light(rng_next_f32(rng)));
    emission_weight = vec3<f32>(1.0);
    var ray = emit(light, rng);
    var power = light.power * emission_weight;
    var diffuse_bounces = 0u;
    var specular_bounces = 0u;
    for (var bounce = 0u; bounce < params.max_bounces; bounce++) {
        if (!loop_iteration()) {
            return;
        }
        let hit = trace_bvh(ray.origin, ray.dir, params.epsilon);
        // Free flight through the media (eq. 5.10–5.12).
        if (MEDIA && params.medium_count > 0u) {
            var t_max = hit.t;
            let disc = params.distant_disc;
            if (hit.t >= NO_HIT && disc.w > 0.0) {
                t_max = max(disc.w - dot(ray.origin - disc.xyz, ray.dir), 0.0);
            }
            let flight = sample_flight(ray.origin, ray.dir, t_max, rng_next_f32(rng));
            if (flight.interaction) {
                let scattering = media_scattering(flight.coefficients);
                if (rng_next_f32(rng) >= scattering.w) {
                    return;
                }
                power *= flight.weight * scattering.xyz;
                let x = ray.origin + ray.dir * flight.distance;
                let m = medium_at(choose_scatterer(flight.mask, rgb_mean(flight.coefficients.sigma_s), rng_next_f32(rng)));
                store(VOLUME_MAP, diffuse_bounces, x, power, ray.dir, m.phase_slot);
                diffuse_bounces += 1u;
                ray = Ray(x, phase_sample(m.phase_kind, m.phase_parameter, ray.dir, rng_next_2d(rng)));
                continue;
            }
            power *= flight.weight;
        }
        if (hit.t >= NO_HIT) {
            return;
        }
        let x = ray.origin + ray.dir * hit.t;
        let normals = hit_normals(hit.prim, ray.origin, ray.dir, x);
        var s = surfaces.all[prims[hit.prim].surface];
        // The surface here with its textures (Scene::material_at).
        let uv = primitive_uv(hit.prim, hit.b);
        var point = surface_point(s, uv, vec2<f32>(0.0), vec2<f32>(0.0));
        if (LAYERED) {
            s = with_layer_texels(s, layer_texels(s, uv, vec2<f32>(0.0), vec2<f32>(0.0)));
        }
        // Normals on the side the photon arrives from; the shading one bent
        // by a normal texture first (Scene::bent, as the CPU tracer).
        let facing = select(-1.0, 1.0, dot(ray.dir, normals.geometric) < 0.0);
        let ng = normals.geometric * facing;
        var shading = normals.shading;
        let prim = prims[hit.prim];
        if (TEXTURED && s.normal_texture != NO_TEXTURE && prim.is_sphere == 0u) {
            shading = bent_normal_at_hit(s, uv, hit.prim, hit.b, prim.b, prim.c, shading, normals.geometric, ray.dir);
        }
        let ns = shading * facing;
        // A normal-mapped point's diffuse lobes: the bump shadowing of the
        // side the photon comes from (as the CPU tracer).
        var bump = 1.0;
        if (bump_mapped() && any(shading != normals.shading)) {
            bump = bump_term(bump_shadow(normals.shading, shading), -ray.dir);
        }
        // Glass mixed into the material, drawn per hit by the CPU tracer's
        // hash (Scene::material_at): a photon stored on the base's draw
        // stands for the glass's too (Drawn::store_weight), and none is
        // stored behind the surface, inside its body (store_where_mixed).
        var store_weight = 1.0;
        if (MIXED && s.transmission > 0.0) {
            let drawn = draw_layer(s, point, mix_threshold(prim.source, x));
            s = drawn.surface;
            point = drawn.point;
            store_weight = select(0.0, 1.0 / drawn.probability, facing > 0.0);
        }
        if (s.kind == 2u) {
            // Arriving from inside: what the glass absorbed on the way.
            power *= glass_interior_transmittance(glass_absorption(s), ray.dir, normals.geometric, hit.t);
        }
        var next_dir: vec3<f32>;
        if (s.kind == 3u) {
            return;
        } else if (s.kind == 2u && !glass_is_smooth(Dielectric(s.ior, point.roughness, point.base))) {
            // Rough glass (Dielectric::sample_world, importance): one
            // microfacet lobe, roulette on the sample's weight.
            let g = Dielectric(s.ior, point.roughness, point.base);
            let u_lobe = rng_next_f32(rng);
            let u = rng_next_2d(rng);
            let sample = glass_sample_rough(g, to_shading(-ray.dir, normals.geometric), u_lobe, u, false);
            if (!sample.valid) {
                return;
            }
            let survive = min(rgb_mean(sample.weight), 1.0);
            if (survive < 1.0) {
                if (!(rng_next_f32(rng) < survive)) {
                    return;
                }
            }
            power *= sample.weight / survive;
            specular_bounces += 1u;
            next_dir = local_to_world(sample.wi, normals.geometric);
        } else if (s.kind == 2u) {
            // dielectric_split about the outward geometric normal.
            let entering = dot(ray.dir, normals.geometric) < 0.0;
            let n = select(-normals.geometric, normals.geometric, entering);
            let eta = select(s.ior, 1.0 / s.ior, entering);
            let cos_i = -dot(ray.dir, n);
            let fresnel = fresnel_dielectric(cos_i, eta);
            specular_bounces += 1u;
            next_dir = mirror(ray.dir, n);
            if (fresnel.x < 1.0) {
                if (rng_next_f32(rng) >= fresnel.x) {
                    next_dir = refract_direction(ray.dir, n, eta, cos_i, fresnel.y);
                    // Dielectric::sample (importance): the tint, by roulette.
                    let tint = glass_transmission_factor(Dielectric(s.ior, point.roughness, point.base), 1.0, false);
                    let survive = min(rgb_mean(tint), 1.0);
                    if (survive < 1.0) {
                        if (!(rng_next_f32(rng) < survive)) {
                            return;
                        }
                    }
                    power *= tint / survive;
                }
            }
        } else if (GLOSSY && s.glossy != 0u) {
            // The glTF BRDF (photon::trace's Pbr arm): stored where the
            // photon maps stand for some lobe, then a bounce sampling the
            // whole BRDF with roulette on the sample's weight.
            var b = point_bsdf(s, point.base, point.metallic, point.roughness);
            // The coat on its own normal (Scene::coat_tilted).
            if (coat_apart(s, uv) && prim.is_sphere == 0u) {
                let coat = coat_normal_at_hit(s, uv, hit.prim, hit.b, prim.b, prim.c, normals.shading, normals.geometric, ray.dir);
                b = with_coat_apart(b, s, to_shading(coat * facing, ns));
            }
            if (bsdf_stores_photons(b) && store_weight > 0.0) {
                store_surface(x, power * store_weight, ray.dir, diffuse_bounces, specular_bounces);
            }
            let u_lobe = rng_next_f32(rng);
            let u = rng_next_2d(rng);
            let wo = to_shading(-ray.dir, ns);
            var sample = bsdf_sample(b, wo, u_lobe, u);
            if (bump_mapped() && bump != 1.0) {
                sample = bsdf_reweigh(b, wo, sample, bump);
            }
            if (!sample.valid) {
                return;
            }
            let survive = min(rgb_mean(sample.weight), 1.0);
            if (!(rng_next_f32(rng) < survive)) {
                return;
            }
            power *= sample.weight / survive;
            if (sample.followed) {
                specular_bounces += 1u;
            } else {
                diffuse_bounces += 1u;
            }
            next_dir = local_to_world(sample.wi, ns);
        } else {
            let rho_d = select(vec3<f32>(0.0), point.base, s.kind == 0u);
            let rho_s = select(s.albedo, s.specular, s.kind == 0u);
            if (max(max(rho_d.x, rho_d.y), rho_d.z) > 0.0) {
                store_surface(x, power, ray.dir, diffuse_bounces, specular_bounces);
            }
            // Material::roulette.
            let xi = rng_next_f32(rng);
            let p_d = rgb_mean(rho_d);
            let p_s = rgb_mean(rho_s);
            if (xi < p_d) {
                power *= rho_d / p_d * bump;
                diffuse_bounces += 1u;
                next_dir = local_to_world(cosine_hemisphere(rng_next_2d(rng)), ns);
            } else if (xi < p_d + p_s) {
                power *= rho_s / p_s;
                specular_bounces += 1u;
                next_dir = mirror(ray.dir, ns);
            } else {
                return;
            }
        }
        // A shading normal can send the path below the true surface: end it there.
        let leaves_front = dot(next_dir, ng) > 0.0;
        let is_transmission = s.kind == 2u && dot(next_dir, ng) < 0.0;
        if (!leaves_front && !is_transmission) {
            return;
        }
        ray = Ray(x, next_dir);
    }
    atomicAdd(&status[1], 1u);
}

struct Coefficients {
    sigma_t: vec3<f32>,
    sigma_s: vec3<f32>,
}

// Media::sigma_t and sigma_s of the media in `mask`, each summed in bit order.
fn mask_coefficients(mask: u32) -> Coefficients {
    var total = Coefficients(vec3<f32>(0.0), vec3<f32>(0.0));
    var bits = mask;
    while (bits != 0u) {
        if (!loop_iteration()) {
            break;
        }
        let m = medium_at(firstTrailingBit(bits));
        total.sigma_t += m.sigma_t;
        total.sigma_s += m.sigma_s;
        bits &= bits - 1u;
    }
    return total;
}

// Media::scattering: the albedo roulette's per-channel factor (xyz) and Λ (w),
// from the summed coefficients of the media there.
fn media_scattering(coefficients: Coefficients) -> vec4<f32> {
    let sigma_t = coefficients.sigma_t;
    let sigma_s = coefficients.sigma_s;
    var lambda = 0.0;
    if (rgb_mean(sigma_t) > 0.0) {
        lambda = rgb_mean(sigma_s) / rgb_mean(sigma_t);
    }
    if (lambda <= 0.0) {
        return vec4<f32>(0.0);
    }
    let albedo = select(vec3<f32>(0.0), sigma_s / sigma_t, sigma_t > vec3<f32>(0.0));
    return vec4<f32>(albedo / lambda, lambda);
}

// Media::choose_scatterer: a medium of `mask` with probability ∝ its mean σ_s
// (`total`: the mask's summed mean σ_s). A mask of one medium is that medium
// without reading it, as the loop gives (acc = x / x = 1 > xi, or NaN for
// σ_s = 0, where the loop ends on that same last bit).
fn choose_scatterer(mask: u32, total: f32, xi: f32) -> u32 {
    if (countOneBits(mask) == 1u) {
        return firstTrailingBit(mask);
    }
    var acc = 0.0;
    var bits = mask;
    var last = firstTrailingBit(mask);
    while (bits != 0u) {
        if (!loop_iteration()) {
            break;
        }
        let i = firstTrailingBit(bits);
        bits &= bits - 1u;
        acc += rgb_mean(medium_at(i).sigma_s) / total;
        last = i;
        if (xi < acc) {
            break;
        }
    }
    return last;
}

struct Flight {
    interaction: bool,
    distance: f32,
    weight: vec3<f32>,
    mask: u32,
    // The summed coefficients of the media in `mask` (read once per flight
    // piece: each medium is a table record of 12 words).
    coefficients: Coefficients,
}

// A region triangle's crossing (region_crossing.wgsl): its distance, or 0.
fn triangle_crossing(o: vec3<f32>, d: vec3<f32>, tri: TraceRegionTriangle) -> f32 {
    return region_crossing(o, d, tri.a, tri.b, tri.c);
}

// +1 where the ray leaves the medium through the triangle, −1 where it enters.
fn crossing_sign(d: vec3<f32>, tri: TraceRegionTriangle) -> i32 {
    return select(-1, 1, dot(cross(tri.b - tri.a, tri.c - tri.a), d) > 0.0);
}

var<private> winding: array<i32, 32>;

fn winding_mask(count: u32) -> u32 {
    var mask = params.global_mask;
    for (var i = 0u; i < count; i++) {
        if (winding[i] > 0) {
            mask |= 1u << i;
        }
    }
    return mask;
}

// Media::sample_flight along o + t·d up to t_max: the pieces of constant
// media between region crossings (Media::segments), walked in order
// without sorting (the next crossing found each time).
fn sample_flight(o: vec3<f32>, d: vec3<f32>, t_max: f32, xi: f32) -> Flight {
    let target_depth = -log(1.0 - xi);
    var tau_bar = 0.0;
    var tau = vec3<f32>(0.0);
    var t0 = 0.0;
    var coefficients = Coefficients(vec3<f32>(0.0), vec3<f32>(0.0));
    var mask = params.global_mask;
    if (params.region_triangles > 0u) {
        for (var i = 0u; i < params.medium_count; i++) {
            winding[i] = 0;
        }
        // The net number of exits ahead is the winding at the origin.
        for (var i = 0u; i < params.region_triangles; i++) {
            if (!loop_iteration()) {
                break;
            }
            let tri = region_at(i);
            if (triangle_crossing(o, d, tri) > 0.0) {
                winding[tri.medium] += crossing_sign(d, tri);
            }
        }
        mask = winding_mask(params.medium_count);
    }
    loop {
        if (!loop_iteration()) {
            break;
        }
        // The next crossing ahead of t0.
        var t_next = NO_HIT;
        for (var i = 0u; i < params.region_triangles; i++) {
            if (!loop_iteration()) {
                break;
            }
            let t = triangle_crossing(o, d, region_at(i));
            if (t > t0 && t < t_next) {
                t_next = t;
            }
        }
        let t1 = min(t_next, t_max);
        coefficients = mask_coefficients(mask);
        let sigma_t = coefficients.sigma_t;
        let sigma_bar = rgb_mean(sigma_t);
        if (sigma_bar > 0.0) {
            let length = t1 - t0;
            if (tau_bar + sigma_bar * length > target_depth) {
                let distance = (target_depth - tau_bar) / sigma_bar;
                let tau_c = tau + sigma_t * distance;
                let weight = exp(-(tau_c - vec3<f32>(target_depth))) * sigma_t / sigma_bar;
                return Flight(true, t0 + distance, weight, mask, coefficients);
            }
            tau_bar += sigma_bar * length;
            tau += sigma_t * length;
        }
        if (t_next >= t_max) {
            break;
        }
        // Every crossing at t_next (shared edges give one per mesh).
        for (var i = 0u; i < params.region_triangles; i++) {
            if (!loop_iteration()) {
                break;
            }
            let tri = region_at(i);
            if (triangle_crossing(o, d, tri) == t_next) {
                winding[tri.medium] -= crossing_sign(d, tri);
            }
        }
        t0 = t_next;
        mask = winding_mask(params.medium_count);
    }
    return Flight(false, 0.0, exp(-(tau - vec3<f32>(tau_bar))), mask, coefficients);
}

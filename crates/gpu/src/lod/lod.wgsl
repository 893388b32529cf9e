// Level of detail (METHOD.md §6): a compute pass that computes each photon's
// detail level and power scale, mirrored from hikari_core::lod, and appends
// the photons that survive to the splat's instance buffer, counting them
// into the indirect draw: culled photons are never rasterized.

struct LodParams {
    eye: vec3<f32>,
    near: f32,
    far: f32,
    groups: u32,
    count: u32,
    // 0: LOD off (every photon drawn with scale 1).
    enabled: u32,
}

// The splat's instance: a stored photon and its LOD power scale.
struct LodPhoton {
    position_x: f32,
    position_y: f32,
    position_z: f32,
    power_rgb9e5: u32,
    direction_and_class: u32,
    scale: f32,
}

struct DrawIndirect {
    vertex_count: u32,
    instance_count: atomic<u32>,
    first_vertex: u32,
    first_instance: u32,
}

@group(0) @binding(0) var<uniform> params: LodParams;
// Stored photons, 5 words each (hikari_core::photon::Photon).
@group(0) @binding(1) var<storage, read> photons: array<u32>;
@group(0) @binding(2) var<storage, read_write> survivors: array<LodPhoton>;
@group(0) @binding(3) var<storage, read_write> draw: DrawIndirect;

fn smoothstep_lod(e0: f32, e1: f32, x: f32) -> f32 {
    if (e0 == e1) {
        return select(1.0, 0.0, x < e0);
    }
    let t = clamp((x - e0) / (e1 - e0), 0.0, 1.0);
    return t * t * (3.0 - 2.0 * t);
}

fn detail_level(distance: f32) -> f32 {
    if (params.near <= params.far) {
        return smoothstep_lod(params.near, params.far, distance);
    }
    return 1.0 - smoothstep_lod(params.far, params.near, distance);
}

// C_p = ⌊index · A / count⌋ (hikari_core::lod::group_of). The Rust side keeps
// count · A below 2^32, so this u32 arithmetic is exact.
fn group_of(index: u32) -> u32 {
    return (index * params.groups) / params.count;
}

fn power_scale(q: f32, group: u32) -> f32 {
    let dq = 1.0 / f32(params.groups);
    let g = f32(group) / f32(params.groups);
    if (q >= g + dq || q >= 1.0) {
        return 0.0;
    }
    if (q <= g) {
        return 1.0 / (1.0 - q);
    }
    return (1.0 - (1.0 - g - dq) / (1.0 - q)) / dq;
}

@compute @workgroup_size(64)
fn cull(@builtin(global_invocation_id) id: vec3<u32>) {
    let i = id.x;
    if (i >= params.count) {
        return;
    }
    let base = 5u * i;
    let position = vec3<f32>(bitcast<f32>(photons[base]), bitcast<f32>(photons[base + 1u]), bitcast<f32>(photons[base + 2u]));
    var scale = 1.0;
    if (params.enabled != 0u) {
        scale = power_scale(detail_level(distance(position, params.eye)), group_of(i));
        if (scale <= 0.0) {
            return;
        }
    }
    let slot = atomicAdd(&draw.instance_count, 1u);
    survivors[slot] = LodPhoton(position.x, position.y, position.z, photons[base + 3u], photons[base + 4u], scale);
}

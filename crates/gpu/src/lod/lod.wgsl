// Level of detail (METHOD.md §6): compute each photon's detail level and
// power scale, mirrored from hikari_core::lod, and compact the photons that
// survive into the splat's instance buffer and indirect draw, so culled
// photons are never rasterized. The compaction keeps storage order (count →
// scan → scatter), so the splat blends in the same order on every run.

struct LodParams {
    eye: vec3<f32>,
    near: f32,
    far: f32,
    groups: u32,
    count: u32,
    // 0: LOD off (every photon drawn with scale 1).
    enabled: u32,
    // Workgroups of the count and scatter dispatches.
    workgroups: u32,
    _pad0: u32,
    _pad1: u32,
    _pad2: u32,
}


struct DrawIndirect {
    vertex_count: u32,
    instance_count: u32,
    first_vertex: u32,
    first_instance: u32,
}

@group(0) @binding(0) var<uniform> params: LodParams;
// Stored photons, 5 words each (hikari_core::photon::Photon).
@group(0) @binding(1) var<storage, read> photons: array<u32>;
@group(0) @binding(2) var<storage, read_write> survivors: array<LodPhoton>;
@group(0) @binding(3) var<storage, read_write> draw: DrawIndirect;
// Survivors per workgroup, then (after `scan`) each workgroup's first slot.
@group(0) @binding(4) var<storage, read_write> group_sums: array<u32>;

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

fn photon_position(i: u32) -> vec3<f32> {
    let base = 5u * i;
    return vec3<f32>(bitcast<f32>(photons[base]), bitcast<f32>(photons[base + 1u]), bitcast<f32>(photons[base + 2u]));
}

// The scale of photon i; 0 when culled or past the end.
fn scale_of(i: u32) -> f32 {
    if (i >= params.count) {
        return 0.0;
    }
    if (params.enabled == 0u) {
        return 1.0;
    }
    return power_scale(detail_level(distance(photon_position(i), params.eye)), group_of(i));
}

@compute @workgroup_size(256)
fn count(@builtin(workgroup_id) wid: vec3<u32>, @builtin(num_workgroups) groups: vec3<u32>, @builtin(local_invocation_index) lid: u32) {
    let g = group_index(wid, groups);
    if (g >= params.workgroups) {
        return;
    }
    let keep = u32(scale_of(g * SCAN_WORKGROUP + lid) > 0.0);
    workgroup_exclusive_prefix(lid, keep);
    if (lid == 0u) {
        group_sums[g] = shared_sums[SCAN_WORKGROUP - 1u];
    }
}

// One workgroup turns the per-workgroup counts into first slots.
@compute @workgroup_size(256)
fn scan(@builtin(local_invocation_index) lid: u32) {
    let total = scan_group_sums(lid, params.workgroups);
    if (lid == SCAN_WORKGROUP - 1u) {
        draw.instance_count = total;
    }
}

@compute @workgroup_size(256)
fn scatter(@builtin(workgroup_id) wid: vec3<u32>, @builtin(num_workgroups) groups: vec3<u32>, @builtin(local_invocation_index) lid: u32) {
    let g = group_index(wid, groups);
    if (g >= params.workgroups) {
        return;
    }
    let i = g * SCAN_WORKGROUP + lid;
    let scale = scale_of(i);
    let keep = u32(scale > 0.0);
    let slot = group_sums[g] + workgroup_exclusive_prefix(lid, keep);
    if (keep == 1u) {
        let p = photon_position(i);
        survivors[slot] = LodPhoton(p.x, p.y, p.z, photons[5u * i + 3u], photons[5u * i + 4u], scale);
    }
}

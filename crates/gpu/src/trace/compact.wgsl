// Puts the tracer's photon records in path order (trace.wgsl): an exclusive
// prefix sum over the per-path counts of the three maps, laid end to end,
// gives each (map, path) its first slot in `photons`, and each record goes
// to its slot plus its sequence number. The maps come out as the CPU
// tracer concatenates them, whatever order the paths ran in.

struct CompactParams {
    // Counts to scan: 3 × paths.
    elements: u32,
    paths: u32,
    // Records the buffer holds (the tracer may have taken more slots).
    record_capacity: u32,
    // Workgroups of the sum and offset dispatches.
    workgroups: u32,
}


@group(0) @binding(0) var<uniform> params: CompactParams;
// Per-path counts, replaced by their first slots.
@group(0) @binding(1) var<storage, read_write> counts: array<u32>;
@group(0) @binding(2) var<storage, read_write> group_sums: array<u32>;
@group(0) @binding(3) var<storage, read> records: array<PhotonRecord>;
// The maps, 5 words per photon: global, then caustic, then volume.
@group(0) @binding(4) var<storage, read_write> photons: array<u32>;
// Diffuse bounces before each photon (for the per-bounce statistics).
@group(0) @binding(5) var<storage, read_write> bounces: array<u32>;
// [first caustic slot, first volume slot, total].
@group(0) @binding(6) var<storage, read_write> map_starts: array<u32, 4>;
// The tracer's status: [0] is the number of records it took.
@group(0) @binding(7) var<storage, read> trace_status: array<u32, 4>;

fn count_of(i: u32) -> u32 {
    return select(0u, counts[i], i < params.elements);
}

@compute @workgroup_size(256)
fn sum_groups(@builtin(workgroup_id) wid: vec3<u32>, @builtin(num_workgroups) groups: vec3<u32>, @builtin(local_invocation_index) lid: u32) {
    let g = group_index(wid, groups);
    if (g >= params.workgroups) {
        return;
    }
    workgroup_exclusive_prefix(lid, count_of(g * SCAN_WORKGROUP + lid));
    if (lid == 0u) {
        group_sums[g] = shared_sums[SCAN_WORKGROUP - 1u];
    }
}

@compute @workgroup_size(256)
fn scan_groups(@builtin(local_invocation_index) lid: u32) {
    let total = scan_group_sums(lid, params.workgroups);
    if (lid == 0u) {
        map_starts[2] = total;
    }
}

@compute @workgroup_size(256)
fn write_offsets(@builtin(workgroup_id) wid: vec3<u32>, @builtin(num_workgroups) groups: vec3<u32>, @builtin(local_invocation_index) lid: u32) {
    let g = group_index(wid, groups);
    if (g >= params.workgroups) {
        return;
    }
    let i = g * SCAN_WORKGROUP + lid;
    let first = group_sums[g] + workgroup_exclusive_prefix(lid, count_of(i));
    if (i < params.elements) {
        counts[i] = first;
    }
    if (i == params.paths) {
        map_starts[0] = first;
    }
    if (i == 2u * params.paths) {
        map_starts[1] = first;
    }
}

@compute @workgroup_size(256)
fn place(@builtin(workgroup_id) wid: vec3<u32>, @builtin(num_workgroups) groups: vec3<u32>, @builtin(local_invocation_index) lid: u32) {
    let i = group_index(wid, groups) * SCAN_WORKGROUP + lid;
    if (i >= min(trace_status[0], params.record_capacity)) {
        return;
    }
    let r = records[i];
    let map = r.tag & 3u;
    let slot = counts[map * params.paths + r.path] + (r.tag >> 16u);
    let base = 5u * slot;
    photons[base] = bitcast<u32>(r.position_x);
    photons[base + 1u] = bitcast<u32>(r.position_y);
    photons[base + 2u] = bitcast<u32>(r.position_z);
    photons[base + 3u] = r.power_rgb9e5;
    photons[base + 4u] = r.direction_and_class;
    bounces[slot] = (r.tag >> 8u) & 0xffu;
}

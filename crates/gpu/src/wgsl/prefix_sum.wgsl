// Exclusive prefix sums across many workgroups, in storage order, for the
// compactions that must not depend on scheduling (the LOD cull, the photon
// tracer's maps): each workgroup sums its items, one workgroup turns those
// sums into first slots (`scan_group_sums`), and each workgroup then adds
// its own prefix. The includer declares `group_sums: array<u32>` (read_write).

const SCAN_WORKGROUP: u32 = 256u;
var<workgroup> shared_sums: array<u32, 256>;

// Exclusive prefix sum of `value` over the workgroup (Hillis–Steele), and the
// workgroup's total in shared_sums[SCAN_WORKGROUP - 1]. Called in uniform
// control flow.
fn workgroup_exclusive_prefix(lid: u32, value: u32) -> u32 {
    shared_sums[lid] = value;
    workgroupBarrier();
    for (var offset = 1u; offset < SCAN_WORKGROUP; offset *= 2u) {
        var add = 0u;
        if (lid >= offset) {
            add = shared_sums[lid - offset];
        }
        workgroupBarrier();
        shared_sums[lid] += add;
        workgroupBarrier();
    }
    return shared_sums[lid] - value;
}

// Dispatches are two-dimensional (x up to 65,535 workgroups, the portable
// limit); workgroups past the last are idle. Uniform per workgroup.
fn group_index(wid: vec3<u32>, groups: vec3<u32>) -> u32 {
    return wid.y * groups.x + wid.x;
}

// Run by one whole workgroup: replaces group_sums[0..n] by their exclusive
// prefix sums and returns the total (in the invocation lid = SCAN_WORKGROUP - 1).
fn scan_group_sums(lid: u32, n: u32) -> u32 {
    let chunk = (n + SCAN_WORKGROUP - 1u) / SCAN_WORKGROUP;
    let start = min(lid * chunk, n);
    let end = min(start + chunk, n);
    var partial = 0u;
    for (var i = start; i < end; i++) {
        partial += group_sums[i];
    }
    var running = workgroup_exclusive_prefix(lid, partial);
    for (var i = start; i < end; i++) {
        let c = group_sums[i];
        group_sums[i] = running;
        running += c;
    }
    return shared_sums[SCAN_WORKGROUP - 1u];
}

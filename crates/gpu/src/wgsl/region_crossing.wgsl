// Where a ray crosses a region mesh's triangle, shared by the photon
// tracer's free flights and the optical depth of light and specular rays
// (media.wgsl), so both count the crossings hikari_core::medium::region does.

// region::intersect_triangle (Woop, Benthin and Wald's watertight test,
// two-sided, t > 0): the distance, or 0 for no crossing. The CPU takes the
// edge functions in f64; here they are f32. Each edge function is still
// exactly antisymmetric (a product rounds the same either way round), so
// the triangles sharing an edge never both count, or both miss, a ray
// through it; a ray within rounding of an edge may pick the other
// triangle than the CPU does.
fn region_crossing(o: vec3<f32>, d: vec3<f32>, a: vec3<f32>, b: vec3<f32>, c: vec3<f32>) -> f32 {
    let ad = abs(d);
    var kz = 0u;
    if (ad.y > ad.x) {
        kz = 1u;
    }
    if (ad.z > max(ad.x, ad.y)) {
        kz = 2u;
    }
    var kx = (kz + 1u) % 3u;
    var ky = (kz + 2u) % 3u;
    if (d[kz] < 0.0) {
        let swap = kx;
        kx = ky;
        ky = swap;
    }
    let sx = d[kx] / d[kz];
    let sy = d[ky] / d[kz];
    let sz = 1.0 / d[kz];
    let qa = a - o;
    let qb = b - o;
    let qc = c - o;
    let pa = vec3<f32>(qa[kx] - sx * qa[kz], qa[ky] - sy * qa[kz], sz * qa[kz]);
    let pb = vec3<f32>(qb[kx] - sx * qb[kz], qb[ky] - sy * qb[kz], sz * qb[kz]);
    let pc = vec3<f32>(qc[kx] - sx * qc[kz], qc[ky] - sy * qc[kz], sz * qc[kz]);
    let u = pc.x * pb.y - pc.y * pb.x;
    let v = pa.x * pc.y - pa.y * pc.x;
    let w = pb.x * pa.y - pb.y * pa.x;
    let det = u + v + w;
    if (det == 0.0) {
        return 0.0;
    }
    if (!(edge_inside(u, det, pb, pc) && edge_inside(v, det, pc, pa) && edge_inside(w, det, pa, pb))) {
        return 0.0;
    }
    let t = (u * pa.z + v * pb.z + w * pc.z) / det;
    return max(t, 0.0);
}

fn edge_inside(e: f32, det: f32, p: vec3<f32>, q: vec3<f32>) -> bool {
    let top_left = q.y > p.y || (q.y == p.y && q.x < p.x);
    if (det > 0.0) {
        return e > 0.0 || (e == 0.0 && top_left);
    }
    return e < 0.0 || (e == 0.0 && top_left);
}

// The BRDF a photon arriving along `photon_dir` (its travel direction) is
// weighted by at a glossy point of BRDF `b`, seen from `eye` (world, from
// the point toward the viewer), shading normal `n`: the lobes the photon
// maps stand for (photon-cpu's `part`). Its includers bind `surfaces`
// (bsdf.wgsl reads the sheen table there).
fn photon_brdf(b: Bsdf, eye: vec3<f32>, n: vec3<f32>, photon_dir: vec3<f32>) -> vec3<f32> {
    return bsdf_f_gathered(b, to_shading(eye, n), to_shading(-photon_dir, n));
}

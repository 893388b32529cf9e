// The BRDF a photon arriving along `photon_dir` (its travel direction) is
// weighted by at a glossy point of BRDF `b`, seen from `eye` (world, from
// the point toward the viewer), shading normal `n`: the lobes the photon
// maps stand for (photon-cpu's `part`), the diffuse and sheen lobes weighed
// by `k` (the bump shadowing of the photon's side, 1 where nothing bends).
// Its includers bind `surfaces` (bsdf.wgsl reads the sheen table there).
fn photon_brdf(b: Bsdf, eye: vec3<f32>, n: vec3<f32>, photon_dir: vec3<f32>, k: f32) -> vec3<f32> {
    return bsdf_f_gathered_bumped(b, to_shading(eye, n), to_shading(-photon_dir, n), k);
}

// A photon of `power` travelling along `photon_dir` as a gather at a point
// of shading normal `n` weighs it: where `bent` (the shading normal off the
// geometric `ng`), shading_normal_factor and, at a normal-mapped point, the
// bump shadowing `bump` of its side; at a `glossy` point the BRDF
// (`photon_brdf`). Callers pass `bent` as a literal, so its tests fold out
// of their loops.
fn gathered_power(power: vec3<f32>, photon_dir: vec3<f32>, n: vec3<f32>, ng: vec3<f32>, bent: bool, bump: BumpShadow, glossy: bool, b: Bsdf, eye: vec3<f32>) -> vec3<f32> {
    var weighed = power;
    var k = 1.0;
    if (bent) {
        weighed *= shading_normal_factor(-photon_dir, n, ng);
        if (bump_mapped()) {
            k = bump_term(bump, -photon_dir);
        }
    }
    if (glossy) {
        return weighed * photon_brdf(b, eye, n, photon_dir, k);
    }
    return weighed * k;
}

// The bump shadowing at a G-buffer pixel of shading normal `n` whose
// albedo.a is `packed` (geometric_normal.wgsl's `pack_kind`): none where
// no normal texture bent `n`.
fn pixel_bump(packed: f32, n: vec3<f32>) -> BumpShadow {
    let unbent = pixel_smooth_normal(packed);
    if (all(unbent == vec3<f32>(0.0))) {
        return no_bump();
    }
    return bump_shadow(unbent, n);
}

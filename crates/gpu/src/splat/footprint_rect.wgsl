// The screen rectangle a photon can light, shared by the raster splats
// (footprint.wgsl) and the tiled estimator. The includer declares `params`
// with `clip_from_world` and `radius`.

// The screen rectangle of a photon's radius-r sphere, in NDC (lo.xy,
// hi.xy), clamped to the screen: the exact bounds of the projected sphere
// (the sphere as the quadric diag(1, 1, 1, −1) mapped by T =
// clip_from_world · translate · scale; a clip plane x − s·w = 0 touches it
// where ⟨t_x − s·t_w, t_x − s·t_w⟩ = 0 for T's rows t and that form:
// Sigg et al. 2006), of a radius 1% larger against rounding. The
// projection of the sphere's bounding cube, drawn before, covered up to
// 1.3× as many pixels per axis off the view axis. A sphere reaching the
// eye plane projects unbounded: the whole screen. Wholly behind: lo > hi.
fn photon_footprint(position: vec3<f32>) -> vec4<f32> {
    let m = params.clip_from_world;
    let r = params.radius * 1.01;
    let c = m * vec4<f32>(position, 1.0);
    let tx = vec4<f32>(r * m[0].x, r * m[1].x, r * m[2].x, c.x);
    let ty = vec4<f32>(r * m[0].y, r * m[1].y, r * m[2].y, c.y);
    let tw = vec4<f32>(r * m[0].w, r * m[1].w, r * m[2].w, c.w);
    // The sphere spans w (the view depth) c.w ± |tw.xyz|.
    let reach = length(tw.xyz);
    if (c.w + reach <= 1.0e-6) {
        return vec4<f32>(1.0, 1.0, -1.0, -1.0);
    }
    if (c.w - reach <= 1.0e-6) {
        return vec4<f32>(-1.0, -1.0, 1.0, 1.0);
    }
    let ww = dot(tw.xyz, tw.xyz) - tw.w * tw.w;
    let xw = dot(tx.xyz, tw.xyz) - tx.w * tw.w;
    let yw = dot(ty.xyz, tw.xyz) - ty.w * tw.w;
    let xx = dot(tx.xyz, tx.xyz) - tx.w * tx.w;
    let yy = dot(ty.xyz, ty.xyz) - ty.w * ty.w;
    let half = sqrt(max(vec2<f32>(xw * xw - xx * ww, yw * yw - yy * ww), vec2<f32>(0.0)));
    // ww < 0 here (the sphere lies in front of the eye plane).
    let a = (vec2<f32>(xw, yw) + half) / ww;
    let b = (vec2<f32>(xw, yw) - half) / ww;
    let lo = min(a, b);
    let hi = max(a, b);
    return vec4<f32>(clamp(lo, vec2<f32>(-1.0), vec2<f32>(1.0)), clamp(hi, vec2<f32>(-1.0), vec2<f32>(1.0)));
}

// The depths (NDC z in [0, 1]) of a photon's sphere's nearest (x) and
// farthest (y) points, widened by a few ulps of the depth buffer: every
// point within the sphere lies between them, so a pixel whose G-buffer
// surface lies nearer (the surface splat's depth test, LessEqual against
// the G-buffer's depth, at x) or whose tile of pixels lies wholly outside
// them (`trimmed_footprint`) cannot see it lit by this photon. A sphere
// reaching the eye plane: (0, 1), nothing skipped.
fn photon_depth_range(position: vec3<f32>) -> vec2<f32> {
    let m = params.clip_from_world;
    let c = m * vec4<f32>(position, 1.0);
    // The view's forward direction scaled by w's rate (unit for a camera).
    let forward = vec3<f32>(m[0].w, m[1].w, m[2].w);
    let reach = length(forward);
    // Depth ulps near 1 span up to 6e-8 · w² / near in w, and near is
    // 1e-4 of the far plane: 0.4% of w is several ulps at any depth.
    let slack = 0.004 * c.w;
    let w_front = c.w - params.radius * 1.01 * reach - slack;
    if (w_front <= 1.0e-6 || reach == 0.0) {
        return vec2<f32>(0.0, 1.0);
    }
    // Along the forward axis from the centre, s world units.
    let s = params.radius * 1.01 + slack / reach;
    let dz = s * dot(vec3<f32>(m[0].z, m[1].z, m[2].z), forward) / reach;
    let front = (c.z - dz) / w_front;
    let back = (c.z + dz) / (c.w + s * reach);
    return clamp(vec2<f32>(front, back), vec2<f32>(0.0), vec2<f32>(1.0));
}

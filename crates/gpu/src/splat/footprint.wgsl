// The screen footprint of a photon's radius-r sphere, shared by the surface
// and volume splats: one instanced 4-vertex strip per surviving photon. The
// includer declares `params` with `clip_from_world` and `radius`.

// A surviving photon from the LOD pass: the stored photon and its power scale.
struct PhotonIn {
    @location(0) position: vec3<f32>,
    @location(1) power_rgb9e5: u32,
    @location(2) direction_and_class: u32,
    @location(3) scale: f32,
}

struct SplatVertex {
    @builtin(position) clip: vec4<f32>,
    @location(0) @interpolate(flat) photon_position: vec3<f32>,
    @location(1) @interpolate(flat) power_rgb9e5: u32,
    @location(2) @interpolate(flat) direction_and_class: u32,
    @location(3) @interpolate(flat) scale: f32,
}

@vertex
fn vs_main(@builtin(vertex_index) corner: u32, photon: PhotonIn) -> SplatVertex {
    // Conservative screen rectangle: the projected corners of the sphere's
    // bounding cube. A corner behind the eye plane makes the projection
    // unbounded: cover the whole screen. All corners behind: nothing visible.
    var lo = vec2<f32>(1.0e30);
    var hi = vec2<f32>(-1.0e30);
    var behind = 0u;
    for (var i = 0u; i < 8u; i++) {
        let offset = vec3<f32>(
            select(-1.0, 1.0, (i & 1u) != 0u),
            select(-1.0, 1.0, (i & 2u) != 0u),
            select(-1.0, 1.0, (i & 4u) != 0u),
        );
        let c = params.clip_from_world * vec4<f32>(photon.position + params.radius * offset, 1.0);
        if (c.w <= 1.0e-6) {
            behind += 1u;
        } else {
            lo = min(lo, c.xy / c.w);
            hi = max(hi, c.xy / c.w);
        }
    }
    if (behind > 0u) {
        lo = vec2<f32>(-1.0);
        hi = vec2<f32>(1.0);
    }
    lo = clamp(lo, vec2<f32>(-1.0), vec2<f32>(1.0));
    hi = clamp(hi, vec2<f32>(-1.0), vec2<f32>(1.0));
    if (behind == 8u) {
        hi = lo; // degenerate: no fragments
    }
    var out: SplatVertex;
    let xy = vec2<f32>(select(lo.x, hi.x, (corner & 1u) != 0u), select(lo.y, hi.y, (corner & 2u) != 0u));
    out.clip = vec4<f32>(xy, 0.0, 1.0);
    out.photon_position = photon.position;
    out.power_rgb9e5 = photon.power_rgb9e5;
    out.direction_and_class = photon.direction_and_class;
    out.scale = photon.scale;
    return out;
}

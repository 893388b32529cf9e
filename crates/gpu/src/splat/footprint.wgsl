// The screen footprint of a photon's radius-r sphere, shared by the surface
// and volume splats: one instanced 4-vertex strip per surviving photon. The
// includer declares `params` with `clip_from_world` and `radius`, and
// defines `splat_footprint(position)`: the rectangle to draw
// (`photon_footprint` or less).

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
    // The photon's decoded travel direction and power (per photon, so
    // decoded by its 4 vertices rather than its hundreds of fragments).
    @location(4) @interpolate(flat) direction: vec3<f32>,
    @location(5) @interpolate(flat) power: vec3<f32>,
}

@vertex
fn vs_main(@builtin(vertex_index) corner: u32, photon: PhotonIn) -> SplatVertex {
    let footprint = splat_footprint(photon.position);
    let lo = footprint.xy;
    // Nothing visible: a degenerate quad (no fragments).
    let hi = select(footprint.zw, lo, footprint.x > footprint.z);
    var out: SplatVertex;
    let xy = vec2<f32>(select(lo.x, hi.x, (corner & 1u) != 0u), select(lo.y, hi.y, (corner & 2u) != 0u));
    // At the sphere's front depth: the surface splat's depth test skips
    // pixels whose surface lies nearer (photon_depth_range).
    out.clip = vec4<f32>(xy, photon_depth_range(photon.position).x, 1.0);
    out.photon_position = photon.position;
    out.power_rgb9e5 = photon.power_rgb9e5;
    out.direction_and_class = photon.direction_and_class;
    out.scale = photon.scale;
    out.direction = decode_octahedral_15(photon.direction_and_class & 0x3fffffffu);
    out.power = decode_rgb9e5(photon.power_rgb9e5);
    return out;
}

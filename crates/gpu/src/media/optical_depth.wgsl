// Optical depth of the region meshes along every view ray, in slices
// (METHOD.md §5, eq. 5.25–5.30). Each region triangle is rasterized with
// no depth test and no culling; a fragment at distance d adds
// sign · σ_t · min(d, D) with D = l·(slice+1)/S the slice's distance along
// the pixel's view ray of length l: + where the ray leaves the medium (the
// face's back), − where it enters. Summed over all faces ahead of the eye
// this is the length inside each region up to D, eye inside or not.
// media.wgsl is prepended.

@group(0) @binding(0) var<uniform> media: MediaParams;
@group(0) @binding(1) var<storage, read> regions: array<RegionTriangle>;
@group(0) @binding(2) var gbuffer_position: texture_2d<f32>;
@group(0) @binding(3) var<uniform> clip_from_world: mat4x4<f32>;

struct RegionVertex {
    @builtin(position) clip: vec4<f32>,
    @location(0) world: vec3<f32>,
    @location(1) @interpolate(flat) sigma_t: vec3<f32>,
    @location(2) @interpolate(flat) slice: u32,
}

// Vertices pulled from `regions`; the instance index is the slice.
@vertex
fn vs_main(@builtin(vertex_index) index: u32, @builtin(instance_index) slice: u32) -> RegionVertex {
    let tri = regions[index / 3u];
    var corners = array<vec3<f32>, 3>(tri.a.xyz, tri.b.xyz, tri.c.xyz);
    let world = corners[index % 3u];
    var out: RegionVertex;
    let clip = clip_from_world * vec4<f32>(world, 1.0);
    // Depth pinned inside [0, w]: nothing is clipped by the near or far
    // plane, only at the eye plane (w = 0), so faces beyond the far plane
    // still count.
    out.clip = vec4<f32>(clip.xy, 0.5 * clip.w, clip.w);
    out.world = world;
    out.sigma_t = tri.sigma_t.xyz;
    out.slice = slice;
    return out;
}

@fragment
fn fs_main(in: RegionVertex, @builtin(front_facing) front: bool) -> @location(0) vec4<f32> {
    let pixel = vec2<i32>(in.clip.xy);
    let ray = view_ray(textureLoad(gbuffer_position, pixel, 0), in.clip.xy);
    let d = distance(in.world, media.camera_position);
    let slice_end = ray.w * f32(in.slice + 1u) / f32(media.slices);
    // Counter-clockwise faces are front faces: seen from their outside, so
    // the view ray enters there.
    let sign = select(1.0, -1.0, front);
    return vec4<f32>(sign * in.sigma_t * min(d, slice_end), 0.0);
}

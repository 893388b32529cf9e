// Shadow views: each layer of the shadow-map array stores, per texel, the
// depth of the nearest surface seen through it (shadow_view.wgsl's
// `shadow_depth`), divided by the view's range so it fits in [0, 1].
// Cut-outs (alphaMode MASK) cast no shadow where they are cut; BLEND
// surfaces cast it from a fraction alpha of their fragments, chosen afresh
// each pass (the renderer redraws the views every pass of a scene with one).

@group(0) @binding(0) var<uniform> view: ShadowView;
@group(1) @binding(0) var<storage, read> surfaces: Surfaces;
@group(1) @binding(1) var<storage, read> texture_data: array<u32>;

// scene_upload::HAS_UV, and light_samples::NO_SURFACE (an emissive mesh's
// own triangles drawn as occluders: opaque).
const HAS_UV: u32 = 0x80000000u;
const NO_SURFACE: u32 = 0x7fffffffu;

struct VertexOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) world: vec3<f32>,
    @location(1) @interpolate(flat) surface: u32,
    @location(2) uv: vec2<f32>,
}

@vertex
fn vs_main(@location(0) position: vec3<f32>, @location(3) surface: u32, @location(4) uv: vec2<f32>) -> VertexOut {
    var out: VertexOut;
    out.clip = view.clip_from_world * vec4<f32>(position, 1.0);
    out.world = position;
    out.surface = surface;
    out.uv = uv;
    return out;
}

@fragment
fn fs_main(in: VertexOut) -> @location(0) vec4<f32> {
    let dx = dpdx(in.uv);
    let dy = dpdy(in.uv);
    let id = in.surface & ~HAS_UV;
    if (CUT_OUTS && id != NO_SURFACE) {
        let uv = vec3<f32>(in.uv, select(0.0, 1.0, (in.surface & HAS_UV) != 0u));
        let s = surfaces.all[id];
        if (!is_there_for_fragment(s, surface_point(s, uv, dx, dy).alpha, in.clip, view.blend_seed.x)) {
            discard;
        }
    }
    return vec4<f32>(shadow_depth(view, in.world) / view.light_position.w, 0.0, 0.0, 0.0);
}

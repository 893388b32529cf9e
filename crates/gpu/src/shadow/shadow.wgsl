// Shadow views: each layer of the shadow-map array stores, per texel, the
// depth of the nearest surface seen through it (shadow_view.wgsl's
// `shadow_depth`), divided by the view's range so it fits in [0, 1].

@group(0) @binding(0) var<uniform> view: ShadowView;

struct VertexOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) world: vec3<f32>,
}

@vertex
fn vs_main(@location(0) position: vec3<f32>) -> VertexOut {
    var out: VertexOut;
    out.clip = view.clip_from_world * vec4<f32>(position, 1.0);
    out.world = position;
    return out;
}

@fragment
fn fs_main(in: VertexOut) -> @location(0) vec4<f32> {
    return vec4<f32>(shadow_depth(view, in.world) / view.light_position.w, 0.0, 0.0, 0.0);
}

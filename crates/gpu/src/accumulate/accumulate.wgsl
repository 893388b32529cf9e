// The running mean of frames (the viewer's still camera: each frame comes
// from a fresh photon set): the sum of the frames since the last reset is
// kept in f32 per pixel, and the output is sum / count.

struct AccumulateParams {
    width: u32,
    height: u32,
    // Frames in the sum once this one is added (1 after a reset).
    count: u32,
    _pad: u32,
}

@group(0) @binding(0) var<uniform> params: AccumulateParams;
@group(0) @binding(1) var frame: texture_2d<f32>;
@group(0) @binding(2) var<storage, read_write> sum: array<vec4<f32>>;
@group(0) @binding(3) var mean: texture_storage_2d<rgba32float, write>;

// Workgroups of WORKGROUP × WORKGROUP pixels (set by the pipeline).
override WORKGROUP: u32;

@compute @workgroup_size(WORKGROUP, WORKGROUP)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    if (id.x >= params.width || id.y >= params.height) {
        return;
    }
    let index = id.y * params.width + id.x;
    let value = textureLoad(frame, vec2<i32>(id.xy), 0);
    var total = value;
    if (params.count > 1u) {
        total += sum[index];
    }
    sum[index] = total;
    textureStore(mean, vec2<i32>(id.xy), total / f32(params.count));
}

// The running mean of frames (the viewer's still camera, the progressive
// render's passes: each frame comes from a fresh photon set): the sum of the
// frames since the last reset is kept in f32 per pixel, and the output is
// sum / count; the odd frames' sum and mean likewise (the noise estimate's
// half-images).

struct AccumulateParams {
    width: u32,
    height: u32,
    // Frames in the sum once this one is added (1 after a reset).
    count: u32,
    _pad: u32,
}

@group(0) @binding(0) var<uniform> params: AccumulateParams;
@group(0) @binding(1) var frame: texture_2d<f32>;
// All frames' sums (first width × height entries), then the odd frames'.
@group(0) @binding(2) var<storage, read_write> sum: array<vec4<f32>>;
@group(0) @binding(3) var mean: texture_storage_2d<rgba32float, write>;
@group(0) @binding(4) var odd_mean: texture_storage_2d<rgba32float, write>;

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
    if (params.count % 2u == 1u) {
        let odd_index = params.width * params.height + index;
        var odd_total = value;
        if (params.count > 1u) {
            odd_total += sum[odd_index];
        }
        sum[odd_index] = odd_total;
        textureStore(odd_mean, vec2<i32>(id.xy), odd_total / f32((params.count + 1u) / 2u));
    }
}

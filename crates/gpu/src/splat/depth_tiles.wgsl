// The range of depths (NDC z, as the depth buffer holds them; 1 where no
// surface is seen) the G-buffer holds in each DEPTH_TILE² block of pixels:
// what the surface splat trims its quads by (splat.wgsl, `trimmed_footprint`).

struct DepthTileParams {
    clip_from_world: mat4x4<f32>,
}

@group(0) @binding(0) var<uniform> tile_params: DepthTileParams;
@group(0) @binding(1) var gbuffer_position: texture_2d<f32>;
// x: the nearest depth, y: the farthest.
@group(0) @binding(2) var tiles: texture_storage_2d<rgba32float, write>;

@compute @workgroup_size(8, 8)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    let count = textureDimensions(tiles);
    if (id.x >= count.x || id.y >= count.y) {
        return;
    }
    let size = textureDimensions(gbuffer_position);
    var lo = 1.0;
    var hi = 0.0;
    for (var y = 0u; y < DEPTH_TILE; y++) {
        for (var x = 0u; x < DEPTH_TILE; x++) {
            let p = id.xy * DEPTH_TILE + vec2<u32>(x, y);
            if (p.x >= size.x || p.y >= size.y) {
                continue;
            }
            let position = textureLoad(gbuffer_position, vec2<i32>(p), 0);
            var z = 1.0;
            if (position.w != 0.0) {
                let c = tile_params.clip_from_world * vec4<f32>(position.xyz, 1.0);
                z = c.z / c.w;
            }
            lo = min(lo, z);
            hi = max(hi, z);
        }
    }
    textureStore(tiles, vec2<i32>(id.xy), vec4<f32>(lo, hi, 0.0, 0.0));
}

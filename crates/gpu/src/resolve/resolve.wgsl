// Resolve: the frame's linear radiance, emission + direct + indirect +
// caustics + specular. Tone mapping happens on output (hikari_core::output),
// the same for every renderer.

@group(0) @binding(0) var emission: texture_2d<f32>;
@group(0) @binding(1) var direct: texture_2d<f32>;
@group(0) @binding(2) var indirect: texture_2d<f32>;
@group(0) @binding(3) var caustic: texture_2d<f32>;
@group(0) @binding(4) var specular: texture_2d<f32>;
@group(0) @binding(5) var output: texture_storage_2d<rgba32float, write>;

@compute @workgroup_size(8, 8)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    let size = textureDimensions(output);
    if (id.x >= size.x || id.y >= size.y) {
        return;
    }
    let p = vec2<i32>(id.xy);
    let sum = textureLoad(emission, p, 0).rgb + textureLoad(direct, p, 0).rgb + textureLoad(indirect, p, 0).rgb
        + textureLoad(caustic, p, 0).rgb + textureLoad(specular, p, 0).rgb;
    textureStore(output, p, vec4<f32>(sum, 1.0));
}

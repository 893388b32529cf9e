// The G-buffer through storage textures, for adapters that cannot render
// to Rgba32Float (Mesa's OpenGL): after a depth-only pass of vs_main, the
// scene is drawn again with the depth test `Equal` done before the fragment
// shader (early_depth_test), so only each pixel's nearest fragment runs
// and stores the same four values as fs_main. Appended to gbuffer.wgsl.

@group(0) @binding(3) var out_position: texture_storage_2d<rgba32float, write>;
@group(0) @binding(4) var out_normal: texture_storage_2d<rgba32float, write>;
@group(0) @binding(5) var out_albedo: texture_storage_2d<rgba32float, write>;
@group(0) @binding(6) var out_emission: texture_storage_2d<rgba32float, write>;

@fragment
@early_depth_test(force)
fn fs_storage(in: VertexOut) {
    let g = shade(in);
    let pixel = vec2<i32>(in.clip.xy);
    textureStore(out_position, pixel, g.position);
    textureStore(out_normal, pixel, g.normal);
    textureStore(out_albedo, pixel, g.albedo);
    textureStore(out_emission, pixel, g.emission);
}

// The G-buffer through storage textures, for adapters that cannot render
// to Rgba32Float (Mesa's OpenGL): after a depth-only pass of vs_main, the
// scene is drawn again with the depth test `Equal` done before the fragment
// shader (early_depth_test), so only each pixel's nearest fragment runs
// and stores the same four values as fs_main. Appended to gbuffer.wgsl.

@group(0) @binding(3) var out_position: texture_storage_2d<rgba32float, write>;
@group(0) @binding(4) var out_normal: texture_storage_2d<rgba32float, write>;
@group(0) @binding(5) var out_albedo: texture_storage_2d<rgba32float, write>;
@group(0) @binding(6) var out_emission: texture_storage_2d<rgba32float, write>;

// LAYERED scenes' fifth target (gbuffer.wgsl's `fs_main_layered`), bound
// only for `fs_storage_layered`.
@group(0) @binding(7) var out_layers: texture_storage_2d<rgba32uint, write>;

fn store_pixel(in: VertexOut) -> Shaded {
    let s = shade(in);
    let pixel = vec2<i32>(in.clip.xy);
    textureStore(out_position, pixel, s.g.position);
    textureStore(out_normal, pixel, s.g.normal);
    textureStore(out_albedo, pixel, s.g.albedo);
    textureStore(out_emission, pixel, s.g.emission);
    return s;
}

@fragment
@early_depth_test(force)
fn fs_storage(in: VertexOut) {
    store_pixel(in);
}

@fragment
@early_depth_test(force)
fn fs_storage_layered(in: VertexOut) {
    let s = store_pixel(in);
    textureStore(out_layers, vec2<i32>(in.clip.xy), s.layers);
}

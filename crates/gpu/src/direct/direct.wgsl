// Direct light at every visible diffuse pixel, attenuated by the media on the
// way from each light sample (media.wgsl and light_eval.wgsl prepended).

@group(0) @binding(0) var<uniform> direct_params: DirectParams;
@group(0) @binding(1) var<storage, read> lights: array<Light>;
@group(0) @binding(2) var<storage, read> samples: array<LightSample>;
@group(0) @binding(3) var<storage, read> views: array<ShadowView>;
@group(0) @binding(4) var shadow_maps: texture_2d_array<f32>;
@group(0) @binding(5) var gbuffer_position: texture_2d<f32>;
@group(0) @binding(6) var gbuffer_normal: texture_2d<f32>;
@group(0) @binding(7) var gbuffer_albedo: texture_2d<f32>;
@group(0) @binding(8) var<uniform> media: MediaParams;
@group(0) @binding(9) var<storage, read> regions: array<RegionTriangle>;
@group(0) @binding(10) var<storage, read> surfaces: Surfaces;
@group(0) @binding(11) var gbuffer_emission: texture_2d<f32>;
// The layer textures' texels (read where LAYERED; layer_texels.wgsl).
@group(0) @binding(12) var gbuffer_layers: texture_2d<u32>;



@fragment
fn fs_main(@builtin(position) frag: vec4<f32>) -> @location(0) vec4<f32> {
    let pixel = vec2<i32>(frag.xy);
    let position = textureLoad(gbuffer_position, pixel, 0);
    let albedo = textureLoad(gbuffer_albedo, pixel, 0);
    // Diffuse and glossy surfaces, and the inside of a glass mix.
    let kind = pixel_kind(albedo.a);
    if (position.w == 0.0 || (kind != 0u && kind != KIND_MIXED_INSIDE)) {
        return vec4<f32>(0.0);
    }
    let x = position.xyz;
    let g = textureLoad(gbuffer_normal, pixel, 0);
    let n = g.xyz;
    var s = surfaces.all[u32(g.w)];
    var layers = vec4<u32>(0u);
    if (LAYERED) {
        layers = textureLoad(gbuffer_layers, pixel, 0);
        s = pixel_surface(s, layers);
    }
    let b = pixel_coat(pixel_bsdf(s, albedo.rgb, textureLoad(gbuffer_emission, pixel, 0).w), s, layers);
    var r = surface_reflector(s, b, unit(media.camera_position - x), n);
    if (BENT && position.w < 0.0) {
        shaded_geometric_normal = unpack_geometric_normal(position.w, n);
        let unbent = pixel_smooth_normal(albedo.a);
        if (bump_mapped() && any(unbent != vec3<f32>(0.0))) {
            r.bump = bump_shadow(unbent, n);
        }
    }
    // Glossy points sample their lobe and area lights: a new stream each pass.
    var rng = pixel_stream(vec2<u32>(pixel), direct_params.pass_index, 1u);
    return vec4<f32>(direct_radiance(x, n, r, &rng), 1.0);
}

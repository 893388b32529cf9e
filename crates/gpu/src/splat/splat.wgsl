// Photon splat (METHOD.md §4): one instanced quad per photon covering the
// screen footprint of its radius-r sphere; each fragment adds the photon's
// contribution (eq. 4.3) at the surface point the G-buffer holds for it.
// Prepended with estimate.wgsl and footprint.wgsl.

struct SplatParams {
    clip_from_world: mat4x4<f32>,
    radius: f32,
    // Watts per unit of stored photon power.
    power_unit: f32,
    normal_test: u32,
    _pad: u32,
    // The eye, for glossy surfaces' BRDF.
    camera_position: vec3<f32>,
    _pad1: u32,
}

@group(0) @binding(0) var<uniform> params: SplatParams;
@group(0) @binding(1) var gbuffer_position: texture_2d<f32>;
@group(0) @binding(2) var gbuffer_normal: texture_2d<f32>;
@group(0) @binding(3) var gbuffer_albedo: texture_2d<f32>;
@group(0) @binding(4) var<storage, read> surfaces: Surfaces;
@group(0) @binding(5) var gbuffer_emission: texture_2d<f32>;
// The layer textures' texels (read where LAYERED; layer_texels.wgsl).
@group(0) @binding(7) var gbuffer_layers: texture_2d<u32>;

// Tiles of the G-buffer's depth range (depth_tiles.rs), read by the
// vertex shader.
@group(0) @binding(6) var depth_tiles: texture_2d<f32>;

// The photon's footprint trimmed to the tiles whose depth range meets its
// sphere's (photon_depth_range): only their pixels can hold a point within
// r of it. No tile: nothing drawn. Quads over more than TRIM_TILES tiles a
// side are drawn whole (the loop reads that many squared).
fn splat_footprint(position: vec3<f32>) -> vec4<f32> {
    let rect = photon_footprint(position);
    if (rect.x > rect.z || rect.y > rect.w) {
        return rect;
    }
    let size = vec2<f32>(textureDimensions(gbuffer_position));
    let tiles = vec2<i32>(textureDimensions(depth_tiles));
    // NDC to pixels (y down).
    let px_lo = vec2<f32>(rect.x + 1.0, 1.0 - rect.w) * 0.5 * size;
    let px_hi = vec2<f32>(rect.z + 1.0, 1.0 - rect.y) * 0.5 * size;
    let t0 = clamp(vec2<i32>(floor(px_lo / f32(DEPTH_TILE))), vec2<i32>(0), tiles - 1);
    let t1 = clamp(vec2<i32>(floor(px_hi / f32(DEPTH_TILE))), vec2<i32>(0), tiles - 1);
    if (any(t1 - t0 >= vec2<i32>(i32(TRIM_TILES)))) {
        return rect;
    }
    let depth = photon_depth_range(position);
    var lo = tiles;
    var hi = vec2<i32>(-1);
    for (var y = t0.y; y <= t1.y; y++) {
        for (var x = t0.x; x <= t1.x; x++) {
            let range = textureLoad(depth_tiles, vec2<i32>(x, y), 0).xy;
            if (range.x <= depth.y && range.y >= depth.x) {
                lo = min(lo, vec2<i32>(x, y));
                hi = max(hi, vec2<i32>(x, y));
            }
        }
    }
    if (hi.x < 0) {
        return vec4<f32>(1.0, 1.0, -1.0, -1.0);
    }
    // The tiles' pixel edges back in NDC, within the sphere's rectangle.
    let edge_lo = vec2<f32>(lo * i32(DEPTH_TILE)) / size;
    let edge_hi = vec2<f32>((hi + 1) * i32(DEPTH_TILE)) / size;
    let trimmed = vec4<f32>(edge_lo.x * 2.0 - 1.0, 1.0 - edge_hi.y * 2.0, edge_hi.x * 2.0 - 1.0, 1.0 - edge_lo.y * 2.0);
    return vec4<f32>(max(rect.xy, trimmed.xy), min(rect.zw, trimmed.zw));
}

@fragment
fn fs_main(in: SplatVertex) -> @location(0) vec4<f32> {
    let pixel = vec2<i32>(in.clip.xy);
    let position = textureLoad(gbuffer_position, pixel, 0);
    let albedo = textureLoad(gbuffer_albedo, pixel, 0);
    // Only visible diffuse surfaces (kind 0) take photon light.
    if (position.w == 0.0 || pixel_kind(albedo.a) != 0u) {
        discard;
    }
    let g = textureLoad(gbuffer_normal, pixel, 0);
    let normal = g.xyz;
    let d = position.xyz - in.photon_position;
    let direction = in.direction;
    if (!photon_accepted(dot(d, d), direction, normal, params.radius, params.normal_test != 0u)) {
        discard;
    }
    // ρ/(π² r²) on a Lambertian surface; on a glossy one (the only ones
    // that pay for the eye, the BRDF and the G-buffer's metal-roughness)
    // the BRDF for the photon's own direction over π r².
    // At a bent point (position.w < 0: smooth-shaded and normal-mapped
    // meshes) the photon weighs as photon-cpu weighs it: shading_normal_factor,
    // and where a normal texture bent it the bump shadowing of its side.
    var bent_factor = 1.0;
    var k = 1.0;
    if (BENT && position.w < 0.0) {
        bent_factor = shading_normal_factor(-direction, normal, unpack_geometric_normal(position.w, normal));
        if (bump_mapped()) {
            k = bump_term(pixel_bump(albedo.a, normal), -direction);
        }
    }
    var weight = radiance_per_power(albedo.rgb, params.radius) * k;
    var surface = surfaces.all[u32(g.w)];
    if (GLOSSY && surface.glossy != 0u) {
        var layers = vec4<u32>(0u);
        if (LAYERED) {
            layers = textureLoad(gbuffer_layers, pixel, 0);
            surface = pixel_surface(surface, layers);
        }
        let b = pixel_coat(pixel_bsdf(surface, albedo.rgb, textureLoad(gbuffer_emission, pixel, 0).w), surface, layers);
        let eye = unit(params.camera_position - position.xyz);
        weight = photon_brdf(b, eye, normal, direction, k) * radiance_per_weighted_power(params.radius);
    }
    weight *= bent_factor;
    let radiance = weight * in.power * (params.power_unit * in.scale);
    // Alpha counts the photons that reached the pixel.
    return vec4<f32>(radiance, 1.0);
}

// Resolve: the frame's linear radiance: the surface light (emission + direct
// + indirect + caustics + specular), or the sky where the pixel sees no
// surface, attenuated by the media between the eye and the surface, plus
// the light the media scatter toward the eye. Tone
// mapping happens on output (hikari_core::output), the same for every
// renderer. Prepended with media.wgsl and view_depth.wgsl.

@group(0) @binding(0) var emission: texture_2d<f32>;
@group(0) @binding(1) var direct: texture_2d<f32>;
@group(0) @binding(2) var indirect: texture_2d<f32>;
@group(0) @binding(3) var caustic: texture_2d<f32>;
@group(0) @binding(4) var specular: texture_2d<f32>;
@group(0) @binding(5) var output: texture_storage_2d<rgba32float, write>;
@group(0) @binding(6) var volume: texture_2d<f32>;
@group(0) @binding(7) var gbuffer_position: texture_2d<f32>;
@group(0) @binding(8) var<uniform> media: MediaParams;
@group(0) @binding(9) var<storage, read> regions: array<RegionTriangle>;
@group(0) @binding(10) var slices_tex: texture_2d_array<f32>;

// Which terms the image holds (1 or 0 each; the viewer's toggles).
struct Terms {
    direct: f32,
    indirect: f32,
    caustic: f32,
    specular: f32,
    volume: f32,
    _pad0: f32,
    _pad1: f32,
    _pad2: f32,
}
@group(0) @binding(11) var<uniform> terms: Terms;
// rgb: radiance of rays that leave the scene (the sky's; zero without one).
@group(0) @binding(12) var<uniform> sky: vec4<f32>;
// The sky image (textures::environment_words), by which `sky` is multiplied.
@group(0) @binding(13) var<storage, read> environment: array<u32>;

fn environment_word(i: u32) -> u32 {
    return environment[i];
}

// Workgroups of WORKGROUP × WORKGROUP pixels (set by the pipeline).
override WORKGROUP: u32;

@compute @workgroup_size(WORKGROUP, WORKGROUP)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    let size = textureDimensions(output);
    if (id.x >= size.x || id.y >= size.y) {
        return;
    }
    let p = vec2<i32>(id.xy);
    var surface = textureLoad(emission, p, 0).rgb + terms.direct * textureLoad(direct, p, 0).rgb
        + terms.indirect * textureLoad(indirect, p, 0).rgb + terms.caustic * textureLoad(caustic, p, 0).rgb
        + terms.specular * textureLoad(specular, p, 0).rgb;
    let position = textureLoad(gbuffer_position, p, 0);
    let ray = view_ray(position, vec2<f32>(p) + 0.5);
    if (position.w == 0.0) {
        surface += sky.rgb * environment_radiance(ray.xyz);
    }
    let transmittance = exp(-view_optical_depth(p, ray.w, ray.w));
    let sum = transmittance * surface + terms.volume * textureLoad(volume, p, 0).rgb;
    textureStore(output, p, vec4<f32>(sum, 1.0));
}

// The sky image (textures::environment_words): the radiance toward `dir`
// (unit, toward the sky) by hikari_core::envmap's mapping, nearest texel,
// without the light's factor; 1 where the scene has no image (the factor
// is then the uniform sky's radiance). The includer defines
// `fn environment_word(i: u32) -> u32`, the image's words.
fn environment_radiance(dir: vec3<f32>) -> vec3<f32> {
    let width = environment_word(0);
    let height = environment_word(1);
    if (!SKY_IMAGE || width == 0u) {
        return vec3<f32>(1.0);
    }
    // u = ½ + atan2(z, x)/2π, v = acos(y)/π (Blender's layout).
    let u = 0.5 + atan2(dir.z, dir.x) / (2.0 * PI);
    let v = acos(clamp(dir.y, -1.0, 1.0)) / PI;
    let x = min(u32((u - floor(u)) * f32(width)), width - 1u);
    let y = min(u32(v * f32(height)), height - 1u);
    let at = 2u + 3u * (y * width + x);
    return vec3<f32>(bitcast<f32>(environment_word(at)), bitcast<f32>(environment_word(at + 1u)), bitcast<f32>(environment_word(at + 2u)));
}

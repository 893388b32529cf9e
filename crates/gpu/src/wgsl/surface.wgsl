// A surface's material as the GPU passes read it (scene_upload::GpuSurface):
// kind 0 diffuse (albedo ρ_d, specular ρ_s), 1 mirror (albedo is its
// reflectance), 2 glass (ior), 3 an area light's body (emission).

struct Surface {
    albedo: vec3<f32>,
    kind: u32,
    emission: vec3<f32>,
    ior: f32,
    specular: vec3<f32>,
    _pad: u32,
}

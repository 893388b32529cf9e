// A surface's material as the GPU passes read it (scene_upload::GpuSurface):
// kind 0 diffuse (albedo ρ_d, specular ρ_s), 1 mirror (albedo is its
// reflectance), 2 glass (ior), 3 an area light's black body. `emission`
// leaves the front face (the geometric normal's side), or both faces when
// `two_sided` is 1; emissive meshes emit from surfaces of any kind. A
// kind-0 surface with `glossy` 1 reflects by the glTF BRDF (bsdf.wgsl) of
// base colour `albedo` (the G-buffer's, with textures), `metallic`,
// `roughness`, `specular_factor`, `clearcoat` (with its roughness) and
// `sheen_color` (with its roughness); otherwise it is Lambertian.

// The G-buffer's kind for the base drawn on the back face of a surface
// that mixes in glass (inside its body): direct light as kind 0's, no
// photon gathers (no photon is stored there), a sampled bounce in the
// specular pass (scene_upload::kind::MIXED_INSIDE).
const KIND_MIXED_INSIDE: u32 = 4u;

struct Surface {
    albedo: vec3<f32>,
    kind: u32,
    emission: vec3<f32>,
    ior: f32,
    specular: vec3<f32>,
    two_sided: u32,
    metallic: f32,
    roughness: f32,
    specular_factor: f32,
    glossy: u32,
    // Textures (textures.wgsl's `surface_point`): `emission` per unit of
    // the emissive texture, MASK's cut-off (negative: opaque; ALPHA_BLEND:
    // BLEND, surface_point.wgsl's `is_there`), texture
    // references (0xffffffff: none) and the base colour factor's alpha.
    emission_per_texel: vec3<f32>,
    alpha_cutoff: f32,
    base_color_texture: u32,
    metallic_roughness_texture: u32,
    emissive_texture: u32,
    alpha_factor: f32,
    // The normal texture and its scale (surface_point.wgsl's `bent_normal`).
    normal_texture: u32,
    normal_scale: f32,
    // The clear coat over the glTF BRDF (bsdf.wgsl; 0: none).
    clearcoat: f32,
    clearcoat_roughness: f32,
    // The glTF BRDF's dielectric reflectance at normal incidence.
    dielectric_f0: f32,
    // The sheen over the glTF BRDF (bsdf.wgsl; black: none).
    sheen_roughness: f32,
    // The share of a kind-0 surface's base let through as glass of IOR
    // `transmission_ior` (0: none), times the R of `transmission_texture`
    // (surface_point.wgsl's `draw_layer`).
    transmission: f32,
    transmission_texture: u32,
    sheen_color: vec3<f32>,
    transmission_ior: f32,
    // KHR_materials_specular's colour, scaling the dielectric's F0; for
    // glass, its inside's absorption (`glass_absorption`).
    specular_color: vec3<f32>,
    // Where the clear-coat, sheen and specular textures' references start
    // in the texture buffer (0xffffffff: none; surface_point.wgsl's
    // `layer_texels`): they multiply the factors above per point.
    layer_textures: u32,
}

// A glass surface's inside absorption per scene unit (kind 2 keeps it in
// `specular_color`, which glass has no use for: scene_upload::GpuSurface).
fn glass_absorption(s: Surface) -> vec3<f32> {
    return s.specular_color;
}

// The surfaces buffer (scene_upload::surfaces_contents): the sheen's albedo
// table, which bsdf.wgsl reads, then one record per surface. Passes bind it
// as `surfaces` and read `surfaces.all[id]`.
struct Surfaces {
    sheen_albedo: array<f32, 1024>,
    all: array<Surface>,
}

//! The scene as the rasterizer sees it: one vertex buffer of triangles
//! (analytic spheres tessellated finely) and a storage buffer of surfaces.

use bytemuck::{Pod, Zeroable};
use glam::Vec3;
use hikari_core::geometry::FlatBvh;
use hikari_core::material::Material;
use hikari_core::scene::Scene;
use hikari_core::texture::AlphaMode;

/// `GpuSurface::alpha_cutoff` of an `alphaMode` BLEND surface: beyond any
/// cut-off, so surface_point.wgsl's `is_there` knows it (its `ALPHA_BLEND`).
pub const ALPHA_BLEND: f32 = 2.0;
use wgpu::util::DeviceExt;

/// One rasterized vertex. Mirrors `VertexIn` in gbuffer.wgsl.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct GpuVertex {
    pub position: [f32; 3],
    /// Shading normal (smooth for OBJ normals and spheres).
    pub normal: [f32; 3],
    /// The triangle's geometric normal (winding side; outward for spheres).
    pub geometric_normal: [f32; 3],
    /// The surface id, with `HAS_UV` set where `uv` holds the vertex's
    /// texture coordinates.
    pub surface: u32,
    pub uv: [f32; 2],
    /// The vertex's stored tangent (`hikari_core::texture::PackedTangent`,
    /// read as `Snorm16x4`); zero where its triangle has none.
    pub tangent: [i16; 4],
}

/// `GpuVertex::surface`'s flag: the triangle has texture coordinates.
pub const HAS_UV: u32 = 1 << 31;

/// Material kinds as the G-buffer stores them.
pub mod kind {
    pub const DIFFUSE: u32 = 0;
    pub const MIRROR: u32 = 1;
    pub const GLASS: u32 = 2;
    pub const EMITTER: u32 = 3;
    /// Written by the G-buffer alone (surface.wgsl's `KIND_MIXED_INSIDE`):
    /// the base drawn on the back face of a surface that mixes in glass.
    pub const MIXED_INSIDE: u32 = 4;
}

/// Per-surface shading data. Mirrors `Surface` in gbuffer.wgsl.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct GpuSurface {
    pub albedo: [f32; 3],
    pub kind: u32,
    /// Radiance emitted toward the side the geometric normal faces (area
    /// lights' bodies, emissive meshes), or toward both sides when
    /// `two_sided` is 1: `Light::emitted_radiance`.
    pub emission: [f32; 3],
    /// Index of refraction (glass).
    pub ior: f32,
    /// Mirror reflectance ρ_s of diffuse + mirror materials.
    pub specular: [f32; 3],
    /// 1 where `emission` leaves both faces (two-sided emissive meshes).
    pub two_sided: u32,
    /// The glTF BRDF's parameters (`hikari_core::bsdf::Bsdf`) where
    /// `glossy` is 1; `albedo` is then its base colour.
    pub metallic: f32,
    pub roughness: f32,
    pub specular_factor: f32,
    /// 1: a kind-0 surface reflecting by the glTF BRDF (a `Pbr` material
    /// with a specular lobe); 0: Lambertian `albedo`, plus the mirror part
    /// `specular`.
    pub glossy: u32,
    /// What textures make of the surface (`hikari_core::texture::Texturing`):
    /// `emission` per unit of the emissive texture (the emitter's uniform
    /// radiance over the texture's mean), and `alphaMode` MASK's cut-off
    /// (negative: opaque; `ALPHA_BLEND`: BLEND).
    pub emission_per_texel: [f32; 3],
    pub alpha_cutoff: f32,
    /// `textures::texture_ref`s (`textures::NO_TEXTURE` for none).
    pub base_color_texture: u32,
    pub metallic_roughness_texture: u32,
    pub emissive_texture: u32,
    /// `baseColorFactor`'s alpha, against the cut-off.
    pub alpha_factor: f32,
    /// The normal texture (`NO_TEXTURE` for none) and its `scale`: the
    /// G-buffer's normal is bent by it (`bent_normal`).
    pub normal_texture: u32,
    pub normal_scale: f32,
    /// The glTF BRDF's clear coat (`Bsdf::clearcoat`, 0: none) and its
    /// roughness, where `glossy` is 1.
    pub clearcoat: f32,
    pub clearcoat_roughness: f32,
    /// The glTF BRDF's dielectric reflectance at normal incidence
    /// (`Bsdf::f0`, from KHR_materials_ior).
    pub dielectric_f0: f32,
    /// The glTF BRDF's sheen roughness (`Bsdf::sheen_roughness`).
    pub sheen_roughness: f32,
    /// The share of a kind-0 surface's dielectric base let through as glass
    /// (`hikari_core::texture::Transmission`: its factor, 0: none; times
    /// the R of `transmission_texture`), glass of IOR `transmission_ior`:
    /// surface_point.wgsl's `draw_layer` draws it per point.
    pub transmission: f32,
    pub transmission_texture: u32,
    /// The glTF BRDF's sheen colour (`Bsdf::sheen_color`, black: none).
    pub sheen_color: [f32; 3],
    pub transmission_ior: f32,
    /// The glTF BRDF's specular colour (`Bsdf::specular_color`, white:
    /// glTF's default); for glass (kind 2), which has no such colour, its
    /// inside's absorption per scene unit (`Dielectric::absorption`,
    /// KHR_materials_volume; surface.wgsl's `glass_absorption`). Shared
    /// rather than a field of its own: 16 more bytes a surface cost every
    /// pass that reads surfaces (the splat passes 5–7% on llvmpipe).
    pub specular_color: [f32; 3],
    /// Where the surface's clear-coat, sheen and specular textures'
    /// references start in the texture buffer (`TextureViews::layer_table`;
    /// `NO_TEXTURE`: none, or drawn as their means): those textures
    /// multiply `clearcoat`, `clearcoat_roughness`, `sheen_color`,
    /// `sheen_roughness`, `specular_factor` and `specular_color` per point
    /// (surface_point.wgsl's `layer_texels`).
    pub layer_textures: u32,
}

/// The surfaces buffer's contents, as surface.wgsl's `Surfaces` reads it:
/// the sheen's albedo table (`hikari_core::bsdf::sheen::SHEEN_ALBEDO`,
/// which bsdf.wgsl reads wherever it shades), then `surfaces`.
pub fn surfaces_contents(surfaces: &[GpuSurface]) -> Vec<u8> {
    let mut bytes = bytemuck::cast_slice::<f32, u8>(&hikari_core::bsdf::sheen::SHEEN_ALBEDO).to_vec();
    bytes.extend_from_slice(bytemuck::cast_slice(surfaces));
    bytes
}

/// Segments around a tessellated sphere: fine enough that its silhouette is
/// within a fraction of a pixel of the analytic one at the built-in sizes.
const SPHERE_SEGMENTS: u32 = 96;

pub struct SceneBuffers {
    pub vertices: wgpu::Buffer,
    pub vertex_count: u32,
    /// Vertices `0..occluder_count` are everything but area-light bodies
    /// (which come last): what shadow maps draw, so an area light's samples
    /// are not shadowed by the light itself.
    pub occluder_count: u32,
    pub surfaces: wgpu::Buffer,
    /// The scene's flat BVH, which the specular pass traverses.
    pub bvh: FlatBvh,
    /// The packed textures (`textures::pack_scene`), texture coordinates
    /// in `bvh`'s primitive order.
    pub textures: wgpu::Buffer,
    /// The sky image (`textures::environment_words`).
    pub environment: wgpu::Buffer,
}

/// Bytes of the scene's largest buffers before they are built: the vertex
/// buffer (3 vertices a triangle, spheres tessellated) and the BVH's
/// per-primitive shading records, its largest storage binding.
pub fn scene_buffer_bytes(scene: &Scene) -> (u64, u64) {
    let triangles = scene.accel.triangles().count() as u64;
    let spheres = scene.accel.spheres().count() as u64;
    let sphere_triangles = 2 * SPHERE_SEGMENTS as u64 * (SPHERE_SEGMENTS / 2) as u64;
    let vertex = std::mem::size_of::<GpuVertex>() as u64;
    let vertices = 3 * (triangles + spheres * sphere_triangles) * vertex;
    let shading = (triangles + spheres) * std::mem::size_of::<hikari_core::geometry::FlatShading>() as u64;
    (vertices, shading)
}

/// All vertices, area-light bodies last; returns them and the occluder count.
/// One pass into vectors of their final size: a posed scene is uploaded
/// anew every frame of an animation (a 100,000-triangle character: 300,000
/// vertices of 56 bytes).
pub fn scene_vertices(scene: &Scene) -> (Vec<GpuVertex>, u32) {
    let is_emitter = |surface: u32| scene.surfaces[surface as usize].emitter.is_some();
    let emitter_triangles = scene.accel.triangles().filter(|&(_, s)| is_emitter(s)).count();
    let triangles = scene.accel.triangles().len();
    let mut occluders = Vec::with_capacity(3 * (triangles - emitter_triangles));
    let mut emitters = Vec::with_capacity(3 * emitter_triangles);
    let uvs = scene.texturing.as_ref().map(|t| &t.uvs);
    let tangents = scene.texturing.as_ref().map(|t| &t.tangents);
    for (prim, (tri, surface)) in scene.accel.triangles().enumerate() {
        let ng = tri.geometric_normal().normalize();
        let normals = match tri.normals {
            Some(n) => n.0,
            None => [ng; 3],
        };
        let uv = uvs.and_then(|t| t.triangle(prim as u32));
        let tangent = tangents.and_then(|t| t.triangle(prim as u32));
        let out = if is_emitter(surface) { &mut emitters } else { &mut occluders };
        let surface = if uv.is_some() { surface | HAS_UV } else { surface };
        for k in 0..3 {
            out.push(GpuVertex {
                position: tri.v[k].to_array(),
                normal: normals[k].to_array(),
                geometric_normal: ng.to_array(),
                surface,
                uv: uv.map_or([0.0; 2], |uv| uv[k].to_array()),
                tangent: tangent.map_or([0; 4], |t| t[k].0),
            });
        }
    }
    for (sphere, surface) in scene.accel.spheres() {
        let out = if is_emitter(surface) { &mut emitters } else { &mut occluders };
        tessellate_sphere(sphere.center, sphere.radius, surface, out);
    }
    let count = occluders.len() as u32;
    occluders.extend(emitters);
    (occluders, count)
}

/// UV sphere, wound so triangle normals point outward.
fn tessellate_sphere(center: Vec3, radius: f32, surface: u32, out: &mut Vec<GpuVertex>) {
    let (n_phi, n_theta) = (SPHERE_SEGMENTS, SPHERE_SEGMENTS / 2);
    let point = |i: u32, j: u32| {
        // Exact poles, so the collapsed triangles there are exactly degenerate.
        if j == 0 {
            return Vec3::Y;
        } else if j == n_theta {
            return Vec3::NEG_Y;
        }
        let theta = std::f32::consts::PI * j as f32 / n_theta as f32;
        let phi = 2.0 * std::f32::consts::PI * i as f32 / n_phi as f32;
        Vec3::new(theta.sin() * phi.cos(), theta.cos(), theta.sin() * phi.sin())
    };
    let mut push = |a: Vec3, b: Vec3, c: Vec3| {
        let ng = (b - a).cross(c - a);
        if ng.length_squared() == 0.0 {
            return;
        }
        let ng = ng.normalize();
        for n in [a, b, c] {
            out.push(GpuVertex {
                position: (center + n * radius).to_array(),
                normal: n.to_array(),
                geometric_normal: ng.to_array(),
                surface,
                uv: [0.0; 2],
                tangent: [0; 4],
            });
        }
    };
    for j in 0..n_theta {
        for i in 0..n_phi {
            let (a, b, c, d) = (point(i, j), point(i + 1, j), point(i + 1, j + 1), point(i, j + 1));
            // φ grows toward +z at φ = 0 and θ toward −y, so (b−a)×(c−a) points outward.
            push(a, b, c);
            push(a, c, d);
        }
    }
}

/// The scene's surfaces. With `layers_per_point`, clear-coat, sheen and
/// specular textures are read per point (`GpuSurface::layer_textures`);
/// without (an adapter whose G-buffer cannot keep them:
/// `GpuContext::layer_texels`), as their means over the image.
pub fn scene_surfaces(scene: &Scene, layers_per_point: bool) -> Vec<GpuSurface> {
    let views = scene.texturing.as_deref().map(crate::textures::TextureViews::of).unwrap_or_default();
    scene
        .surfaces
        .iter()
        .map(|s| {
            // A transmission mix as its base, with `transmission` below.
            let material = &match &scene.texturing {
                Some(t) if !layers_per_point => t.with_layer_means(scene.materials[s.material as usize], s.material),
                _ => scene.materials[s.material as usize],
            };
            let (kind, albedo, ior) = match material {
                Material::Diffuse { albedo, .. } => (kind::DIFFUSE, *albedo, 1.0),
                Material::Mirror { reflectance } => (kind::MIRROR, *reflectance, 1.0),
                // Glass's albedo is the tint of what crosses it.
                Material::Glass(glass) => (kind::GLASS, glass.tint, glass.ior),
                Material::Emitter => (kind::EMITTER, Vec3::ZERO, 1.0),
                Material::Pbr(bsdf) => (kind::DIFFUSE, bsdf.base_color, 1.0),
            };
            // What the eye sees besides what the surface reflects.
            let (emission, two_sided) = s.emitter.map_or((Vec3::ZERO, false), |l| match &scene.lights[l as usize] {
                hikari_core::light::Light::Sphere { radiance, .. }
                | hikari_core::light::Light::Quad { radiance, .. } => (*radiance, false),
                hikari_core::light::Light::Mesh(mesh) => (mesh.radiance, mesh.two_sided),
                _ => (Vec3::ZERO, false),
            });
            let textures = scene
                .texturing
                .as_ref()
                .and_then(|t| t.materials.get(s.material as usize).copied().flatten())
                .unwrap_or_default();
            let mean = textures.emissive_mean;
            let per_texel =
                Vec3::select(mean.cmpgt(Vec3::ZERO), emission / mean.max(Vec3::splat(f32::MIN_POSITIVE)), Vec3::ZERO);
            // Glass mixed into a glTF material's base (only a `Pbr` one mixes).
            let transmission = match material {
                Material::Pbr(_) => textures.transmission,
                _ => None,
            };
            // The glTF BRDF where it has a specular lobe, a coat or a sheen
            // (or mixes in glass, which raises its metallic where drawn);
            // exactly Lambertian ones (and the old materials) take the cheaper path.
            let glossy = match material {
                Material::Pbr(bsdf) if bsdf.is_glossy() || transmission.is_some() => Some(bsdf),
                _ => None,
            };
            GpuSurface {
                albedo: albedo.to_array(),
                kind,
                emission: emission.to_array(),
                ior,
                specular: match material {
                    Material::Diffuse { specular, .. } => specular.to_array(),
                    _ => [0.0; 3],
                },
                two_sided: two_sided as u32,
                metallic: glossy.map_or(0.0, |b| b.metallic),
                roughness: match material {
                    Material::Glass(glass) => glass.roughness,
                    _ => glossy.map_or(1.0, |b| b.roughness),
                },
                specular_factor: glossy.map_or(0.0, |b| b.specular),
                glossy: glossy.is_some() as u32,
                emission_per_texel: per_texel.to_array(),
                alpha_cutoff: match textures.alpha_mode {
                    AlphaMode::Opaque => -1.0,
                    AlphaMode::Mask(cutoff) => cutoff,
                    AlphaMode::Blend => ALPHA_BLEND,
                },
                base_color_texture: views.reference(textures.base_color),
                metallic_roughness_texture: views.reference(textures.metallic_roughness),
                emissive_texture: views.reference(textures.emissive),
                alpha_factor: if textures.alpha_mode == AlphaMode::Opaque { 1.0 } else { textures.alpha_factor },
                normal_texture: views.reference(textures.normal),
                normal_scale: textures.normal_scale,
                clearcoat: glossy.map_or(0.0, |b| b.clearcoat),
                clearcoat_roughness: glossy.map_or(0.0, |b| b.clearcoat_roughness),
                dielectric_f0: glossy.map_or(hikari_core::bsdf::DIELECTRIC_F0, |b| b.f0),
                sheen_roughness: glossy.map_or(0.0, |b| b.sheen_roughness),
                transmission: transmission.map_or(0.0, |t| t.factor),
                transmission_texture: views.reference(transmission.and_then(|t| t.texture)),
                sheen_color: glossy.map_or([0.0; 3], |b| b.sheen_color.to_array()),
                transmission_ior: transmission.map_or(1.0, |t| t.ior),
                specular_color: match material {
                    Material::Glass(glass) => glass.absorption.to_array(),
                    _ => glossy.map_or([1.0; 3], |b| b.specular_color.to_array()),
                },
                layer_textures: match (material, layers_per_point) {
                    (Material::Pbr(_), true) => views.layer_table(s.material),
                    _ => crate::textures::NO_TEXTURE,
                },
            }
        })
        .collect()
}

impl SceneBuffers {
    /// The scene's buffers, its layer textures read per point where
    /// `layers_per_point` (`scene_surfaces`).
    pub fn upload(device: &wgpu::Device, scene: &Scene, layers_per_point: bool) -> Self {
        let (vertices, occluder_count) = scene_vertices(scene);
        let surfaces = scene_surfaces(scene, layers_per_point);
        let bvh = FlatBvh::new(&scene.accel);
        let textures = crate::textures::pack_scene(scene, Some(&bvh));
        SceneBuffers {
            environment: device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some("sky image"),
                contents: bytemuck::cast_slice(&crate::textures::environment_words(scene)),
                // COPY_SRC: the specular pass copies it into its tables.
                usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
            }),
            bvh,
            textures: device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some("scene textures"),
                contents: bytemuck::cast_slice(&textures),
                usage: wgpu::BufferUsages::STORAGE,
            }),
            vertex_count: vertices.len() as u32,
            occluder_count,
            vertices: device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some("scene vertices"),
                contents: bytemuck::cast_slice(&vertices),
                usage: wgpu::BufferUsages::VERTEX,
            }),
            surfaces: device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some("scene surfaces"),
                contents: &surfaces_contents(&surfaces),
                usage: wgpu::BufferUsages::STORAGE,
            }),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A surface with clear-coat, sheen and specular textures: read per
    /// point, its record holds the factors and where its six textures'
    /// references lie in the packed texture words (each the view
    /// `TextureViews::reference` names); drawn as their means, each factor
    /// times its texture's mean (`Texturing::with_layer_means`, which
    /// hikari-core's tests pin) and no table.
    #[test]
    fn layer_textures_upload_per_point_or_as_their_means() {
        use crate::textures::{NO_TEXTURE, TextureViews, pack};
        use hikari_core::test_scenes::gltf_textures::{LAYER_FACTORS, layered_glb, load};
        let scene = load("gpu-layers", &layered_glb());
        let texturing = scene.texturing.as_ref().unwrap();
        let index = scene.surfaces.iter().position(|s| texturing.materials[s.material as usize].is_some()).unwrap();
        let material = scene.surfaces[index].material;

        let means = scene_surfaces(&scene, false)[index];
        let Material::Pbr(mean) = texturing.with_layer_means(scene.materials[material as usize], material) else {
            panic!()
        };
        assert_eq!(means.clearcoat, mean.clearcoat);
        assert!(means.clearcoat < LAYER_FACTORS.0 * 0.99, "the texture's mean (below 1) applied");
        assert_eq!(means.sheen_color, mean.sheen_color.to_array());
        assert_eq!(means.specular_factor, mean.specular);
        assert_eq!(means.specular_color, mean.specular_color.to_array());
        assert_eq!(means.layer_textures, NO_TEXTURE);

        let per_point = scene_surfaces(&scene, true)[index];
        let (coat, coat_roughness, sheen, sheen_roughness, specular, specular_color) = LAYER_FACTORS;
        assert_eq!(per_point.clearcoat, coat);
        assert_eq!(per_point.clearcoat_roughness, coat_roughness);
        assert_eq!(per_point.sheen_color, sheen);
        assert_eq!(per_point.sheen_roughness, sheen_roughness);
        assert_eq!(per_point.specular_factor, specular);
        assert_eq!(per_point.specular_color, specular_color);
        let table = per_point.layer_textures as usize;
        let words = pack(texturing, None);
        let views = TextureViews::of(texturing);
        let layers = texturing.materials[material as usize].unwrap().layers;
        for (k, texture) in layers.all().into_iter().enumerate() {
            assert!(texture.is_some(), "layered_glb has all six");
            assert_eq!(words[table + k], views.reference(texture), "table word {k}");
        }
        assert!(scene_surfaces(&scene, true).iter().filter(|s| s.glossy == 0).all(|s| s.layer_textures == NO_TEXTURE));
    }

    /// The kind only the G-buffer writes is surface.wgsl's constant.
    #[test]
    fn the_mixed_inside_kind_is_the_wgsl_constant() {
        let wgsl = crate::wgsl::SURFACE.source;
        assert!(wgsl.contains(&format!("const KIND_MIXED_INSIDE: u32 = {}u;", kind::MIXED_INSIDE)));
    }

    #[test]
    fn tessellated_sphere_winds_outward() {
        let mut v = Vec::new();
        tessellate_sphere(Vec3::new(1.0, 2.0, 3.0), 0.5, 0, &mut v);
        for tri in v.chunks(3) {
            let c = tri.iter().map(|x| Vec3::from(x.position)).sum::<Vec3>() / 3.0;
            assert!(Vec3::from(tri[0].geometric_normal).dot(c - Vec3::new(1.0, 2.0, 3.0)) > 0.0);
        }
    }
}

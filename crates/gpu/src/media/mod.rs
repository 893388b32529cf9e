//! Participating media on the GPU (METHOD.md §5): the scene's media as
//! uniforms and a triangle buffer, and the optical-depth pass that
//! rasterizes the region meshes into per-pixel slices along the view rays
//! (eq. 5.25–5.30, `--volume-slices`). The volume splat (`crate::volume`),
//! the direct-light pass and the resolve read them.

use crate::gbuffer::GBuffer;
use bytemuck::{Pod, Zeroable};
use hikari_core::medium::{Media, Phase};
use hikari_core::scene::Scene;
use wgpu::util::DeviceExt;

/// Structs and functions shared by every shader that sees media.
pub static MEDIA: crate::wgsl::Module = crate::wgsl::Module {
    name: "media.wgsl",
    source: include_str!("media.wgsl"),
    requires: &[&crate::wgsl::CONSTANTS, &crate::wgsl::REGION_CROSSING, &crate::features::FEATURES],
};
/// `region_triangle(i)` for media.wgsl from the includer's `regions` array.
pub static REGION_ARRAY: crate::wgsl::Module = crate::wgsl::Module {
    name: "region_array",
    source: "fn region_triangle(i: u32) -> RegionTriangle {\n    return regions[i];\n}\n",
    requires: &[&MEDIA],
};
/// The optical depth along view rays from the slices.
pub static VIEW_DEPTH: crate::wgsl::Module =
    crate::wgsl::Module { name: "view_depth.wgsl", source: include_str!("view_depth.wgsl"), requires: &[&MEDIA] };

pub fn optical_depth_shader_source() -> String {
    use crate::wgsl::{Module, UNCOUNTED_LOOPS, compose};
    static OPTICAL_DEPTH: Module =
        Module { name: "optical_depth.wgsl", source: include_str!("optical_depth.wgsl"), requires: &[] };
    compose(&[&UNCOUNTED_LOOPS, &MEDIA, &REGION_ARRAY, &OPTICAL_DEPTH])
}

/// Mirrors `MediaParams` in media.wgsl.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct MediaParams {
    /// First, values that stay from frame to frame (not the camera's):
    /// Mesa 22.3's lavapipe bakes a uniform buffer's first word into
    /// shaders that test its fields, compiling anew whenever it changes
    /// (`SpecularParams`).
    pub global_sigma_t: [f32; 3],
    pub region_triangles: u32,
    pub forward: [f32; 3],
    pub tan_half_fov: f32,
    pub right: [f32; 3],
    pub aspect: f32,
    pub up: [f32; 3],
    pub slices: u32,
    pub camera_position: [f32; 3],
    pub max_distance: f32,
    pub phases: [[f32; 4]; 4],
    pub image_size: [f32; 2],
    /// The camera's sub-pixel jitter (`Camera::jitter`).
    pub jitter: [f32; 2],
    /// The disc the distant lights' photons start from: centre and radius
    /// (radius 0 without distant lights). Rays that see no surface end at
    /// its plane (`escape_distance` in media.wgsl).
    pub distant_disc: [f32; 4],
}

/// Mirrors `RegionTriangle` in media.wgsl.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct RegionTriangle {
    pub a: [f32; 4],
    pub b: [f32; 4],
    pub c: [f32; 4],
    pub sigma_t: [f32; 4],
}

/// Length of view rays that see no surface in a scene without distant
/// lights: photon-cpu's, so both estimate the same in-scattering there.
pub fn max_view_distance(scene: &Scene) -> f32 {
    scene.diagonal() * 2.0
}

/// The distant lights' disc as `MediaParams::distant_disc` holds it.
fn distant_disc(scene: &Scene) -> [f32; 4] {
    scene.lights.iter().find_map(|l| l.distant_disc()).map_or([0.0; 4], |d| d.center.extend(d.radius).to_array())
}

impl MediaParams {
    /// These parameters seen from `camera` (same resolution).
    pub fn with_camera(&self, camera: &hikari_core::camera::Camera) -> Self {
        let (forward, right, up, tan_half_fov) = camera.basis();
        MediaParams {
            camera_position: camera.position.to_array(),
            forward: forward.to_array(),
            tan_half_fov,
            right: right.to_array(),
            aspect: camera.width as f32 / camera.height as f32,
            up: up.to_array(),
            jitter: camera.jitter.to_array(),
            ..*self
        }
    }

    pub fn new(scene: &Scene, slices: u32) -> Self {
        let media = &scene.media;
        let camera = &scene.camera;
        let (forward, right, up, tan_half_fov) = camera.basis();
        let mut phases = [[0.0; 4]; 4];
        for (slot, phase) in media.phases().iter().enumerate() {
            phases[slot] = match *phase {
                Phase::Schlick { k } => [0.0, k, 0.0, 0.0],
                Phase::HenyeyGreenstein { g } => [1.0, g, 0.0, 0.0],
            };
        }
        let triangles = region_triangles(media).len() as u32;
        MediaParams {
            camera_position: camera.position.to_array(),
            max_distance: max_view_distance(scene),
            forward: forward.to_array(),
            tan_half_fov,
            right: right.to_array(),
            aspect: camera.width as f32 / camera.height as f32,
            up: up.to_array(),
            slices: if triangles > 0 { slices.max(1) } else { 0 },
            global_sigma_t: media.global_sigma_t().to_array(),
            region_triangles: triangles,
            phases,
            image_size: [camera.width as f32, camera.height as f32],
            jitter: camera.jitter.to_array(),
            distant_disc: distant_disc(scene),
        }
    }
}

impl GpuMedia {
    /// Whether `scene` has media bounded by region meshes (the
    /// optical-depth pass and its slices run only then).
    pub fn has_regions(scene: &Scene) -> bool {
        Self::region_triangle_count(scene) > 0
    }

    pub fn region_triangle_count(scene: &Scene) -> usize {
        scene.media.entries().iter().filter_map(|e| e.region.as_ref()).map(|r| r.triangles().len()).sum()
    }
}

/// Every region mesh's triangles with their medium's σ_t.
pub fn region_triangles(media: &Media) -> Vec<RegionTriangle> {
    let mut out = Vec::new();
    for entry in media.entries() {
        let Some(region) = &entry.region else { continue };
        let s = entry.medium.sigma_t();
        for [a, b, c] in region.triangles() {
            out.push(RegionTriangle {
                a: a.extend(0.0).to_array(),
                b: b.extend(0.0).to_array(),
                c: c.extend(0.0).to_array(),
                sigma_t: [s.x, s.y, s.z, 0.0],
            });
        }
    }
    out
}

/// The media's GPU resources and the optical-depth pass.
pub struct GpuMedia {
    pub params: MediaParams,
    pub params_buffer: wgpu::Buffer,
    pub regions: wgpu::Buffer,
    /// `slices` layers (at least one) of the regions' optical depth.
    pub slices: wgpu::Texture,
    pipeline: wgpu::RenderPipeline,
    bind_group: wgpu::BindGroup,
    clip_buffer: wgpu::Buffer,
}

impl GpuMedia {
    /// Sees the media from `camera` from the next frame on.
    pub fn set_camera(
        &mut self,
        queue: &wgpu::Queue,
        camera: &hikari_core::camera::Camera,
        clip_from_world: glam::Mat4,
    ) {
        self.params = self.params.with_camera(camera);
        queue.write_buffer(&self.params_buffer, 0, bytemuck::bytes_of(&self.params));
        queue.write_buffer(&self.clip_buffer, 0, bytemuck::bytes_of(&clip_from_world.to_cols_array_2d()));
    }

    /// Follows a moved `scene` (its media and regions unchanged): view rays
    /// that see no surface end at the new scene's `max_view_distance`, or
    /// its distant lights' disc.
    pub fn set_scene(&mut self, queue: &wgpu::Queue, scene: &Scene) {
        self.params.max_distance = max_view_distance(scene);
        self.params.distant_disc = distant_disc(scene);
        queue.write_buffer(&self.params_buffer, 0, bytemuck::bytes_of(&self.params));
    }

    pub fn new(
        device: &wgpu::Device,
        scene: &Scene,
        slices: u32,
        gbuffer: &GBuffer,
        clip_from_world: glam::Mat4,
        format: wgpu::TextureFormat,
    ) -> Self {
        let params = MediaParams::new(scene, slices);
        let params_buffer = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("media params"),
            contents: bytemuck::bytes_of(&params),
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
        });
        let mut triangles = region_triangles(&scene.media);
        if triangles.is_empty() {
            triangles.push(RegionTriangle::zeroed()); // wgpu refuses empty buffers
        }
        let regions = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("region triangles"),
            contents: bytemuck::cast_slice(&triangles),
            // COPY_SRC: the specular pass copies them into its tables.
            usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
        });
        let slices_texture = device.create_texture(&wgpu::TextureDescriptor {
            label: Some("optical-depth slices"),
            size: wgpu::Extent3d {
                width: gbuffer.width,
                height: gbuffer.height,
                depth_or_array_layers: crate::binding::array_layers(gbuffer.width, gbuffer.height, params.slices),
            },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format,
            usage: wgpu::TextureUsages::RENDER_ATTACHMENT
                | wgpu::TextureUsages::TEXTURE_BINDING
                | wgpu::TextureUsages::COPY_SRC,
            view_formats: &[],
        });
        let clip_buffer = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("optical-depth clip_from_world"),
            contents: bytemuck::bytes_of(&clip_from_world.to_cols_array_2d()),
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
        });
        use crate::binding::{entry, storage, texture, uniform};
        let stages = wgpu::ShaderStages::VERTEX_FRAGMENT;
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("optical depth"),
            entries: &[
                entry(0, stages, uniform()),
                entry(1, stages, storage(true)),
                entry(2, stages, texture(wgpu::TextureViewDimension::D2)),
                entry(3, stages, uniform()),
            ],
        });
        let position = gbuffer.position.create_view(&Default::default());
        let bind_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("optical depth"),
            layout: &layout,
            entries: &[
                wgpu::BindGroupEntry { binding: 0, resource: params_buffer.as_entire_binding() },
                wgpu::BindGroupEntry { binding: 1, resource: regions.as_entire_binding() },
                wgpu::BindGroupEntry { binding: 2, resource: wgpu::BindingResource::TextureView(&position) },
                wgpu::BindGroupEntry { binding: 3, resource: clip_buffer.as_entire_binding() },
            ],
        });
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("optical_depth.wgsl"),
            source: wgpu::ShaderSource::Wgsl(optical_depth_shader_source().into()),
        });
        let pipeline_layout = crate::binding::pipeline_layout(device, "optical depth", &layout);
        let pipeline =
            crate::splat::additive_pipeline(device, &pipeline_layout, &module, format, &[], "optical depth", &[], None);
        GpuMedia { params, params_buffer, regions, slices: slices_texture, pipeline, bind_group, clip_buffer }
    }

    /// Rasterizes the region meshes once per slice (nothing without regions).
    pub fn record(&self, encoder: &mut wgpu::CommandEncoder) {
        for slice in 0..self.params.slices {
            let view = self.slices.create_view(&wgpu::TextureViewDescriptor {
                dimension: Some(wgpu::TextureViewDimension::D2),
                base_array_layer: slice,
                array_layer_count: Some(1),
                ..Default::default()
            });
            let mut pass = crate::binding::color_pass(encoder, "optical depth", &view, true);
            pass.set_pipeline(&self.pipeline);
            pass.set_bind_group(0, &self.bind_group, &[]);
            pass.draw(0..3 * self.params.region_triangles, slice..slice + 1);
        }
    }
}

//! The specular pass: mirrors, glass and the mirror part of diffuse + mirror
//! materials seen by the camera, ray-traced on
//! the GPU through the scene BVH to their diffuse hits, which are shaded
//! with direct light and photon gathers, every segment attenuated by the
//! media and adding their in-scattering (see specular.wgsl).

use crate::direct::DirectParams;
use crate::gbuffer::GBuffer;
use crate::media::GpuMedia;
use crate::photon_grid::PhotonGrid;
use crate::scene_upload::SceneBuffers;
use crate::shadow::ShadowMaps;
use crate::shadow::light_samples::GpuLights;
use bytemuck::{Pod, Zeroable};
use hikari_core::estimate::FixedRadius;
use hikari_core::geometry::FlatBvh;
use hikari_core::material::Material;
use hikari_core::photon::Photon;
use hikari_core::scene::Scene;
use wgpu::util::DeviceExt;

/// Workgroup side (the `WORKGROUP` override of the shader).
const WORKGROUP: u32 = 8;

/// Whether any surface is a mirror, glass, partly mirroring or transmissive, or glossy
/// with a lobe the eye follows (smoother than `GATHER_ROUGHNESS`): the
/// pass runs only then.
pub fn has_specular_surfaces(scene: &Scene) -> bool {
    // Glass mixed into a material (drawn per pixel and per hit).
    let mixes = |material: u32| scene.texturing.as_ref().is_some_and(|t| t.mixes(material));
    scene.surfaces.iter().any(|s| {
        mixes(s.material)
            || match &scene.materials[s.material as usize] {
                Material::Mirror { .. } | Material::Glass { .. } => true,
                Material::Diffuse { specular, .. } => specular.max_element() > 0.0,
                Material::Pbr(bsdf) => {
                    // A metallic–roughness texture may make it smoother somewhere.
                    let textured = scene
                        .texturing
                        .as_ref()
                        .and_then(|t| t.materials.get(s.material as usize).copied().flatten())
                        .is_some_and(|t| t.metallic_roughness.is_some());
                    bsdf.follows_any() || (bsdf.has_specular() && textured)
                }
                Material::Emitter => false,
            }
    })
}

pub fn shader_source() -> String {
    use crate::wgsl::{BVH, Module, OPTICS, compose};
    static LOOP_BUDGET: Module =
        Module { name: "loop_budget.wgsl", source: include_str!("loop_budget.wgsl"), requires: &[] };
    static SPECULAR: Module = Module { name: "specular.wgsl", source: include_str!("specular.wgsl"), requires: &[] };
    compose(&[
        &crate::wgsl::PHOTON_BRDF,
        &crate::media::MEDIA,
        &crate::direct::LIGHT_EVAL,
        &LOOP_BUDGET,
        &BVH,
        &crate::wgsl::HIT_NORMALS,
        &OPTICS,
        &crate::wgsl::DIELECTRIC,
        &crate::wgsl::SURFACE,
        &crate::wgsl::CUT_OUTS,
        &crate::textures::ENVIRONMENT,
        &crate::wgsl::VOLUME_CHORD,
        &crate::tables::TABLES,
        &SPECULAR,
    ])
}

/// Mirrors `SpecularParams` in specular.wgsl.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct SpecularParams {
    /// First, values that stay from frame to frame: Mesa 22.3's lavapipe
    /// bakes this buffer's first word into the shader at every dispatch
    /// (its uniform inlining reads offset 0 of any uniform buffer but the
    /// first), and a camera value there compiled the pass anew each time
    /// the camera moved (5 s a frame on showcase.glb, BENCHMARKS.md).
    pub width: u32,
    pub height: u32,
    pub normal_test: u32,
    pub power_unit: f32,
    pub camera_position: [f32; 3],
    pub tan_half_fov: f32,
    pub camera_right: [f32; 3],
    pub aspect: f32,
    pub camera_up: [f32; 3],
    pub epsilon: f32,
    pub camera_forward: [f32; 3],
    pub max_depth: u32,
    pub global_radius: f32,
    pub global_buckets: u32,
    pub global_start_offset: u32,
    pub global_photon_offset: u32,
    pub caustic_radius: f32,
    pub caustic_buckets: u32,
    pub caustic_start_offset: u32,
    pub caustic_photon_offset: u32,
    pub volume_radius: f32,
    /// 0 when there are no volume photons.
    pub volume_buckets: u32,
    pub volume_start_offset: u32,
    pub volume_photon_offset: u32,
    /// Bounds of the volume photons' positions.
    pub volume_min: [f32; 3],
    /// The camera's sub-pixel jitter (`Camera::jitter`), x then y.
    pub jitter_x: f32,
    pub volume_max: [f32; 3],
    pub jitter_y: f32,
    /// Radiance of rays that leave the scene (the sky's; zero without one).
    pub sky_radiance: [f32; 3],
    /// Word offsets in the tables buffer (`SpecularTables`).
    pub light_table: u32,
    pub sample_table: u32,
    pub view_table: u32,
    pub region_table: u32,
    pub environment_table: u32,
    /// The flat BVH's vertex normals (`FlatShading` records, hit_normals.wgsl).
    pub shading_table: u32,
    pub _pad0: u32,
    pub _pad1: u32,
    pub _pad2: u32,
}

/// Mirrors `SliceParams` in specular.wgsl: which share of the photon
/// gathers one dispatch computes, and its loop budget.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct SliceParams {
    pub index: u32,
    pub count: u32,
    pub iteration_budget: u32,
    /// The progressive pass (from 1): seeds the pixels' random streams.
    pub pass_index: u32,
}

/// Most dispatches the gathers are split into before the pass gives up.
pub const MAX_SLICES: u32 = 256;
/// Uniform offsets must be multiples of 256 bytes on every adapter.
const SLICE_STRIDE: u64 = 256;

/// What the last frame's specular pass reported.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct SpecularStatus {
    /// Pixel invocations (over all slices) that ran out of loop budget.
    pub over_budget: u32,
    /// The most loop iterations one invocation ran.
    pub most_iterations: u32,
}

/// Everything the estimate needs to know about the photon maps.
pub struct SpecularInputs<'a> {
    pub global_photons: &'a [Photon],
    pub caustic_photons: &'a [Photon],
    pub volume_photons: &'a [Photon],
    pub volume_radius: f32,
    pub global: FixedRadius,
    pub caustic: FixedRadius,
    pub power_unit: f32,
    pub max_depth: u32,
    pub shadow_bias: f32,
    /// Loop iterations one invocation may run (`GpuContext::loop_budget`).
    pub iteration_budget: u32,
}

pub struct SpecularPass {
    pipeline: wgpu::ComputePipeline,
    bind_group: wgpu::BindGroup,
    width: u32,
    height: u32,
    /// False when no surface is a mirror or glass: the pass is skipped and
    /// its (zero-initialised) output stays black.
    enabled: bool,
    pub output: wgpu::Texture,
    slice_params: wgpu::Buffer,
    status: wgpu::Buffer,
    params: SpecularParams,
    params_buffer: wgpu::Buffer,
    iteration_budget: u32,
    /// Dispatches the gathers are split into; grows when a frame ran over
    /// budget and is kept for the next frames.
    slices: std::cell::Cell<u32>,
    bindings: Bindings,
    /// The photon grids now bound.
    grid: wgpu::Buffer,
    shadow_bias: f32,
}

/// What the pass reads of the scene itself: the flat BVH, and the
/// parameters of direct light at specular hits.
struct SceneData {
    nodes: wgpu::Buffer,
    prims: wgpu::Buffer,
    direct: wgpu::Buffer,
}

impl SceneData {
    fn upload(device: &wgpu::Device, bvh: &FlatBvh, lights: &GpuLights, maps: &ShadowMaps, bias: f32) -> Self {
        let storage = wgpu::BufferUsages::STORAGE;
        let direct_params =
            DirectParams { light_count: lights.lights.len() as u32, shadow_size: maps.size, bias, pass_index: 0 };
        SceneData {
            nodes: padded_buffer(device, "bvh nodes", bytemuck::cast_slice(&bvh.nodes), storage),
            prims: padded_buffer(device, "bvh prims", bytemuck::cast_slice(&bvh.prims), storage),
            direct: padded_buffer(
                device,
                "specular direct params",
                bytemuck::bytes_of(&direct_params),
                wgpu::BufferUsages::UNIFORM,
            ),
        }
    }
}

/// The pass's small tables in one storage buffer (specular.wgsl's
/// `light_record` and the other readers): the lights and light samples
/// written from the host, then the shadow views, region triangles and sky
/// image, copied in on the GPU from the renderer's buffers by `copy_in`
/// (the views and regions every frame, as moving lights and objects
/// rewrite them in place; the sky image once).
struct SpecularTables {
    buffer: wgpu::Buffer,
    /// Word offsets: lights, samples, views, regions, sky image, vertex normals.
    offsets: [u32; 6],
    views: wgpu::Buffer,
    regions: wgpu::Buffer,
    environment: wgpu::Buffer,
    environment_copied: std::cell::Cell<bool>,
}

impl SpecularTables {
    fn new(
        device: &wgpu::Device,
        lights: &GpuLights,
        views: &wgpu::Buffer,
        regions: &wgpu::Buffer,
        environment: &wgpu::Buffer,
        shading: &[hikari_core::geometry::FlatShading],
    ) -> Self {
        let mut tables = crate::tables::PackedTables::after(Vec::new());
        let words = |b: &wgpu::Buffer| (b.size() / 4) as usize;
        let offsets = [
            tables.push(&lights.lights),
            tables.push(&lights.samples),
            tables.reserve_words(words(views)),
            tables.reserve_words(words(regions)),
            tables.reserve_words(words(environment)),
            tables.push(shading),
        ];
        let usage = wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST;
        SpecularTables {
            buffer: padded_buffer(device, "specular tables", bytemuck::cast_slice(&tables.words), usage),
            offsets,
            views: views.clone(),
            regions: regions.clone(),
            environment: environment.clone(),
            environment_copied: std::cell::Cell::new(false),
        }
    }

    /// `params` pointing at these tables.
    fn locate(&self, params: SpecularParams) -> SpecularParams {
        let [light_table, sample_table, view_table, region_table, environment_table, shading_table] = self.offsets;
        SpecularParams {
            light_table,
            sample_table,
            view_table,
            region_table,
            environment_table,
            shading_table,
            ..params
        }
    }

    /// `lights`' samples in place of the ones it was made with (the same
    /// count: another pass's samples).
    fn write_samples(&self, queue: &wgpu::Queue, lights: &GpuLights) {
        queue.write_buffer(&self.buffer, self.offsets[1] as u64 * 4, bytemuck::cast_slice(&lights.samples));
    }

    /// Records the copies of what the renderer may have rewritten.
    fn copy_in(&self, encoder: &mut wgpu::CommandEncoder) {
        let [_, _, views, regions, environment, _] = self.offsets.map(|words| words as u64 * 4);
        encoder.copy_buffer_to_buffer(&self.views, 0, &self.buffer, views, self.views.size());
        encoder.copy_buffer_to_buffer(&self.regions, 0, &self.buffer, regions, self.regions.size());
        if !self.environment_copied.replace(true) {
            encoder.copy_buffer_to_buffer(&self.environment, 0, &self.buffer, environment, self.environment.size());
        }
    }
}

/// A buffer holding `bytes`; wgpu refuses empty bindings, so an empty one
/// holds zero words instead.
fn padded_buffer(device: &wgpu::Device, label: &str, bytes: &[u8], usage: wgpu::BufferUsages) -> wgpu::Buffer {
    let padded: &[u8] = if bytes.is_empty() { &[0; 48] } else { bytes };
    device.create_buffer_init(&wgpu::util::BufferInitDescriptor { label: Some(label), contents: padded, usage })
}

/// Everything the pass binds but the photon grids, kept to rebind new ones.
struct Bindings {
    layout: wgpu::BindGroupLayout,
    params: wgpu::Buffer,
    nodes: wgpu::Buffer,
    prims: wgpu::Buffer,
    surfaces: wgpu::Buffer,
    textures: wgpu::Buffer,
    tables: SpecularTables,
    direct: wgpu::Buffer,
    maps: wgpu::TextureView,
    normal: wgpu::TextureView,
    albedo: wgpu::TextureView,
    emission: wgpu::TextureView,
    output: wgpu::TextureView,
    media: wgpu::Buffer,
    accum: wgpu::Buffer,
    status: wgpu::Buffer,
    slices: wgpu::Buffer,
}

impl Bindings {
    fn bind_group(&self, device: &wgpu::Device, grid: &wgpu::Buffer) -> wgpu::BindGroup {
        let layout = &self.layout;
        fn buffer(binding: u32, b: &wgpu::Buffer) -> wgpu::BindGroupEntry<'_> {
            wgpu::BindGroupEntry { binding, resource: b.as_entire_binding() }
        }
        fn view(binding: u32, v: &wgpu::TextureView) -> wgpu::BindGroupEntry<'_> {
            wgpu::BindGroupEntry { binding, resource: wgpu::BindingResource::TextureView(v) }
        }
        device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("specular"),
            layout,
            entries: &[
                buffer(0, &self.params),
                buffer(1, &self.nodes),
                buffer(2, &self.prims),
                buffer(3, &self.surfaces),
                buffer(4, grid),
                buffer(5, &self.tables.buffer),
                buffer(6, &self.direct),
                view(10, &self.maps),
                view(11, &self.normal),
                view(12, &self.output),
                buffer(13, &self.media),
                buffer(14, &self.accum),
                buffer(15, &self.status),
                wgpu::BindGroupEntry {
                    binding: 16,
                    resource: wgpu::BindingResource::Buffer(wgpu::BufferBinding {
                        buffer: &self.slices,
                        offset: 0,
                        size: std::num::NonZeroU64::new(std::mem::size_of::<SliceParams>() as u64),
                    }),
                },
                buffer(17, &self.textures),
                view(18, &self.albedo),
                view(19, &self.emission),
            ],
        })
    }
}

/// The three photon grids (global, caustic, volume) in one buffer of words:
/// all bucket starts, then all photons; and the parameters that locate them.
struct PackedGrids;

impl PackedGrids {
    /// The words and a `SpecularParams` whose grid fields (buckets, offsets,
    /// volume bounds, power unit) are set, the rest zero.
    fn new(inputs: &SpecularInputs) -> (Vec<u32>, SpecularParams) {
        let global = PhotonGrid::new(inputs.global_photons, inputs.global.radius);
        let caustic = PhotonGrid::new(inputs.caustic_photons, inputs.caustic.radius);
        let volume = PhotonGrid::new(inputs.volume_photons, inputs.volume_radius);
        let grids = [&global, &caustic, &volume];
        let mut words: Vec<u32> = Vec::new();
        let mut start_offsets = [0u32; 3];
        for (offset, grid) in start_offsets.iter_mut().zip(grids) {
            *offset = words.len() as u32;
            words.extend(&grid.starts);
        }
        let mut photon_offsets = [0u32; 3];
        for (offset, grid) in photon_offsets.iter_mut().zip(grids) {
            *offset = words.len() as u32;
            words.extend_from_slice(bytemuck::cast_slice(&grid.photons));
        }
        let (lo, hi) = inputs
            .volume_photons
            .iter()
            .fold((glam::Vec3::splat(f32::MAX), glam::Vec3::splat(f32::MIN)), |(lo, hi), p| {
                (lo.min(p.position()), hi.max(p.position()))
            });
        let params = SpecularParams {
            power_unit: inputs.power_unit,
            global_radius: inputs.global.radius,
            global_buckets: global.buckets,
            global_start_offset: start_offsets[0],
            global_photon_offset: photon_offsets[0],
            caustic_radius: inputs.caustic.radius,
            caustic_buckets: caustic.buckets,
            caustic_start_offset: start_offsets[1],
            caustic_photon_offset: photon_offsets[1],
            volume_radius: inputs.volume_radius,
            volume_buckets: if inputs.volume_photons.is_empty() { 0 } else { volume.buckets },
            volume_start_offset: start_offsets[2],
            volume_photon_offset: photon_offsets[2],
            volume_min: lo.to_array(),
            volume_max: hi.to_array(),
            ..SpecularParams::zeroed()
        };
        (words, params)
    }
}

impl SpecularPass {
    #[allow(clippy::too_many_arguments)]
    pub fn new(
        device: &wgpu::Device,
        scene: &Scene,
        scene_buffers: &SceneBuffers,
        lights: &GpuLights,
        maps: &ShadowMaps,
        gbuffer: &GBuffer,
        media: &GpuMedia,
        inputs: &SpecularInputs,
        features: crate::features::SceneFeatures,
    ) -> Self {
        let (width, height) = (gbuffer.width, gbuffer.height);
        let iteration_budget = inputs.iteration_budget;
        let source = shader_source();
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("specular.wgsl"),
            source: wgpu::ShaderSource::Wgsl(source.as_str().into()),
        });
        use crate::binding::{storage, storage_texture_rgba32f, texture, uniform};
        use wgpu::TextureViewDimension::{D2, D2Array};
        let entry = |b, ty| crate::binding::entry(b, wgpu::ShaderStages::COMPUTE, ty);
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("specular"),
            entries: &[
                entry(0, uniform()),
                entry(1, storage(true)),
                entry(2, storage(true)),
                entry(3, storage(true)),
                entry(4, storage(true)),
                entry(5, storage(true)),
                entry(6, uniform()),
                entry(10, texture(D2Array)),
                entry(11, texture(D2)),
                entry(12, storage_texture_rgba32f()),
                entry(13, uniform()),
                entry(14, storage(false)),
                entry(15, storage(false)),
                entry(16, crate::binding::dynamic_uniform(std::mem::size_of::<SliceParams>() as u64)),
                entry(17, storage(true)),
                entry(18, texture(D2)),
                entry(19, texture(D2)),
            ],
        });
        let pipeline_layout = crate::binding::pipeline_layout(device, "specular", &layout);
        // Specialised to the scene's features; the renderer remakes the
        // pass for a scene that uses others (`GpuRenderer::set_scene`).
        let mut constants = features.constants(&source);
        constants.push(("WORKGROUP", WORKGROUP as f64));
        let pipeline =
            crate::binding::compute_pipeline_with(device, "specular", &pipeline_layout, &module, "main", &constants);

        let (words, grid_params) = PackedGrids::new(inputs);
        let (forward, right, up, tan_half_fov) = scene.camera.basis();
        let tables = SpecularTables::new(
            device,
            lights,
            &maps.views_buffer,
            &media.regions,
            &scene_buffers.environment,
            &scene_buffers.bvh.shading,
        );
        let params = tables.locate(SpecularParams {
            camera_position: scene.camera.position.to_array(),
            tan_half_fov,
            camera_right: right.to_array(),
            aspect: scene.camera.aspect(),
            camera_up: up.to_array(),
            epsilon: scene.accel.epsilon,
            camera_forward: forward.to_array(),
            max_depth: inputs.max_depth,
            width,
            height,
            normal_test: inputs.global.normal_test as u32,
            jitter_x: scene.camera.jitter.x,
            jitter_y: scene.camera.jitter.y,
            sky_radiance: lights.sky_radiance.to_array(),
            ..grid_params
        });
        let storage_usage = wgpu::BufferUsages::STORAGE;
        let params_buffer = padded_buffer(
            device,
            "specular params",
            bytemuck::bytes_of(&params),
            wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
        );
        let grid = padded_buffer(device, "photon grids", bytemuck::cast_slice(&words), storage_usage);
        let keep = |b: &wgpu::Buffer| b.clone();
        let SceneData { nodes, prims, direct } =
            SceneData::upload(device, &scene_buffers.bvh, lights, maps, inputs.shadow_bias);
        let output = crate::binding::storage_output_texture(device, "specular radiance", width, height);
        let accum = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("specular accumulation"),
            size: width as u64 * height as u64 * 16,
            usage: storage_usage,
            mapped_at_creation: false,
        });
        let status = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("specular status"),
            size: 16,
            usage: storage_usage | wgpu::BufferUsages::COPY_SRC | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let slice_params = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("specular slices"),
            size: MAX_SLICES as u64 * SLICE_STRIDE,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let maps_view =
            maps.texture.create_view(&wgpu::TextureViewDescriptor { dimension: Some(D2Array), ..Default::default() });
        let bindings = Bindings {
            layout,
            params: keep(&params_buffer),
            nodes,
            prims,
            surfaces: keep(&scene_buffers.surfaces),
            textures: keep(&scene_buffers.textures),
            tables,
            direct,
            maps: maps_view,
            normal: gbuffer.normal.create_view(&Default::default()),
            albedo: gbuffer.albedo.create_view(&Default::default()),
            emission: gbuffer.emission.create_view(&Default::default()),
            output: output.create_view(&Default::default()),
            media: keep(&media.params_buffer),
            accum,
            status: keep(&status),
            slices: keep(&slice_params),
        };
        let bind_group = bindings.bind_group(device, &grid);
        let enabled = has_specular_surfaces(scene);
        SpecularPass {
            grid,
            shadow_bias: inputs.shadow_bias,
            pipeline,
            bind_group,
            width,
            height,
            enabled,
            output,
            slice_params,
            status,
            params,
            params_buffer,
            iteration_budget,
            slices: std::cell::Cell::new(0),
            bindings,
        }
    }

    /// Gathers from new photon maps, at the radii of `inputs`, from the next frame on:
    /// a new grid buffer and bind group, nothing else rebuilt.
    pub fn set_photons(&mut self, device: &wgpu::Device, queue: &wgpu::Queue, inputs: &SpecularInputs) {
        let (words, grid_params) = PackedGrids::new(inputs);
        self.grid = padded_buffer(device, "photon grids", bytemuck::cast_slice(&words), wgpu::BufferUsages::STORAGE);
        self.params = SpecularParams {
            power_unit: grid_params.power_unit,
            // The radii and the normal test too: progressive passes and the
            // viewer's sliders change them.
            normal_test: inputs.global.normal_test as u32,
            global_radius: grid_params.global_radius,
            caustic_radius: grid_params.caustic_radius,
            volume_radius: grid_params.volume_radius,
            global_buckets: grid_params.global_buckets,
            global_start_offset: grid_params.global_start_offset,
            global_photon_offset: grid_params.global_photon_offset,
            caustic_buckets: grid_params.caustic_buckets,
            caustic_start_offset: grid_params.caustic_start_offset,
            caustic_photon_offset: grid_params.caustic_photon_offset,
            volume_buckets: grid_params.volume_buckets,
            volume_start_offset: grid_params.volume_start_offset,
            volume_photon_offset: grid_params.volume_photon_offset,
            volume_min: grid_params.volume_min,
            volume_max: grid_params.volume_max,
            ..self.params
        };
        queue.write_buffer(&self.params_buffer, 0, bytemuck::bytes_of(&self.params));
        self.bind_group = self.bindings.bind_group(device, &self.grid);
    }

    /// Traces the moved `scene` (same surfaces and lights, posed anew) from
    /// the next frame on: a new BVH and lights; `scene_buffers` (its BVH,
    /// surfaces and textures) and `maps` are the renderer's, new buffers too. Photon grids stay (the
    /// renderer gives the moved scene's photons with `set_photons`).
    pub fn set_scene(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        scene: &Scene,
        scene_buffers: &SceneBuffers,
        lights: &GpuLights,
        maps: &ShadowMaps,
    ) {
        let sky_radiance = lights.sky_radiance.to_array();
        let SceneData { nodes, prims, direct } =
            SceneData::upload(device, &scene_buffers.bvh, lights, maps, self.shadow_bias);
        let b = &mut self.bindings;
        (b.nodes, b.prims, b.direct) = (nodes, prims, direct);
        b.surfaces = scene_buffers.surfaces.clone();
        b.textures = scene_buffers.textures.clone();
        // The region triangles stay the renderer's (rewritten in place).
        let regions = b.tables.regions.clone();
        b.tables = SpecularTables::new(
            device,
            lights,
            &maps.views_buffer,
            &regions,
            &scene_buffers.environment,
            &scene_buffers.bvh.shading,
        );
        self.params = b.tables.locate(self.params);
        b.maps = maps.texture.create_view(&wgpu::TextureViewDescriptor {
            dimension: Some(wgpu::TextureViewDimension::D2Array),
            ..Default::default()
        });
        self.params.epsilon = scene.accel.epsilon;
        self.params.sky_radiance = sky_radiance;
        queue.write_buffer(&self.params_buffer, 0, bytemuck::bytes_of(&self.params));
        self.enabled = has_specular_surfaces(scene);
        self.bind_group = self.bindings.bind_group(device, &self.grid);
    }

    /// Shades with another pass's samples of the same lights from the next
    /// frame on (`GpuLights::sampled`).
    pub fn set_light_samples(&self, queue: &wgpu::Queue, lights: &GpuLights) {
        self.bindings.tables.write_samples(queue, lights);
    }

    /// Casts its primary rays from `camera` (same resolution) from the next frame on.
    pub fn set_camera(&mut self, queue: &wgpu::Queue, camera: &hikari_core::camera::Camera) {
        let (forward, right, up, tan_half_fov) = camera.basis();
        self.params = SpecularParams {
            camera_position: camera.position.to_array(),
            tan_half_fov,
            camera_right: right.to_array(),
            aspect: camera.aspect(),
            camera_up: up.to_array(),
            camera_forward: forward.to_array(),
            jitter_x: camera.jitter.x,
            jitter_y: camera.jitter.y,
            ..self.params
        };
        queue.write_buffer(&self.params_buffer, 0, bytemuck::bytes_of(&self.params));
    }

    /// Whether the pass runs at all (the scene has specular surfaces).
    pub fn enabled(&self) -> bool {
        self.enabled
    }

    /// Dispatches the gathers are split into.
    pub fn slices(&self) -> u32 {
        self.slices.get().max(1)
    }

    /// Splits the gathers into `slices` dispatches from the next frame on.
    pub fn set_slices(&self, slices: u32) {
        self.slices.set(slices.clamp(1, MAX_SLICES));
    }

    /// The loop iterations one invocation may run.
    pub fn iteration_budget(&self) -> u32 {
        self.iteration_budget
    }

    /// What the last recorded frame reported (waits for it).
    pub fn read_status(&self, ctx: &crate::GpuContext) -> Result<SpecularStatus, crate::GpuError> {
        crate::block::wait_for(self.read_status_async(ctx))
    }

    /// `read_status` without blocking.
    pub async fn read_status_async(&self, ctx: &crate::GpuContext) -> Result<SpecularStatus, crate::GpuError> {
        let words = crate::readback::read_u32s_async(ctx, &self.status, 2).await?;
        Ok(SpecularStatus { over_budget: words[0], most_iterations: words[1] })
    }

    /// Records the pass for progressive pass `pass`: one dispatch per slice,
    /// after clearing the status.
    pub fn record(&self, queue: &wgpu::Queue, encoder: &mut wgpu::CommandEncoder, pass: u32) {
        self.record_slices(queue, encoder, pass, self.slices(), self.slices());
    }

    /// Records only the first of `MAX_SLICES` slices, the one that does
    /// the most (the direct light, and the most photons of each cell): its
    /// status says whether any split of the gathers can fit the budget,
    /// for the cost of one dispatch. Leaves no image (the last slice
    /// stores it); the next `record` clears what it wrote.
    pub fn record_probe(&self, queue: &wgpu::Queue, encoder: &mut wgpu::CommandEncoder, pass: u32) {
        self.record_slices(queue, encoder, pass, MAX_SLICES, 1);
    }

    /// The first `dispatched` of `count` slices.
    fn record_slices(
        &self,
        queue: &wgpu::Queue,
        encoder: &mut wgpu::CommandEncoder,
        pass: u32,
        count: u32,
        dispatched: u32,
    ) {
        if !self.enabled {
            return;
        }
        let params: Vec<u8> = (0..dispatched)
            .flat_map(|index| {
                let p = SliceParams { index, count, iteration_budget: self.iteration_budget, pass_index: pass };
                let mut bytes = bytemuck::bytes_of(&p).to_vec();
                bytes.resize(SLICE_STRIDE as usize, 0);
                bytes
            })
            .collect();
        queue.write_buffer(&self.slice_params, 0, &params);
        self.bindings.tables.copy_in(encoder);
        encoder.clear_buffer(&self.status, 0, None);
        let mut pass = encoder
            .begin_compute_pass(&wgpu::ComputePassDescriptor { label: Some("specular"), timestamp_writes: None });
        pass.set_pipeline(&self.pipeline);
        for index in 0..dispatched {
            pass.set_bind_group(0, &self.bind_group, &[index * SLICE_STRIDE as u32]);
            pass.dispatch_workgroups(self.width.div_ceil(WORKGROUP), self.height.div_ceil(WORKGROUP), 1);
        }
    }
}

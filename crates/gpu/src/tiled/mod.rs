//! The tiled estimator (tiled.wgsl): the raster splat's sum computed in
//! compute shaders, photons binned into 16×16-pixel screen tiles and each
//! pixel summing its tile's list, in fixed point so the result does not
//! depend on the order the atomics ran in. On GPUs whose rasterizer is a
//! small part of the chip (H100/H200: 4 of 132 SMs run fragment shaders)
//! this is the faster estimator (`Estimator`).
//!
//! The list buffer's size and the number of gather slices depend on where
//! the photons fall, which only the GPU knows: `TiledBinding::check` reads
//! the frame's status back, and `fit` grows the list or adds slices when a
//! frame needed more, so the frame is drawn again rather than drawn wrong.

use crate::context::{GpuContext, GpuError};
use crate::gbuffer::GBuffer;
use crate::lod::{LodOutput, dispatch_grid};
use crate::media::GpuMedia;
use crate::wgsl::{ESTIMATE, Module, PREFIX_SUM, SCAN_WORKGROUP, compose};
use bytemuck::{Pod, Zeroable};
use std::cell::Cell;

/// Pixels per tile side (`TILE` in tiled.wgsl).
pub const TILE: u32 = 16;

/// How photon density is estimated on the GPU.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Estimator {
    /// The seed's method: one instanced quad per photon, added by blending.
    Raster,
    /// Photons binned into screen tiles, each pixel gathering in a compute shader.
    Tiled,
}

impl Estimator {
    /// The documented rule: tiled where the adapter is a hardware GPU
    /// (compute runs on the whole chip, rasterization on part of it), the
    /// raster splat on software adapters, where the splat's fixed-function
    /// path is cheaper than the gather's loops and needs no loop slicing,
    /// and where the adapter offers too few storage buffers for the gather
    /// (a browser's WebGPU may offer 8).
    pub fn for_adapter(ctx: &GpuContext) -> Estimator {
        let software = ctx.adapter_info.device_type == wgpu::DeviceType::Cpu;
        // A browser may offer too few storage buffers for the tiled gather.
        let tiled_fits = crate::capabilities::storage_buffer_shortfall(
            &ctx.limits,
            crate::capabilities::TILED_STORAGE_BUFFERS,
            "the tiled estimator",
        )
        .is_none();
        if software || !tiled_fits { Estimator::Raster } else { Estimator::Tiled }
    }
}

pub fn shader_source(radiance_format: wgpu::TextureFormat) -> String {
    static TILED: Module = Module {
        name: "tiled.wgsl",
        source: include_str!("tiled.wgsl"),
        requires: &[
            &crate::wgsl::UNCOUNTED_LOOPS,
            &ESTIMATE,
            &crate::wgsl::PHOTON_BRDF,
            &crate::gbuffer::layer_texels::LAYER_TEXELS,
            &crate::splat::FOOTPRINT_RECT,
            &PREFIX_SUM,
            &crate::lod::LOD_PHOTON,
            &crate::media::VIEW_DEPTH,
            &crate::media::REGION_ARRAY,
            &crate::wgsl::VOLUME_CHORD,
        ],
    };
    let format = if radiance_format == wgpu::TextureFormat::Rgba32Float { "rgba32float" } else { "rgba16float" };
    compose(&[&TILED]).replace("RADIANCE_FORMAT", format)
}

/// Mirrors `TiledParams` in tiled.wgsl.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct TiledParams {
    pub clip_from_world: [[f32; 4]; 4],
    pub radius: f32,
    pub power_unit: f32,
    pub normal_test: u32,
    pub width: u32,
    pub height: u32,
    pub tiles_x: u32,
    pub tiles_y: u32,
    pub list_capacity: u32,
    pub scan_workgroups: u32,
    pub slice_start: u32,
    pub slice_length: u32,
    pub last_slice: u32,
    pub loop_budget: u32,
    pub _pad0: u32,
    pub _pad1: u32,
    pub _pad2: u32,
}

pub struct TiledPass {
    count_tiles: wgpu::ComputePipeline,
    sum_groups: wgpu::ComputePipeline,
    scan_groups: wgpu::ComputePipeline,
    write_starts: wgpu::ComputePipeline,
    fill_tiles: wgpu::ComputePipeline,
    gather: wgpu::ComputePipeline,
    gather_volume: wgpu::ComputePipeline,
    layout: wgpu::BindGroupLayout,
}

/// One map's tiles, lists and sums, kept between frames; rebuilt when its
/// photons (`LodOutput`) change or a frame needed more room.
pub struct TiledBinding {
    map: TiledMap,
    tiles: (u32, u32),
    size: (u32, u32),
    list_capacity: u32,
    /// Gather dispatches per frame, and the list entries each reads.
    slices: u32,
    slice_length: u32,
    /// One params block per slice, at 256-byte offsets.
    params: wgpu::Buffer,
    tile_counts: wgpu::Buffer,
    status: wgpu::Buffer,
    bind_group: wgpu::BindGroup,
    /// The last frame's status was checked and fitted.
    checked: Cell<bool>,
}

/// Which estimate a binding gathers.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TiledMap {
    /// A surface map (global or caustic) at the G-buffer's points.
    Surface,
    /// The volume map along the view rays.
    Volume,
}

/// What a frame of one map needed (`TiledBinding::check`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct TiledStatus {
    pub list_entries: u32,
    pub longest_list: u32,
    pub over_budget: u32,
}

const PARAMS_STRIDE: u64 = 256;

impl TiledPass {
    /// Specialised to what a scene with `features` uses.
    pub fn new(
        device: &wgpu::Device,
        radiance_format: wgpu::TextureFormat,
        features: crate::features::SceneFeatures,
    ) -> Self {
        let source = shader_source(radiance_format);
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("tiled.wgsl"),
            source: wgpu::ShaderSource::Wgsl(source.as_str().into()),
        });
        let constants = features.constants(&source);
        use crate::binding::{dynamic_uniform, entry, storage, texture};
        let compute = |b, ty| entry(b, wgpu::ShaderStages::COMPUTE, ty);
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("tiled"),
            entries: &[
                compute(0, dynamic_uniform(std::mem::size_of::<TiledParams>() as u64)),
                compute(1, storage(true)),
                compute(2, storage(true)),
                compute(3, storage(false)),
                compute(4, storage(false)),
                compute(5, storage(false)),
                compute(6, storage(false)),
                compute(7, storage(false)),
                compute(8, storage(false)),
                compute(9, texture(wgpu::TextureViewDimension::D2)),
                compute(10, texture(wgpu::TextureViewDimension::D2)),
                compute(11, texture(wgpu::TextureViewDimension::D2)),
                compute(
                    12,
                    wgpu::BindingType::StorageTexture {
                        access: wgpu::StorageTextureAccess::WriteOnly,
                        format: radiance_format,
                        view_dimension: wgpu::TextureViewDimension::D2,
                    },
                ),
                compute(13, crate::binding::uniform()),
                compute(14, storage(true)),
                compute(15, texture(wgpu::TextureViewDimension::D2Array)),
                compute(16, storage(true)),
                compute(17, texture(wgpu::TextureViewDimension::D2)),
                compute(18, crate::binding::texture_uint()),
            ],
        });
        let pipeline_layout = crate::binding::pipeline_layout(device, "tiled", &layout);
        let pipeline = |entry_point: &str| {
            crate::binding::compute_pipeline_with(
                device,
                entry_point,
                &pipeline_layout,
                &module,
                entry_point,
                &constants,
            )
        };
        TiledPass {
            count_tiles: pipeline("count_tiles"),
            sum_groups: pipeline("sum_groups"),
            scan_groups: pipeline("scan_groups"),
            write_starts: pipeline("write_starts"),
            fill_tiles: pipeline("fill_tiles"),
            gather: pipeline("gather"),
            gather_volume: pipeline("gather_volume"),
            layout,
        }
    }

    /// Buffers for estimating `photons` over `gbuffer` into `target`, with
    /// room for `list_capacity` list entries and `slices` gather dispatches;
    /// `map` says which gather (the volume's sees `media`).
    #[allow(clippy::too_many_arguments)]
    pub fn bind(
        &self,
        device: &wgpu::Device,
        gbuffer: &GBuffer,
        media: &GpuMedia,
        map: TiledMap,
        photons: &LodOutput,
        surfaces: &wgpu::Buffer,
        target: &wgpu::Texture,
        list_capacity: u32,
        slices: u32,
        slice_length: u32,
    ) -> TiledBinding {
        let size = (gbuffer.width, gbuffer.height);
        let tiles = (size.0.div_ceil(TILE), size.1.div_ceil(TILE));
        let tile_count = (tiles.0 * tiles.1) as u64;
        use wgpu::BufferUsages as U;
        let buffer = |label: &str, bytes: u64, usage: wgpu::BufferUsages| {
            device.create_buffer(&wgpu::BufferDescriptor {
                label: Some(label),
                size: bytes.max(16),
                usage,
                mapped_at_creation: false,
            })
        };
        let params = buffer("tiled params", PARAMS_STRIDE * slices as u64, U::UNIFORM | U::COPY_DST);
        let tile_counts = buffer("tile counts", tile_count * 4, U::STORAGE | U::COPY_DST);
        let group_sums = buffer("tile group sums", tile_count.div_ceil(SCAN_WORKGROUP as u64) * 4, U::STORAGE);
        let tile_starts = buffer("tile starts", tile_count * 4, U::STORAGE);
        let tile_lists = buffer("tile lists", list_capacity as u64 * 4, U::STORAGE);
        let accum = buffer("tiled sums", size.0 as u64 * size.1 as u64 * 32, U::STORAGE);
        let status = buffer("tiled status", 16, U::STORAGE | U::COPY_DST | U::COPY_SRC);
        let view = |t: &wgpu::Texture| t.create_view(&Default::default());
        let (position, normal, albedo, output) =
            (view(&gbuffer.position), view(&gbuffer.normal), view(&gbuffer.albedo), view(target));
        let (emission, layers) = (view(&gbuffer.emission), view(&gbuffer.layers));
        let slices_view = media.slices.create_view(&wgpu::TextureViewDescriptor {
            dimension: Some(wgpu::TextureViewDimension::D2Array),
            ..Default::default()
        });
        fn whole(binding: u32, b: &wgpu::Buffer) -> wgpu::BindGroupEntry<'_> {
            wgpu::BindGroupEntry { binding, resource: b.as_entire_binding() }
        }
        fn texture(binding: u32, v: &wgpu::TextureView) -> wgpu::BindGroupEntry<'_> {
            wgpu::BindGroupEntry { binding, resource: wgpu::BindingResource::TextureView(v) }
        }
        let bind_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("tiled"),
            layout: &self.layout,
            entries: &[
                wgpu::BindGroupEntry {
                    binding: 0,
                    resource: wgpu::BindingResource::Buffer(wgpu::BufferBinding {
                        buffer: &params,
                        offset: 0,
                        size: std::num::NonZeroU64::new(std::mem::size_of::<TiledParams>() as u64),
                    }),
                },
                whole(1, &photons.survivors),
                whole(2, &photons.draw_args),
                whole(3, &tile_counts),
                whole(4, &group_sums),
                whole(5, &tile_starts),
                whole(6, &tile_lists),
                whole(7, &accum),
                whole(8, &status),
                texture(9, &position),
                texture(10, &normal),
                texture(11, &albedo),
                texture(12, &output),
                whole(13, &media.params_buffer),
                whole(14, &media.regions),
                texture(15, &slices_view),
                whole(16, surfaces),
                texture(17, &emission),
                texture(18, &layers),
            ],
        });
        TiledBinding {
            map,
            tiles,
            size,
            list_capacity,
            slices,
            slice_length,
            params,
            tile_counts,
            status,
            bind_group,
            checked: Cell::new(false),
        }
    }

    /// Records one map's estimate: bin, scan, fill, then the gather slices.
    /// `base` holds the camera, radius, power unit and normal test.
    pub fn record(
        &self,
        queue: &wgpu::Queue,
        encoder: &mut wgpu::CommandEncoder,
        binding: &TiledBinding,
        base: &crate::splat::SplatParams,
        photons: &LodOutput,
        loop_budget: u32,
    ) {
        let tile_count = binding.tiles.0 * binding.tiles.1;
        let scan_workgroups = tile_count.div_ceil(SCAN_WORKGROUP);
        for slice in 0..binding.slices {
            let params = TiledParams {
                clip_from_world: base.clip_from_world,
                radius: base.radius,
                power_unit: base.power_unit,
                normal_test: base.normal_test,
                width: binding.size.0,
                height: binding.size.1,
                tiles_x: binding.tiles.0,
                tiles_y: binding.tiles.1,
                list_capacity: binding.list_capacity,
                scan_workgroups,
                slice_start: slice * binding.slice_length,
                slice_length: binding.slice_length,
                last_slice: (slice + 1 == binding.slices) as u32,
                loop_budget,
                _pad0: 0,
                _pad1: 0,
                _pad2: 0,
            };
            queue.write_buffer(&binding.params, slice as u64 * PARAMS_STRIDE, bytemuck::bytes_of(&params));
        }
        encoder.clear_buffer(&binding.tile_counts, 0, None);
        encoder.clear_buffer(&binding.status, 0, None);
        binding.checked.set(false);
        let mut pass = encoder
            .begin_compute_pass(&wgpu::ComputePassDescriptor { label: Some("tiled estimate"), timestamp_writes: None });
        pass.set_bind_group(0, &binding.bind_group, &[0]);
        // Survivors are counted on the GPU: dispatch for all the map could hold.
        let (x, y) = dispatch_grid(photons.capacity().div_ceil(256).max(1));
        pass.set_pipeline(&self.count_tiles);
        pass.dispatch_workgroups(x, y, 1);
        pass.set_pipeline(&self.sum_groups);
        pass.dispatch_workgroups(scan_workgroups, 1, 1);
        pass.set_pipeline(&self.scan_groups);
        pass.dispatch_workgroups(1, 1, 1);
        pass.set_pipeline(&self.write_starts);
        pass.dispatch_workgroups(scan_workgroups, 1, 1);
        pass.set_pipeline(&self.fill_tiles);
        pass.dispatch_workgroups(x, y, 1);
        pass.set_pipeline(if binding.map == TiledMap::Volume { &self.gather_volume } else { &self.gather });
        for slice in 0..binding.slices {
            pass.set_bind_group(0, &binding.bind_group, &[slice * PARAMS_STRIDE as u32]);
            pass.dispatch_workgroups(binding.tiles.0, binding.tiles.1, 1);
        }
    }
}

impl TiledBinding {
    /// The last recorded frame's needs (waits for it).
    pub fn check(&self, ctx: &GpuContext) -> Result<TiledStatus, GpuError> {
        crate::block::wait_for(self.check_async(ctx))
    }

    /// `check` without blocking.
    pub async fn check_async(&self, ctx: &GpuContext) -> Result<TiledStatus, GpuError> {
        let s = crate::readback::read_u32s_async(ctx, &self.status, 4).await?;
        self.checked.set(true);
        Ok(TiledStatus { list_entries: s[0], longest_list: s[1], over_budget: s[2] })
    }

    /// Whether the last frame fitted: every list entry stored and every list
    /// gathered within the slices.
    pub fn fits(&self, status: &TiledStatus) -> bool {
        status.over_budget == 0
            && status.list_entries <= self.list_capacity
            && status.longest_list <= self.slices * self.slice_length
    }

    pub fn list_capacity(&self) -> u32 {
        self.list_capacity
    }

    pub fn slices(&self) -> u32 {
        self.slices
    }
}

/// List entries and gather slices for a frame that needed `status`, with
/// `slice_length` entries per slice (the loop budget) and at most
/// `max_entries` entries (the adapter's largest buffer).
pub fn fitted_sizes(status: &TiledStatus, slice_length: u32, max_entries: u32) -> Result<(u32, u32), GpuError> {
    if status.over_budget > 0 {
        return Err(GpuError::LoopBudget(format!(
            "{} photons cover more screen tiles than the adapter's loop budget ({slice_length}); the tiled estimator cannot draw them",
            status.over_budget
        )));
    }
    let entries = status.list_entries.saturating_add(status.list_entries / 4).max(1024);
    if status.list_entries > max_entries {
        return Err(GpuError::TooLarge(format!(
            "the tiled estimator needs {} tile-list entries; the adapter's largest buffer holds {max_entries}",
            status.list_entries
        )));
    }
    Ok((entries.min(max_entries), status.longest_list.div_ceil(slice_length.max(1)).max(1)))
}

//! Photon tracing in a compute shader (trace.wgsl), compacted into the
//! global, caustic and volume maps in path order (compact.wgsl): the GPU
//! twin of `hikari_core::photon::trace_photons` (every light, material and
//! medium, region meshes included), with the same random
//! streams and the same 20-byte photons.
//!
//! Paths run in batches of at most `MAX_BATCH_PATHS`; each batch's buffers
//! are kept for the next call. A batch whose photons overflow the record
//! buffer runs again with room for all of them (the tracer counts what it
//! could not write), so nothing is dropped and the maps stay deterministic.

use crate::context::{GpuContext, GpuError};
use crate::features::SceneFeatures;
use crate::lod::dispatch_grid;
use crate::tables::PackedTables;
use crate::wgsl::{BVH, Module, OPTICS, PHOTON_ENCODING, PREFIX_SUM, RANDOM, SAMPLING, SPOT, SURFACE, compose};
use bytemuck::{Pod, Zeroable};
use hikari_core::geometry::{FlatBvh, FlatNode};
use hikari_core::light::Light;
use hikari_core::material::{Rgb, mean};
use hikari_core::photon::{Photon, TraceSettings, TraceStats, TracedPhotons};
use hikari_core::sampling::Rng;
use hikari_core::scene::Scene;
use web_time::Instant;
use wgpu::util::DeviceExt;

/// Paths per batch: bounds the batch buffers (about 100 bytes per path).
pub const MAX_BATCH_PATHS: u32 = 1 << 20;
/// Invocations per workgroup of the tracing dispatch (an override constant of trace.wgsl).
pub const TRACE_WORKGROUP: u32 = 64;
/// Record slots per path in a batch's first try: cornell-box stores 1.7.
pub const RECORDS_PER_PATH: u32 = 3;

/// The record a stored photon travels in from trace.wgsl to compact.wgsl.
static RECORD: Module = Module { name: "record.wgsl", source: include_str!("record.wgsl"), requires: &[] };

pub fn trace_shader_source() -> String {
    static TRACE: Module = Module {
        name: "trace.wgsl",
        source: include_str!("trace.wgsl"),
        requires: &[
            &RANDOM,
            &SAMPLING,
            &OPTICS,
            &BVH,
            &crate::wgsl::HIT_NORMALS,
            &SURFACE,
            &crate::wgsl::BSDF,
            &crate::wgsl::DIELECTRIC,
            &crate::wgsl::CUT_OUTS,
            &SPOT,
            &PHOTON_ENCODING,
            &RECORD,
            &crate::wgsl::REGION_CROSSING,
            &crate::tables::TABLES,
        ],
    };
    compose(&[&TRACE])
}

pub fn compact_shader_source() -> String {
    static COMPACT: Module =
        Module { name: "compact.wgsl", source: include_str!("compact.wgsl"), requires: &[&PREFIX_SUM, &RECORD] };
    compose(&[&COMPACT])
}

/// Mirrors `TraceParams` in trace.wgsl.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct TraceParams {
    pub mixed_seed: [u32; 2],
    pub increment: [u32; 2],
    pub first_path: [u32; 2],
    pub paths: u32,
    pub max_bounces: u32,
    pub light_count: u32,
    pub epsilon: f32,
    pub record_capacity: u32,
    pub iteration_budget: u32,
    pub medium_count: u32,
    pub global_mask: u32,
    pub region_triangles: u32,
    pub _pad0: u32,
    /// The distant lights' disc: centre and radius (0 without distant lights).
    pub distant_disc: [f32; 4],
    /// Word offsets of the tables behind the texture words.
    pub light_table: u32,
    pub medium_table: u32,
    pub region_table: u32,
    pub emissive_table: u32,
}

/// Mirrors `TraceLight` in trace.wgsl.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct TraceLight {
    pub origin: [f32; 3],
    pub kind: u32,
    pub axis: [f32; 3],
    pub radius: f32,
    pub edge_v: [f32; 3],
    pub cos_cutoff: f32,
    pub normal: [f32; 3],
    pub cutoff: f32,
    pub power: [f32; 3],
    pub falloff_start: f32,
    pub probability: f32,
    /// An emissive mesh's triangles in the tracer's triangle buffer.
    pub first_triangle: u32,
    pub triangle_count: u32,
    pub two_sided: u32,
    /// A sky image's sampling block in the texture buffer (word offset,
    /// `textures::sky_block`); 0 for a uniform sky and the other lights.
    pub sky_image: u32,
    pub _pad0: u32,
    pub _pad1: u32,
    pub _pad2: u32,
}

/// Mirrors `TraceTriangle` in trace.wgsl: a triangle of an emissive mesh
/// with its mesh's cumulative area up to it and before it, and its unit
/// winding normal.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct TraceTriangle {
    pub v0: [f32; 3],
    pub cumulative_area: f32,
    pub v1: [f32; 3],
    pub start_area: f32,
    pub v2: [f32; 3],
    pub _pad0: u32,
    pub normal: [f32; 3],
    pub _pad1: u32,
}

/// Mirrors `TraceMedium` in trace.wgsl.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct TraceMedium {
    pub sigma_t: [f32; 3],
    pub phase_slot: u32,
    pub sigma_s: [f32; 3],
    pub phase_kind: f32,
    pub phase_parameter: f32,
    pub _pad0: u32,
    pub _pad1: u32,
    pub _pad2: u32,
}

/// Mirrors `TraceRegionTriangle` in trace.wgsl.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct TraceRegionTriangle {
    pub a: [f32; 3],
    pub medium: u32,
    pub b: [f32; 3],
    pub _pad0: u32,
    pub c: [f32; 3],
    pub _pad1: u32,
}

/// Mirrors `PhotonRecord` in trace.wgsl and compact.wgsl.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct PhotonRecord {
    pub path: u32,
    pub tag: u32,
    pub position_x: f32,
    pub position_y: f32,
    pub position_z: f32,
    pub power_rgb9e5: u32,
    pub direction_and_class: u32,
    pub _pad: u32,
}

/// Mirrors `CompactParams` in compact.wgsl.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct CompactParams {
    pub elements: u32,
    pub paths: u32,
    pub record_capacity: u32,
    pub workgroups: u32,
}

/// The light as trace.wgsl emits from it, carrying `power` (each photon's
/// starting power in power units) and its selection probability; an
/// emissive mesh's triangles start at `first_triangle` of the triangle buffer.
fn trace_light(light: &Light, power: Rgb, probability: f32, first_triangle: u32) -> TraceLight {
    let mut out = TraceLight { power: power.to_array(), probability, ..TraceLight::zeroed() };
    match *light {
        Light::Point { position, .. } => {
            out.origin = position.to_array();
            out.kind = 0;
        }
        Light::Spot { position, axis, cutoff, falloff_start, .. } => {
            out.origin = position.to_array();
            out.kind = 1;
            out.axis = axis.to_array();
            out.cos_cutoff = cutoff.cos();
            out.cutoff = cutoff;
            out.falloff_start = falloff_start;
        }
        Light::Sphere { center, radius, .. } => {
            out.origin = center.to_array();
            out.kind = 2;
            out.radius = radius;
        }
        Light::Quad { corner, edge_u, edge_v, .. } => {
            out.origin = corner.to_array();
            out.kind = 3;
            out.axis = edge_u.to_array();
            out.edge_v = edge_v.to_array();
            out.normal = edge_u.cross(edge_v).normalize().to_array();
        }
        Light::Directional { direction, disc, .. } => {
            out.origin = disc.center.to_array();
            out.kind = 4;
            out.axis = direction.to_array();
            out.radius = disc.radius;
        }
        Light::Environment { disc, .. } => {
            out.origin = disc.center.to_array();
            out.kind = 5;
            out.radius = disc.radius;
        }
        Light::Mesh(ref mesh) => {
            out.kind = 6;
            // The total area exactly as `EmissiveMesh::area` gives it.
            out.radius = mesh.area();
            out.first_triangle = first_triangle;
            out.triangle_count = mesh.triangles().len() as u32;
            out.two_sided = mesh.two_sided as u32;
        }
    }
    out
}

/// Every emissive mesh's triangles, in light order, and where each light's start.
fn trace_triangles(lights: &[Light]) -> (Vec<TraceTriangle>, Vec<u32>) {
    let mut triangles = Vec::new();
    let mut firsts = Vec::with_capacity(lights.len());
    for light in lights {
        firsts.push(triangles.len() as u32);
        let Light::Mesh(mesh) = light else { continue };
        let cumulative = mesh.cumulative_areas();
        for (i, &[v0, v1, v2]) in mesh.triangles().iter().enumerate() {
            triangles.push(TraceTriangle {
                v0: v0.to_array(),
                cumulative_area: cumulative[i],
                v1: v1.to_array(),
                start_area: if i == 0 { 0.0 } else { cumulative[i - 1] },
                v2: v2.to_array(),
                // As EmissiveMesh::sample_point computes it.
                normal: (v1 - v0).cross(v2 - v0).normalize_or_zero().to_array(),
                ..TraceTriangle::zeroed()
            });
        }
    }
    (triangles, firsts)
}

/// What the tracer reads of the scene, uploaded by `GpuTracer::set_scene`.
struct TraceScene {
    nodes: wgpu::Buffer,
    prims: wgpu::Buffer,
    shading: wgpu::Buffer,
    surfaces: wgpu::Buffer,
    region_triangles: u32,
    global_mask: u32,
    /// The packed textures, coordinates in the BVH's order
    /// (`textures::pack_scene`), then the tables (`tables::PackedTables`):
    /// media, region triangles, emissive meshes' triangles and room for
    /// the lights, which each dispatch writes.
    tables: wgpu::Buffer,
    light_table: u32,
    medium_table: u32,
    region_table: u32,
    emissive_table: u32,
    /// Where the sky image's sampling block starts in `textures` (0: none).
    sky_image: u32,
    first_triangles: Vec<u32>,
    distant_disc: [f32; 4],
    lights: Vec<Light>,
    probabilities: Vec<f32>,
    total_power: f32,
    epsilon: f32,
    medium_count: u32,
}

fn storage_buffer(device: &wgpu::Device, label: &str, bytes: &[u8]) -> wgpu::Buffer {
    // wgpu refuses empty bindings.
    let bytes: &[u8] = if bytes.is_empty() { &[0; 64] } else { bytes };
    device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: Some(label),
        contents: bytes,
        usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
    })
}

impl TraceScene {
    fn upload(device: &wgpu::Device, scene: &Scene) -> Self {
        let bvh = FlatBvh::new(&scene.accel);
        let texture_words = crate::textures::pack_scene_for_tracing(scene, &bvh);
        // An empty scene: one node whose box no ray meets.
        let empty = [FlatNode { min: [1.0; 3], prim_count: 0, max: [-1.0; 3], first: 0 }];
        let nodes: &[FlatNode] = if bvh.nodes.is_empty() { &empty } else { &bvh.nodes };
        let media = &scene.media;
        let entries: Vec<TraceMedium> = media
            .entries()
            .iter()
            .map(|e| {
                let (kind, parameter) = match e.medium.phase {
                    hikari_core::medium::Phase::Schlick { k } => (0.0, k),
                    hikari_core::medium::Phase::HenyeyGreenstein { g } => (1.0, g),
                };
                TraceMedium {
                    sigma_t: e.medium.sigma_t().to_array(),
                    phase_slot: e.phase_slot as u32,
                    sigma_s: e.medium.sigma_s.to_array(),
                    phase_kind: kind,
                    phase_parameter: parameter,
                    ..TraceMedium::zeroed()
                }
            })
            .collect();
        let regions: Vec<TraceRegionTriangle> = media
            .entries()
            .iter()
            .enumerate()
            .filter_map(|(i, e)| e.region.as_ref().map(|r| (i, r)))
            .flat_map(|(i, region)| {
                region.triangles().iter().map(move |[a, b, c]| TraceRegionTriangle {
                    a: a.to_array(),
                    medium: i as u32,
                    b: b.to_array(),
                    c: c.to_array(),
                    ..TraceRegionTriangle::zeroed()
                })
            })
            .collect();
        let (triangles, first_triangles) = trace_triangles(&scene.lights);
        let sky_image = texture_words[2];
        let mut tables = PackedTables::after(texture_words);
        let medium_table = tables.push(&entries);
        let region_table = tables.push(&regions);
        let emissive_table = tables.push(&triangles);
        let light_table = tables.reserve_for::<TraceLight>(scene.lights.len());
        TraceScene {
            nodes: storage_buffer(device, "trace bvh nodes", bytemuck::cast_slice(nodes)),
            prims: storage_buffer(device, "trace bvh prims", bytemuck::cast_slice(&bvh.prims)),
            shading: storage_buffer(device, "trace bvh shading", bytemuck::cast_slice(&bvh.shading)),
            surfaces: storage_buffer(
                device,
                "trace surfaces",
                &crate::scene_upload::surfaces_contents(&crate::scene_upload::scene_surfaces(scene, true)),
            ),
            region_triangles: regions.len() as u32,
            global_mask: media.global_mask(),
            tables: storage_buffer(device, "trace textures and tables", bytemuck::cast_slice(&tables.words)),
            light_table,
            medium_table,
            region_table,
            emissive_table,
            sky_image,
            first_triangles,
            distant_disc: scene
                .lights
                .iter()
                .find_map(Light::distant_disc)
                .map_or([0.0; 4], |d| d.center.extend(d.radius).to_array()),
            lights: scene.lights.clone(),
            probabilities: scene.light_selection_probabilities(),
            total_power: scene.lights.iter().map(|l| mean(l.power())).sum(),
            epsilon: bvh.epsilon,
            medium_count: entries.len() as u32,
        }
    }
}

/// The buffers of one batch size, kept between calls.
struct Batch {
    paths: u32,
    record_capacity: u32,
    params: wgpu::Buffer,
    compact_params: wgpu::Buffer,
    status: wgpu::Buffer,
    photons: wgpu::Buffer,
    bounces: wgpu::Buffer,
    map_starts: wgpu::Buffer,
    trace_bind_group: wgpu::BindGroup,
    compact_bind_group: wgpu::BindGroup,
}

/// What one batch left on the GPU.
#[derive(Clone, Copy, Debug, Default)]
struct BatchResult {
    /// First caustic slot, first volume slot, total photons.
    map_starts: [u32; 3],
    truncated: u32,
}

/// How a `GpuTracer::trace` call went, beside its photons.
#[derive(Clone, Debug, Default)]
pub struct GpuTraceReport {
    /// Seconds from the first dispatch until the last batch's maps were
    /// compacted on the GPU (including the status readback that checks them).
    pub gpu_seconds: f64,
    /// Seconds spent copying the maps back to the host.
    pub readback_seconds: f64,
    /// Batches that ran again because their photons overflowed the records.
    pub retried_batches: u32,
    /// Most loop iterations one path ran (against the adapter's budget).
    pub most_iterations: u32,
}

pub struct GpuTracer {
    trace: wgpu::ComputePipeline,
    /// What `trace` is specialised to (`SceneFeatures`); a scene edited to
    /// use more gets a new pipeline.
    features: SceneFeatures,
    trace_module: wgpu::ShaderModule,
    trace_pipeline_layout: wgpu::PipelineLayout,
    sum_groups: wgpu::ComputePipeline,
    scan_groups: wgpu::ComputePipeline,
    write_offsets: wgpu::ComputePipeline,
    place: wgpu::ComputePipeline,
    trace_layout: wgpu::BindGroupLayout,
    compact_layout: wgpu::BindGroupLayout,
    scene: TraceScene,
    batch: Option<Batch>,
    iteration_budget: u32,
    /// Read back each photon's diffuse-bounce count to fill
    /// `TraceStats::stored_flux_per_bounce` (tests; costs 4 bytes a photon).
    pub per_bounce_statistics: bool,
    /// Paths per batch (`MAX_BATCH_PATHS`; tests make it small).
    pub batch_paths: u32,
    /// Record slots per path in a batch's first try (`RECORDS_PER_PATH`;
    /// tests make it small to exercise the retry).
    pub records_per_path: u32,
}

/// The tracing pipeline of `module` (trace.wgsl), specialised to `features`.
fn trace_pipeline(
    device: &wgpu::Device,
    layout: &wgpu::PipelineLayout,
    module: &wgpu::ShaderModule,
    features: SceneFeatures,
) -> wgpu::ComputePipeline {
    let mut constants = features.constants(&trace_shader_source());
    constants.push(("WORKGROUP_SIZE", TRACE_WORKGROUP as f64));
    crate::binding::compute_pipeline_with(device, "trace paths", layout, module, "trace_paths", &constants)
}

impl GpuTracer {
    pub fn new(ctx: &GpuContext, scene: &Scene) -> Result<Self, GpuError> {
        Self::with_features(ctx, scene, SceneFeatures::of_scene(scene))
    }

    /// `new` with the tracing pipeline specialised to `features`, which
    /// must include the scene's (tests compare `SceneFeatures::ALL`).
    #[doc(hidden)]
    pub fn with_features(ctx: &GpuContext, scene: &Scene, features: SceneFeatures) -> Result<Self, GpuError> {
        let device = &ctx.device;
        ctx.scoped(|| {
            use crate::binding::{entry, storage, uniform};
            let compute = |b, ty| entry(b, wgpu::ShaderStages::COMPUTE, ty);
            let trace_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
                label: Some("trace"),
                entries: &[
                    compute(0, uniform()),
                    compute(1, storage(true)),
                    compute(2, storage(true)),
                    compute(3, storage(true)),
                    compute(4, storage(true)),
                    compute(5, storage(false)),
                    compute(6, storage(false)),
                    compute(7, storage(false)),
                    compute(8, storage(true)),
                ],
            });
            let compact_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
                label: Some("trace compact"),
                entries: &[
                    compute(0, uniform()),
                    compute(1, storage(false)),
                    compute(2, storage(false)),
                    compute(3, storage(true)),
                    compute(4, storage(false)),
                    compute(5, storage(false)),
                    compute(6, storage(false)),
                    compute(7, storage(true)),
                ],
            });
            let trace_module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
                label: Some("trace.wgsl"),
                source: wgpu::ShaderSource::Wgsl(trace_shader_source().into()),
            });
            let compact_module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
                label: Some("compact.wgsl"),
                source: wgpu::ShaderSource::Wgsl(compact_shader_source().into()),
            });
            let trace_pipeline_layout = crate::binding::pipeline_layout(device, "trace", &trace_layout);
            let trace = trace_pipeline(device, &trace_pipeline_layout, &trace_module, features);
            let compact_pipeline_layout = crate::binding::pipeline_layout(device, "trace compact", &compact_layout);
            let compact = |entry_point: &str| {
                crate::binding::compute_pipeline(
                    device,
                    entry_point,
                    &compact_pipeline_layout,
                    &compact_module,
                    entry_point,
                )
            };
            GpuTracer {
                trace,
                features,
                trace_module,
                trace_pipeline_layout,
                sum_groups: compact("sum_groups"),
                scan_groups: compact("scan_groups"),
                write_offsets: compact("write_offsets"),
                place: compact("place"),
                trace_layout,
                compact_layout,
                scene: TraceScene::upload(device, scene),
                batch: None,
                iteration_budget: ctx.loop_budget,
                per_bounce_statistics: false,
                batch_paths: MAX_BATCH_PATHS,
                records_per_path: RECORDS_PER_PATH,
            }
        })
    }

    /// Traces from a moved or edited scene from now on.
    pub fn set_scene(&mut self, ctx: &GpuContext, scene: &Scene) -> Result<(), GpuError> {
        let features = SceneFeatures::of_scene(scene);
        if features.union(self.features) != self.features {
            let device = &ctx.device;
            self.trace =
                ctx.scoped(|| trace_pipeline(device, &self.trace_pipeline_layout, &self.trace_module, features))?;
            self.features = features;
        }
        let scene = ctx.scoped(|| TraceScene::upload(&ctx.device, scene))?;
        self.scene = scene;
        // The bind groups hold the old scene's buffers.
        self.batch = None;
        Ok(())
    }

    /// Traces `settings.photons` paths and reads the maps back: the same
    /// maps as `trace_photons` up to float rounding (see the tests).
    pub fn trace(
        &mut self,
        ctx: &GpuContext,
        settings: &TraceSettings,
    ) -> Result<(TracedPhotons, GpuTraceReport), GpuError> {
        crate::block::wait_for(self.trace_async(ctx, settings))
    }

    /// `trace` without blocking: each batch's readbacks are awaited, so a
    /// browser's frames go on while a large set is traced.
    pub async fn trace_async(
        &mut self,
        ctx: &GpuContext,
        settings: &TraceSettings,
    ) -> Result<(TracedPhotons, GpuTraceReport), GpuError> {
        let n = settings.photons.max(1);
        let power_unit = self.scene.total_power / n as f32;
        let mut traced = TracedPhotons {
            global: Vec::new(),
            caustic: Vec::new(),
            volume: Vec::new(),
            power_unit,
            stats: TraceStats { emitted: n, ..Default::default() },
        };
        let mut report = GpuTraceReport::default();
        let mut bounces_of_global: Vec<u32> = Vec::new();
        let mut first = 0u64;
        while first < n {
            let paths = (n - first).min(self.batch_paths.max(1) as u64) as u32;
            let started = Instant::now();
            let result = self.run_batch(ctx, settings, n, first, paths, &mut report).await?;
            report.gpu_seconds += started.elapsed().as_secs_f64();
            let started = Instant::now();
            let batch = self.batch.as_ref().expect("run_batch made the batch");
            let [caustic_start, volume_start, total] = result.map_starts;
            let words = crate::readback::read_u32s_async(ctx, &batch.photons, total as u64 * 5).await?;
            let photons: &[Photon] = bytemuck::cast_slice(&words);
            traced.global.extend_from_slice(&photons[..caustic_start as usize]);
            traced.caustic.extend_from_slice(&photons[caustic_start as usize..volume_start as usize]);
            traced.volume.extend_from_slice(&photons[volume_start as usize..]);
            if self.per_bounce_statistics {
                let bounces = crate::readback::read_u32s_async(ctx, &batch.bounces, caustic_start as u64).await?;
                bounces_of_global.extend(bounces);
            }
            report.readback_seconds += started.elapsed().as_secs_f64();
            traced.stats.truncated += result.truncated as u64;
            first += paths as u64;
        }
        if self.per_bounce_statistics {
            let per_bounce = &mut traced.stats.stored_flux_per_bounce;
            for (photon, &k) in traced.global.iter().zip(&bounces_of_global) {
                if per_bounce.len() <= k as usize {
                    per_bounce.resize(k as usize + 1, Rgb::ZERO);
                }
                per_bounce[k as usize] += photon.power_in_units() * power_unit;
            }
        }
        Ok((traced, report))
    }

    /// Traces without reading the maps back: how many photons each map got.
    /// For measuring the tracing rate.
    pub fn trace_on_gpu(&mut self, ctx: &GpuContext, settings: &TraceSettings) -> Result<[u64; 3], GpuError> {
        crate::block::wait_for(self.trace_on_gpu_async(ctx, settings))
    }

    async fn trace_on_gpu_async(&mut self, ctx: &GpuContext, settings: &TraceSettings) -> Result<[u64; 3], GpuError> {
        let n = settings.photons.max(1);
        let mut report = GpuTraceReport::default();
        let mut sizes = [0u64; 3];
        let mut first = 0u64;
        while first < n {
            let paths = (n - first).min(self.batch_paths.max(1) as u64) as u32;
            let [caustic_start, volume_start, total] =
                self.run_batch(ctx, settings, n, first, paths, &mut report).await?.map_starts;
            sizes[0] += caustic_start as u64;
            sizes[1] += (volume_start - caustic_start) as u64;
            sizes[2] += (total - volume_start) as u64;
            first += paths as u64;
        }
        Ok(sizes)
    }

    /// Traces paths `first .. first + paths` of a run of `n` and compacts
    /// their maps, running again with more record room if they overflowed.
    async fn run_batch(
        &mut self,
        ctx: &GpuContext,
        settings: &TraceSettings,
        n: u64,
        first: u64,
        paths: u32,
        report: &mut GpuTraceReport,
    ) -> Result<BatchResult, GpuError> {
        let max_records = (ctx.limits.max_storage_buffer_binding_size as u64
            / std::mem::size_of::<PhotonRecord>() as u64)
            .min(u32::MAX as u64 / 5) as u32;
        let mut record_capacity = paths.saturating_mul(self.records_per_path).clamp(16, max_records);
        if let Some(batch) = &self.batch {
            if batch.paths >= paths {
                record_capacity = record_capacity.max(batch.record_capacity);
            }
        }
        loop {
            self.ensure_batch(ctx, paths, record_capacity)?;
            let status = self.dispatch(ctx, settings, n, first, paths).await?;
            let [taken, truncated, over_budget, iterations] = [status[0], status[1], status[2], status[3]];
            report.most_iterations = report.most_iterations.max(iterations);
            if over_budget > 0 {
                return Err(GpuError::LoopBudget(format!(
                    "{over_budget} photon paths ran past the adapter's loop budget of {} iterations on the GPU tracer",
                    self.iteration_budget
                )));
            }
            let capacity = self.batch.as_ref().map_or(0, |b| b.record_capacity);
            if taken <= capacity {
                return Ok(BatchResult { map_starts: [status[4], status[5], status[6]], truncated });
            }
            if taken > max_records {
                return Err(GpuError::TooLarge(format!(
                    "{taken} photons from {paths} paths exceed the adapter's largest storage buffer ({max_records} records)"
                )));
            }
            report.retried_batches += 1;
            // Room for what this batch stored, and a margin for the next.
            record_capacity = taken.saturating_add(taken / 8).min(max_records);
        }
    }

    /// Makes (or keeps) buffers for `paths` paths and `record_capacity` records.
    fn ensure_batch(&mut self, ctx: &GpuContext, paths: u32, record_capacity: u32) -> Result<(), GpuError> {
        if let Some(batch) = &self.batch {
            if batch.paths >= paths && batch.record_capacity >= record_capacity {
                return Ok(());
            }
        }
        self.batch = None;
        let batch = ctx.scoped(|| self.create_batch(&ctx.device, paths, record_capacity))?;
        self.batch = Some(batch);
        Ok(())
    }

    fn create_batch(&self, device: &wgpu::Device, paths: u32, record_capacity: u32) -> Batch {
        let buffer = |label: &str, size: u64, usage: wgpu::BufferUsages| {
            device.create_buffer(&wgpu::BufferDescriptor {
                label: Some(label),
                size: size.max(16),
                usage,
                mapped_at_creation: false,
            })
        };
        use wgpu::BufferUsages as U;
        let elements = 3 * paths as u64;
        let params = buffer("trace params", std::mem::size_of::<TraceParams>() as u64, U::UNIFORM | U::COPY_DST);
        let compact_params =
            buffer("trace compact params", std::mem::size_of::<CompactParams>() as u64, U::UNIFORM | U::COPY_DST);
        let records =
            buffer("trace records", record_capacity as u64 * std::mem::size_of::<PhotonRecord>() as u64, U::STORAGE);
        let counts = buffer("trace counts", elements * 4, U::STORAGE);
        let status = buffer("trace status", 16, U::STORAGE | U::COPY_DST | U::COPY_SRC);
        let group_sums = buffer("trace group sums", elements.div_ceil(256) * 4, U::STORAGE);
        let photons = buffer("traced photons", record_capacity as u64 * 20, U::STORAGE | U::COPY_SRC);
        let bounces = buffer("traced photon bounces", record_capacity as u64 * 4, U::STORAGE | U::COPY_SRC);
        let map_starts = buffer("traced map starts", 16, U::STORAGE | U::COPY_SRC);
        let bind = |layout: &wgpu::BindGroupLayout, label: &str, buffers: &[&wgpu::Buffer]| {
            let entries: Vec<wgpu::BindGroupEntry> = buffers
                .iter()
                .enumerate()
                .map(|(i, b)| wgpu::BindGroupEntry { binding: i as u32, resource: b.as_entire_binding() })
                .collect();
            device.create_bind_group(&wgpu::BindGroupDescriptor { label: Some(label), layout, entries: &entries })
        };
        let s = &self.scene;
        let trace_bind_group = bind(
            &self.trace_layout,
            "trace",
            &[&params, &s.nodes, &s.prims, &s.shading, &s.surfaces, &records, &counts, &status, &s.tables],
        );
        let compact_bind_group = bind(
            &self.compact_layout,
            "trace compact",
            &[&compact_params, &counts, &group_sums, &records, &photons, &bounces, &map_starts, &status],
        );
        Batch {
            paths,
            record_capacity,
            params,
            compact_params,
            status,
            photons,
            bounces,
            map_starts,
            trace_bind_group,
            compact_bind_group,
        }
    }

    /// Records and runs one batch; returns the tracer's status words then
    /// the map starts.
    async fn dispatch(
        &self,
        ctx: &GpuContext,
        settings: &TraceSettings,
        n: u64,
        first: u64,
        paths: u32,
    ) -> Result<[u32; 7], GpuError> {
        let batch = self.batch.as_ref().expect("ensure_batch ran");
        let s = &self.scene;
        let power_unit = s.total_power / n as f32;
        let lights: Vec<TraceLight> = s
            .lights
            .iter()
            .zip(&s.probabilities)
            .zip(&s.first_triangles)
            .map(|((light, &p), &first)| {
                let mut t = trace_light(light, light.power() / (p * n as f32) / power_unit, p, first);
                if matches!(light, Light::Environment { map: Some(_), .. }) {
                    t.sky_image = s.sky_image;
                }
                t
            })
            .collect();
        let (mixed_seed, increment) = Rng::seed_constants(settings.seed);
        let words = |x: u64| [x as u32, (x >> 32) as u32];
        let params = TraceParams {
            mixed_seed: words(mixed_seed),
            increment: words(increment),
            first_path: words(first),
            paths,
            max_bounces: settings.max_bounces,
            light_count: lights.len() as u32,
            epsilon: s.epsilon,
            record_capacity: batch.record_capacity,
            iteration_budget: self.iteration_budget,
            medium_count: s.medium_count,
            global_mask: s.global_mask,
            region_triangles: s.region_triangles,
            _pad0: 0,
            distant_disc: s.distant_disc,
            light_table: s.light_table,
            medium_table: s.medium_table,
            region_table: s.region_table,
            emissive_table: s.emissive_table,
        };
        let elements = 3 * paths;
        let scan_workgroups = elements.div_ceil(crate::wgsl::SCAN_WORKGROUP);
        let compact =
            CompactParams { elements, paths, record_capacity: batch.record_capacity, workgroups: scan_workgroups };
        let queue = &ctx.queue;
        queue.write_buffer(&batch.params, 0, bytemuck::bytes_of(&params));
        queue.write_buffer(&s.tables, s.light_table as u64 * 4, bytemuck::cast_slice(&lights));
        queue.write_buffer(&batch.compact_params, 0, bytemuck::bytes_of(&compact));
        queue.write_buffer(&batch.status, 0, &[0; 16]);
        let mut encoder = ctx.device.create_command_encoder(&Default::default());
        {
            let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some("trace photons"),
                timestamp_writes: None,
            });
            pass.set_pipeline(&self.trace);
            pass.set_bind_group(0, &batch.trace_bind_group, &[]);
            let (x, y) = dispatch_grid(paths.div_ceil(TRACE_WORKGROUP));
            pass.dispatch_workgroups(x, y, 1);
            pass.set_bind_group(0, &batch.compact_bind_group, &[]);
            let (x, y) = dispatch_grid(scan_workgroups);
            pass.set_pipeline(&self.sum_groups);
            pass.dispatch_workgroups(x, y, 1);
            pass.set_pipeline(&self.scan_groups);
            pass.dispatch_workgroups(1, 1, 1);
            pass.set_pipeline(&self.write_offsets);
            pass.dispatch_workgroups(x, y, 1);
            let (x, y) = dispatch_grid(batch.record_capacity.div_ceil(crate::wgsl::SCAN_WORKGROUP));
            pass.set_pipeline(&self.place);
            pass.dispatch_workgroups(x, y, 1);
        }
        ctx.scoped(|| queue.submit([encoder.finish()]))?;
        let status = crate::readback::read_u32s_async(ctx, &batch.status, 4).await?;
        let starts = crate::readback::read_u32s_async(ctx, &batch.map_starts, 3).await?;
        Ok([status[0], status[1], status[2], status[3], starts[0], starts[1], starts[2]])
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// trace.wgsl's `light_at` and the other readers step through the
    /// tables by these strides (in words).
    #[test]
    fn table_records_have_the_strides_the_shader_reads() {
        use std::mem::size_of;
        assert_eq!(size_of::<TraceLight>(), 28 * 4);
        assert_eq!(size_of::<TraceMedium>(), 12 * 4);
        assert_eq!(size_of::<TraceRegionTriangle>(), 12 * 4);
        assert_eq!(size_of::<TraceTriangle>(), 16 * 4);
        let source = trace_shader_source();
        for stride in ["i * 28u", "i * 12u", "i * 16u"] {
            assert!(source.contains(stride), "trace.wgsl reads records with stride {stride}");
        }
    }

    #[test]
    fn quad_lights_carry_the_normal_emit_uses() {
        let light = Light::Quad {
            corner: glam::Vec3::ZERO,
            edge_u: glam::Vec3::new(2.0, 0.0, 0.0),
            edge_v: glam::Vec3::new(0.0, 0.0, 0.5),
            radiance: Rgb::ONE,
        };
        let t = trace_light(&light, Rgb::ONE, 1.0, 0);
        assert_eq!(t.kind, 3);
        assert_eq!(t.normal, [0.0, -1.0, 0.0]);
    }
}

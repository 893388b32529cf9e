//! `hikari render`: load a scene, trace photons, render, write the image.

use crate::passes::renderers::{CpuPasses, GpuPasses, PathPasses, VcmPasses};
use crate::passes::{self, PassPlan, read_reference};
use crate::progress_bar::TerminalProgress;
use crate::tracing::{PhotonTracer, TraceDevice};
use anyhow::{Context, Result};
use clap::{Args, ValueEnum};
use hikari_core::lod::LodSettings;
use hikari_core::output::write_image;
use hikari_core::photon::TracedPhotons;
use hikari_core::photon::{TraceSettings, trace_photons};
use hikari_core::progress::Silent;
use hikari_core::progressive::shard::{Part, PartHeader, Shard, fingerprint};
use hikari_core::progressive::{DEFAULT_ALPHA, ImageMean, Schedules, pass_trace_settings};
use hikari_core::render::{Image, path, photon_cpu, vcm};

/// A render without --passes, --time or --target-error (nor --spp with the
/// path tracer) renders passes until the noise they estimate falls to this
/// fraction of the image's mean, or for this many seconds, whichever first.
pub const DEFAULT_TARGET_ERROR: f64 = 0.02;
pub const DEFAULT_TIME_LIMIT: f64 = 20.0;
/// Samples per pixel of the path tracer's open-ended passes (without --spp).
const PATH_PASS_SPP: u32 = 4;
use hikari_core::scene::{Scene, builtin};
use hikari_gpu::tiled::Estimator;
use hikari_gpu::{GpuContext, GpuError, GpuRenderer, GpuSettings};
use std::path::PathBuf;
use std::time::{Duration, Instant};

/// Returns a `UsageError` (exit code 2) with a formatted message.
macro_rules! usage {
    ($($arg:tt)*) => {
        return Err(UsageError(format!($($arg)*)).into())
    };
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum RendererKind {
    /// The seed's photon splatting on the GPU. Falls back to photon-cpu,
    /// saying why, when no adapter can run it, when the scene or settings
    /// exceed the adapter's limits, or on any GPU error.
    Gpu,
    /// The seed's fixed-radius photon mapping on the CPU.
    PhotonCpu,
    /// Path tracer: the unbiased ground truth (next-event estimation with MIS; equiangular sampling of point and spot lights in fog).
    Path,
    /// Vertex connection and merging: light tracing, bidirectional
    /// connections and photon merging weighted by MIS, in progressive
    /// passes, fog included (points in media merge within a ball).
    Vcm,
}

/// Which of VCM's strategies `--renderer vcm` uses.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum VcmStrategies {
    /// Connections and merging.
    All,
    /// Connections only: bidirectional path tracing (unbiased).
    Connections,
    /// Merging only: progressive photon mapping at every eye vertex.
    Merging,
    /// Light tracing alone (and the lights the eye sees directly).
    LightTracing,
}

impl From<VcmStrategies> for hikari_core::render::vcm::Strategies {
    fn from(s: VcmStrategies) -> Self {
        use hikari_core::render::vcm::Strategies;
        match s {
            VcmStrategies::All => Strategies::All,
            VcmStrategies::Connections => Strategies::Connections,
            VcmStrategies::Merging => Strategies::Merging,
            VcmStrategies::LightTracing => Strategies::LightTracing,
        }
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum EstimatorChoice {
    /// Tiled on hardware GPUs (their compute units far outnumber their
    /// rasterizers), raster on software adapters (lavapipe, llvmpipe).
    Auto,
    /// The seed's method: one instanced quad per photon, added by blending.
    Raster,
    /// Photons binned into 16×16-pixel screen tiles, each pixel summing
    /// its tile's photons in a compute shader (exact fixed-point sums).
    Tiled,
}

impl EstimatorChoice {
    pub fn on(self, ctx: &GpuContext) -> Estimator {
        match self {
            EstimatorChoice::Auto => Estimator::for_adapter(ctx),
            EstimatorChoice::Raster => Estimator::Raster,
            EstimatorChoice::Tiled => Estimator::Tiled,
        }
    }
}

#[derive(Args, Clone, Debug)]
pub struct RenderArgs {
    /// A built-in scene name (see `hikari scenes`), a path to a .toml scene
    /// file, or a glTF 2.0 file (.glb, or .gltf with its buffers).
    #[arg(default_value = builtin::DEFAULT)]
    pub scene: String,
    /// Output image: .png (tone-mapped sRGB) or .exr (linear float RGB).
    #[arg(short, long, default_value = "hikari.png")]
    pub output: PathBuf,
    #[arg(long, value_enum, default_value_t = RendererKind::Gpu)]
    pub renderer: RendererKind,
    /// Where photons are traced: auto is the GPU on a hardware adapter and
    /// the CPU on a software one (lavapipe, llvmpipe) or without an adapter.
    #[arg(long, value_enum, default_value_t = TraceDevice::Auto)]
    pub trace: TraceDevice,
    /// How the GPU renderer estimates the global, caustic and volume maps.
    #[arg(long, value_enum, default_value_t = EstimatorChoice::Auto)]
    pub estimator: EstimatorChoice,
    /// Photon paths emitted from the lights (1 to 100,000,000; the memory
    /// the maps will take is printed above 2,000,000).
    #[arg(long, default_value_t = 200_000, value_parser = clap::value_parser!(u64).range(1..=MAX_PHOTONS))]
    pub photons: u64,
    /// Global-map radius r in scene units, between 1e-5 and 0.5 scene
    /// diagonals [default: 3% of the scene diagonal].
    #[arg(long, allow_negative_numbers = true)]
    pub radius: Option<f32>,
    /// Caustic-map radius in scene units, between 1e-5 and 0.5 scene
    /// diagonals [default: 1% of the scene diagonal].
    #[arg(long, allow_negative_numbers = true)]
    pub caustic_radius: Option<f32>,
    /// Samples per pixel, 1 to 65536 [default: 4 for photon-cpu, 64 for path].
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=65536))]
    pub spp: Option<u32>,
    /// Override the scene's resolution, e.g. 1280x720, or 1280 (or x720) to
    /// keep the camera's aspect ratio (each side 1 to 16384, at most
    /// 8192x8192 pixels in all).
    #[arg(long, value_parser = parse_resolution)]
    pub resolution: Option<Resolution>,
    /// The camera of a glTF file to render through, by name [default: the
    /// first perspective camera; without one, a camera framing the scene].
    #[arg(long)]
    pub camera: Option<String>,
    /// Light the scene by this equirectangular sky image (.hdr or .exr,
    /// Blender's orientation) in place of its environment.
    #[arg(long, value_name = "FILE")]
    pub environment: Option<std::path::PathBuf>,
    /// With --renderer vcm: which of its strategies to use.
    #[arg(long, value_enum, default_value_t = VcmStrategies::All)]
    pub vcm_strategies: VcmStrategies,
    /// Random seed: the same seed gives the same image whatever the thread count.
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// Render the scene's animations (`[[animation]]`) at this time, in
    /// seconds (0 to 1,000,000).
    #[arg(long, default_value_t = 0.0, value_parser = parse_time, allow_negative_numbers = true)]
    pub at: f32,
    /// Worker threads, 1 to 1024 [default: all cores].
    #[arg(long, value_parser = clap::value_parser!(u64).range(1..=1024))]
    pub threads: Option<u64>,
    /// Exposure in stops applied before PNG tone mapping (-64 to 64).
    #[arg(long, default_value_t = 0.0, allow_negative_numbers = true)]
    pub exposure: f32,
    /// Shadow-map side in texels for each shadow view, 16 to 8192 (gpu; the
    /// views' total memory is checked against the adapter before tracing).
    #[arg(long, default_value_t = 1024, value_parser = clap::value_parser!(u32).range(16..=8192))]
    pub shadow_map_size: u32,
    /// Samples per area light, 1 to 256: shadow rays per shaded point
    /// (photon-cpu), shadow-mapped points on the light (gpu; each takes
    /// shadow-map layers, checked against the adapter's memory).
    #[arg(long, default_value_t = 4, value_parser = clap::value_parser!(u32).range(1..=256))]
    pub area_light_samples: u32,
    /// Volume-map radius in scene units, between 1e-5 and 0.5 scene
    /// diagonals [default: 3% of the scene diagonal for one pass, 0.8% for
    /// the first of progressive passes; vcm: its merging radius in media,
    /// 0.3%].
    #[arg(long, allow_negative_numbers = true)]
    pub volume_radius: Option<f32>,
    /// Optical-depth slices along each view ray through region media, 1 to 64 (gpu).
    #[arg(long, default_value_t = 8, value_parser = clap::value_parser!(u32).range(1..=64))]
    pub volume_slices: u32,
    /// Count only photons that arrived from the side the surface faces the
    /// eye: stops light leaking through thin walls and across edges and
    /// corners [default: off for one pass (the seed's method), on for
    /// progressive passes, where it lowered cornell-box's error after 128
    /// passes by 29%; `--normal-test=false` turns it off].
    #[arg(long, num_args = 0..=1, default_missing_value = "true", require_equals = true)]
    pub normal_test: Option<bool>,
    /// LOD (gpu): photons nearer the eye than this are fully detailed when
    /// lod-near < lod-far, fully culled when lod-near > lod-far (scene units).
    #[arg(long, requires = "lod_far", allow_negative_numbers = true)]
    pub lod_near: Option<f32>,
    /// LOD (gpu): the other end of the detail ramp (scene units).
    #[arg(long, requires = "lod_near", allow_negative_numbers = true)]
    pub lod_far: Option<f32>,
    /// LOD (gpu): number of photon groups A, 1 to 1000.
    #[arg(long, default_value_t = 20, value_parser = clap::value_parser!(u32).range(1..=1000))]
    pub lod_groups: u32,
    /// Progressive photon mapping (docs/progressive.md): render up to this
    /// many passes, each with a fresh photon set and smaller radii, and
    /// average them, 1 to 1,000,000; `--passes 1` is the seed's single
    /// pass [default: until the estimated noise is 2% or 20 s have passed;
    /// no limit with --time or --target-error]. With --renderer path, passes
    /// of --spp samples (a single pass where --spp alone is given).
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=1_000_000))]
    pub passes: Option<u32>,
    /// Stop the passes after the first that ends past this many seconds.
    #[arg(long, value_parser = parse_seconds, allow_negative_numbers = true)]
    pub time: Option<f64>,
    /// The radius schedule's α in (0, 1): r² shrinks by (i + α)/(i + 1)
    /// after pass i; smaller shrinks faster.
    #[arg(long, default_value_t = DEFAULT_ALPHA, value_parser = parse_alpha)]
    pub alpha: f32,
    /// Render passes until the noise the passes themselves estimate (two
    /// interleaved half-images; relative to the image's mean, as --reference
    /// reports) falls to this fraction, e.g. 0.02. With --time, whichever
    /// comes first. Noise only: photon mapping's blur is not in it. The GPU
    /// reads its estimate back after passes 2, 3, 4, 6, 8, 12, 16, ….
    #[arg(long, value_parser = parse_fraction)]
    pub target_error: Option<f64>,
    /// With passes: write the image so far every this many seconds.
    #[arg(long, value_parser = parse_seconds, allow_negative_numbers = true)]
    pub checkpoint: Option<f64>,
    /// An image of the same size (e.g. a long path-traced EXR): print the
    /// error against it at each checkpoint and at the end: the per-pixel RMS
    /// error over the reference's mean (relRMSE), the image means' ratio,
    /// the same error on 16×16 blocks, and the older RMS-relative figure.
    #[arg(long)]
    pub reference: Option<PathBuf>,
    /// Render only shard K of M: passes K, K + M, K + 2M, … of --passes
    /// N (or as many as --time allows), the same passes, seeds and radii
    /// one run of all N renders, into an .exr part that `hikari merge`
    /// adds up with the other shards' into that run's image (docs/cluster.md).
    #[arg(long, value_parser = Shard::parse, value_name = "K/M")]
    pub shard: Option<Shard>,
    /// Render frames A to B (both included) of the scene's animation, frame
    /// f at time f / --fps, each to the output named with its run of #
    /// replaced by the zero-padded frame number (-o out-####.exr). Frames
    /// whose file exists are skipped, so a re-run after a failure resumes.
    #[arg(long, value_parser = parse_frames, value_name = "A..B", conflicts_with_all = ["shard", "at"])]
    pub frames: Option<(u32, u32)>,
    /// Frames per second of --frames (0.001 to 10,000).
    #[arg(long, default_value_t = 24.0, value_parser = parse_fps, requires = "frames")]
    pub fps: f64,
    /// No progress bars.
    #[arg(short, long)]
    pub quiet: bool,
}

/// "A..B" with A ≤ B ≤ 1,000,000.
fn parse_frames(text: &str) -> Result<(u32, u32), String> {
    let bad = || format!("{text}: frames are A..B, both included, 0 ≤ A ≤ B ≤ 1000000 (e.g. 0..119)");
    let (a, b) = text.split_once("..").ok_or_else(bad)?;
    let (a, b) = (a.trim().parse::<u32>().map_err(|_| bad())?, b.trim().parse::<u32>().map_err(|_| bad())?);
    if a > b || b > 1_000_000 {
        return Err(bad());
    }
    Ok((a, b))
}

fn parse_fps(text: &str) -> Result<f64, String> {
    match text.parse::<f64>() {
        Ok(v) if (0.001..=10_000.0).contains(&v) => Ok(v),
        _ => Err(format!("{text}: frames per second must be between 0.001 and 10000")),
    }
}

/// `output` with its last run of # replaced by `frame`, zero-padded to
/// the run's length (out-####.exr, 7 → out-0007.exr).
pub fn frame_path(output: &std::path::Path, frame: u32) -> Option<PathBuf> {
    let name = output.file_name()?.to_str()?;
    let end = name.rfind('#')? + 1;
    let start = name[..end].rfind(|c| c != '#').map_or(0, |i| i + 1);
    let width = end - start;
    Some(output.with_file_name(format!("{}{frame:0width$}{}", &name[..start], &name[end..])))
}

/// A duration in seconds: finite and positive, at most a year.
fn parse_seconds(text: &str) -> Result<f64, String> {
    let t: f64 = text.parse().map_err(|_| format!("`{text}` is not a number of seconds"))?;
    if t > 0.0 && t <= 3.2e7 { Ok(t) } else { Err(format!("{t} s: must be more than 0 and at most a year")) }
}

/// Knaus & Zwicker's α: strictly between 0 and 1.
fn parse_alpha(text: &str) -> Result<f32, String> {
    let a: f32 = text.parse().map_err(|_| format!("`{text}` is not a number"))?;
    if a > 0.0 && a < 1.0 { Ok(a) } else { Err(format!("{a}: α must lie strictly between 0 and 1")) }
}

/// An animation time in seconds: finite, in [0, 10⁶].
pub fn parse_time(text: &str) -> Result<f32, String> {
    let t: f32 = text.parse().map_err(|_| format!("`{text}` is not a number of seconds"))?;
    if (0.0..=1e6).contains(&t) { Ok(t) } else { Err(format!("{t} s is outside 0 to 1,000,000 s")) }
}

/// An image size from `--resolution`: both sides, or one side with the
/// other following the camera's aspect ratio.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Resolution {
    pub width: Option<u32>,
    pub height: Option<u32>,
}

impl Resolution {
    /// Both sides, the missing one from `aspect` (width / height).
    pub fn resolve(&self, aspect: f32) -> Result<(u32, u32), String> {
        use hikari_core::scene::limits::{MAX_PIXELS, MAX_SIDE};
        let side = |x: f32| (x.round() as u32).max(1);
        let (w, h) = match (self.width, self.height) {
            (Some(w), Some(h)) => (w, h),
            (Some(w), None) => (w, side(w as f32 / aspect)),
            (None, Some(h)) => (side(h as f32 * aspect), h),
            (None, None) => unreachable!("parse_resolution gives at least one side"),
        };
        if w > MAX_SIDE || h > MAX_SIDE {
            return Err(format!("--resolution: {w}x{h} at the camera's aspect ratio has a side above {MAX_SIDE}"));
        }
        if w as u64 * h as u64 > MAX_PIXELS {
            return Err(format!("--resolution: {w}x{h} is more than {MAX_PIXELS} pixels (8192x8192)"));
        }
        Ok((w, h))
    }
}

/// `WIDTHxHEIGHT`, or `WIDTH` (also `WIDTHx`) or `xHEIGHT` to keep the camera's aspect ratio.
pub fn parse_resolution(s: &str) -> Result<Resolution, String> {
    let expected = || format!("`{s}`: expected WIDTHxHEIGHT (e.g. 640x480), WIDTH or xHEIGHT");
    let (w, h) = s.split_once(['x', 'X']).unwrap_or((s, ""));
    let parse = |v: &str| -> Result<Option<u32>, String> {
        let v = v.trim();
        if v.is_empty() { Ok(None) } else { v.parse::<u32>().map(Some).map_err(|_| expected()) }
    };
    let (width, height) = (parse(w)?, parse(h)?);
    if width.is_none() && height.is_none() {
        return Err(expected());
    }
    use hikari_core::scene::limits::{MAX_PIXELS, MAX_SIDE};
    if [width, height].iter().flatten().any(|&x| x == 0 || x > MAX_SIDE) {
        return Err(format!("`{s}`: each side must be between 1 and {MAX_SIDE}"));
    }
    if let (Some(w), Some(h)) = (width, height)
        && w as u64 * h as u64 > MAX_PIXELS
    {
        return Err(format!("`{s}`: at most {MAX_PIXELS} pixels (8192x8192)"));
    }
    Ok(Resolution { width, height })
}

/// Loads `spec` (built-in name, `.toml`, `.gltf` or `.glb`) through
/// `camera`, printing the loader's notes; a bad file is a usage error.
pub fn load_scene(
    spec: &str,
    camera: Option<&str>,
    environment: Option<&std::path::Path>,
    quiet: bool,
) -> Result<Scene, UsageError> {
    let options = hikari_core::scene::LoadOptions {
        camera: camera.map(str::to_string),
        environment: environment.map(std::path::Path::to_path_buf),
    };
    // A bar only for files that take over a second (a large glTF file).
    let progress = TerminalProgress::after(quiet, std::time::Duration::from_secs(1));
    let scene = Scene::load_with_progress(spec, &options, &progress).map_err(|e| UsageError(e.to_string()))?;
    for note in &scene.notes {
        eprintln!("note: {note}");
    }
    Ok(scene)
}

/// Most photon paths `--photons` accepts: about 6 GB of photon maps in the
/// built-in scenes (3 stored photons of 20 bytes per path).
pub const MAX_PHOTONS: u64 = 100_000_000;

/// photon-cpu's settings for these arguments (also the GPU's radii).
fn cpu_settings(args: &RenderArgs) -> photon_cpu::PhotonCpuSettings {
    photon_cpu::PhotonCpuSettings {
        radius: args.radius,
        caustic_radius: args.caustic_radius,
        spp: args.spp.unwrap_or(4),
        seed: args.seed,
        area_light_samples: args.area_light_samples,
        normal_test: args.normal_test.unwrap_or(progressive(args)),
        volume_radius: args.volume_radius,
        ..Default::default()
    }
}

/// The GPU renderer's settings for these arguments.
fn gpu_settings(args: &RenderArgs, scene: &Scene, settings: &photon_cpu::PhotonCpuSettings) -> GpuSettings {
    let (global, caustic) = settings.estimate_params(scene);
    let lod = match (args.lod_near, args.lod_far) {
        (Some(near), Some(far)) => Some(LodSettings { near, far, groups: args.lod_groups }),
        _ => None,
    };
    GpuSettings {
        area_light_samples: args.area_light_samples,
        shadow_map_size: args.shadow_map_size,
        lod,
        volume_radius: args.volume_radius.unwrap_or_else(|| photon_cpu::default_radius(scene)),
        volume_slices: args.volume_slices,
        ..GpuSettings::new(global, caustic)
    }
}

/// Photons each map will hold for `photons` paths, from a pilot trace of a
/// few thousand paths (with 25% to spare), so limits are checked before
/// the real trace.
fn expected_map_sizes(scene: &Scene, photons: u64, seed: u64) -> [u64; 3] {
    const PILOT: u64 = 4096;
    let quiet = TerminalProgress::new(true);
    let pilot =
        trace_photons(scene, &TraceSettings { photons: PILOT, seed: seed ^ 0x9e37, ..Default::default() }, &quiet);
    let per_path = |stored: usize| (stored as f64 / PILOT as f64 * photons as f64 * 1.25).ceil() as u64 + 64;
    [per_path(pilot.indirect().len()), per_path(pilot.caustic.len()), per_path(pilot.volume.len())]
}

/// An adapter that can draw `scene` with `settings`, or None after one line
/// saying why not.
fn open_gpu(scene: &Scene, settings: &GpuSettings, expected: [u64; 3]) -> Option<GpuContext> {
    let ctx = match GpuContext::new() {
        Ok(ctx) => ctx,
        Err(e) => {
            eprintln!("{e}: rendering with photon-cpu instead");
            return None;
        }
    };
    if let Err(e) = GpuRenderer::check_fits(&ctx, scene, settings, expected) {
        eprintln!("gpu {}: {e}: rendering with photon-cpu instead", ctx.describe());
        return None;
    }
    Some(ctx)
}

/// One frame on the GPU, read back.
fn render_on_gpu(
    ctx: GpuContext,
    scene: &Scene,
    traced: &TracedPhotons,
    settings: GpuSettings,
) -> Result<(Image, u64), GpuError> {
    let adapter = format!("{}, {:?} estimator", ctx.describe(), settings.estimator);
    if !ctx.float32_blend && settings.estimator == Estimator::Raster {
        eprintln!(
            "note: {} cannot blend 32-bit float targets; photon splats accumulate in 16-bit floats (about 3 significant digits)",
            ctx.describe()
        );
    }
    let setup_start = Instant::now();
    let renderer = GpuRenderer::new(ctx, scene, traced, settings)?;
    let setup = setup_start.elapsed().as_secs_f64();
    let frame_start = Instant::now();
    renderer.render()?;
    let result = renderer.read_image()?;
    let slices = renderer.specular_slices();
    let split = if slices > 1 { format!(", specular gathers split into {slices} dispatches") } else { String::new() };
    eprintln!(
        "gpu: {adapter}; setup {setup:.2} s, frame and readback {:.3} s (1 sample per pixel{split})",
        frame_start.elapsed().as_secs_f64()
    );
    Ok(result)
}

/// Traces photons, then splats them on the GPU or estimates them on the CPU.
fn render_photons(
    args: &RenderArgs,
    renderer: RendererKind,
    scene: &Scene,
    progress: &TerminalProgress,
) -> Result<(Image, u64)> {
    let settings = cpu_settings(args);
    let gpu_settings = gpu_settings(args, scene, &settings);
    let needs_estimate = renderer == RendererKind::Gpu || args.photons > 2_000_000;
    let expected = if needs_estimate { expected_map_sizes(scene, args.photons, args.seed) } else { [0; 3] };
    if args.photons > 2_000_000 {
        let stored: u64 = expected.iter().sum();
        eprintln!(
            "note: {} photon paths will store about {} M photons: about {} MiB of photon maps",
            args.photons,
            stored / 1_000_000,
            (stored * 20) >> 20
        );
    }
    let gpu = match renderer {
        RendererKind::Gpu => open_gpu(scene, &gpu_settings, expected),
        _ => None,
    };
    let mut tracer = PhotonTracer::choose(args.trace, gpu.as_ref(), scene);
    let trace_start = Instant::now();
    let traced =
        tracer.trace(scene, &TraceSettings { photons: args.photons, seed: args.seed, ..Default::default() }, progress);
    let trace_time = trace_start.elapsed().as_secs_f64();
    eprintln!(
        "photons (traced on the {}): {} emitted, {} stored in the global map, {} in the caustic map, {} in the volume map; {:.2} M paths/s ({:.2} s)",
        tracer.device(),
        traced.stats.emitted,
        traced.global.len(),
        traced.caustic.len(),
        traced.volume.len(),
        traced.stats.emitted as f64 / trace_time / 1e6,
        trace_time
    );
    let (global, caustic) = settings.estimate_params(scene);
    eprintln!("radius {:.4}, caustic radius {:.4}", global.radius, caustic.radius);
    if let Some(ctx) = gpu {
        let gpu_settings = GpuSettings { estimator: args.estimator.on(&ctx), ..gpu_settings };
        match render_on_gpu(ctx, scene, &traced, gpu_settings) {
            Ok(result) => return Ok(result),
            Err(e) => eprintln!("gpu: {e}: rendering with photon-cpu instead"),
        }
    }
    let build_start = Instant::now();
    let cpu = photon_cpu::PhotonCpuRenderer::new(scene, &traced, &settings);
    let build_time = build_start.elapsed().as_secs_f64();
    let render_start = Instant::now();
    let result = cpu.render(progress);
    eprintln!(
        "photon-cpu: photon-map indexes {build_time:.2} s, render {:.2} s ({} spp)",
        render_start.elapsed().as_secs_f64(),
        settings.spp
    );
    Ok(result)
}

/// Whether to render in progressive passes: more than one pass, a time
/// limit, checkpoints or a reference to compare with, or nothing said
/// ([`by_default`]).
fn progressive(args: &RenderArgs) -> bool {
    args.passes.is_some_and(|n| n > 1)
        || args.time.is_some()
        || args.reference.is_some()
        || args.checkpoint.is_some()
        || args.target_error.is_some()
        || by_default(args)
}

/// Whether nothing says when to stop, so the render stops at
/// [`DEFAULT_TARGET_ERROR`] or [`DEFAULT_TIME_LIMIT`]: no --passes,
/// --time or --target-error, and for the path tracer no --spp.
fn by_default(args: &RenderArgs) -> bool {
    args.passes.is_none()
        && args.time.is_none()
        && args.target_error.is_none()
        && !(args.renderer == RendererKind::Path && args.spp.is_some())
}

/// A fraction in (0, 1).
fn parse_fraction(text: &str) -> Result<f64, String> {
    match text.parse::<f64>() {
        Ok(v) if v > 0.0 && v < 1.0 => Ok(v),
        _ => Err(format!("{text}: must be a number between 0 and 1 (e.g. 0.02 for 2%)")),
    }
}

/// What a render in passes made: the image, the non-finite samples
/// dropped and, for a shard, what its part keeps.
struct Passes {
    image: Image,
    nonfinite: u64,
    part: Option<PartBody>,
}

/// A shard's passes: its sums, which passes, and who rendered them.
struct PartBody {
    sums: Vec<[f64; 3]>,
    passes: Vec<u32>,
    stopped_early: bool,
    /// The renderer that ran (after any fallback), with how (gpu: where photons were traced, the estimator).
    renderer: String,
}

/// What `renderer` made of `plan` (`done`): a shard keeps its sums.
fn finish<R: passes::PassRenderer>(
    done: passes::Outcome,
    renderer: &mut R,
    plan: &PassPlan,
    name: &str,
    nonfinite: impl Fn(&R) -> u64,
) -> Result<Passes> {
    let part = match plan.shard {
        None => None,
        Some(_) => Some(PartBody {
            sums: renderer.sums()?,
            passes: done.passes,
            stopped_early: done.stopped_early,
            renderer: name.to_string(),
        }),
    };
    Ok(Passes { image: done.image, nonfinite: nonfinite(renderer), part })
}

/// Renders in passes (`--passes`, `--time`, `--reference`, `--shard`) with
/// `kind`; the GPU falls back to photon-cpu as the single pass does.
fn render_in_passes(args: &RenderArgs, kind: RendererKind, scene: &Scene) -> Result<Passes> {
    let reference = match &args.reference {
        None => None,
        Some(path) => {
            let image = read_reference(path).map_err(|e| UsageError(format!("{e:#}")))?;
            let (w, h) = (scene.camera.width, scene.camera.height);
            if (image.width, image.height) != (w, h) {
                usage!("--reference {}: {}x{}, but the render is {w}x{h}", path.display(), image.width, image.height);
            }
            Some((path.clone(), image))
        }
    };
    let defaults = by_default(args);
    let target_error = args.target_error.or(defaults.then_some(DEFAULT_TARGET_ERROR));
    let time = args.time.or(defaults.then_some(DEFAULT_TIME_LIMIT));
    if args.checkpoint.is_some() && args.passes.is_none_or(|n| n == 1) && time.is_none() && target_error.is_none() {
        usage!("--checkpoint needs --passes (more than 1), --time or --target-error");
    }
    if defaults && !args.quiet {
        eprintln!(
            "rendering passes until the estimated noise is {}% or {DEFAULT_TIME_LIMIT} s have passed (--passes 1: the seed's single pass)",
            100.0 * DEFAULT_TARGET_ERROR
        );
    }
    let open_ended = time.is_some() || target_error.is_some();
    let plan = PassPlan {
        passes: args.passes.unwrap_or(if open_ended { u32::MAX } else { 1 }),
        shard: args.shard,
        target_error,
        time: time.map(Duration::from_secs_f64),
        checkpoint: args.checkpoint.map(Duration::from_secs_f64),
        reference,
        output: args.output.clone(),
        exposure: args.exposure,
        quiet: args.quiet,
    };
    let (w, h) = (scene.camera.width, scene.camera.height);
    if kind == RendererKind::Path {
        let spp = args.spp.unwrap_or(if open_ended { PATH_PASS_SPP } else { 64 });
        let settings = path::PathSettings { spp, seed: args.seed, ..Default::default() };
        eprintln!("path tracing in passes of {} spp", settings.spp);
        let mut passes = PathPasses { scene, settings, mean: ImageMean::new(w, h), nonfinite: 0 };
        let done = passes::run(&mut passes, &plan)?;
        return finish(done, &mut passes, &plan, "path", |p| p.nonfinite);
    }
    if kind == RendererKind::Vcm {
        let settings = vcm::VcmSettings {
            seed: args.seed,
            strategies: args.vcm_strategies.into(),
            radius: args.radius,
            volume_radius: args.volume_radius,
            alpha: args.alpha,
            ..Default::default()
        };
        let radius = settings.radius.unwrap_or_else(|| vcm::default_radius(scene));
        let in_media = if scene.media.is_empty() {
            String::new()
        } else {
            let volume = settings.volume_radius.unwrap_or_else(|| vcm::default_volume_radius(scene));
            format!(" ({volume:.4} in media)")
        };
        eprintln!(
            "vcm ({:?}): one light and one camera subpath per pixel a pass, first merging radius {radius:.4}{in_media}, α = {}",
            settings.strategies, args.alpha
        );
        let mut passes =
            VcmPasses { scene, settings, mean: ImageMean::new(w, h), nonfinite: 0, workspace: Default::default() };
        let done = passes::run(&mut passes, &plan)?;
        return finish(done, &mut passes, &plan, "vcm", |p| p.nonfinite);
    }
    let settings = cpu_settings(args);
    let (global, caustic) = settings.estimate_params(scene);
    let volume = args.volume_radius.unwrap_or_else(|| hikari_core::progressive::default_volume_radius(scene));
    let schedules = Schedules::new([global.radius, caustic.radius, volume], args.alpha);
    eprintln!(
        "progressive: {} photon paths per pass, α = {}; first radii {:.4} (global), {:.4} (caustic){}",
        args.photons,
        args.alpha,
        global.radius,
        caustic.radius,
        if scene.media.is_empty() { String::new() } else { format!(", {volume:.4} (volume)") }
    );
    if kind == RendererKind::Gpu {
        let gpu_settings = gpu_settings(args, scene, &settings);
        let expected = expected_map_sizes(scene, args.photons, args.seed);
        if let Some(ctx) = open_gpu(scene, &gpu_settings, expected) {
            let adapter = ctx.describe();
            let mut tracer = PhotonTracer::choose(args.trace, Some(&ctx), scene);
            let device = tracer.device();
            // A shard's first pass builds the renderer (a shard with no passes: pass 1).
            let first_pass = plan.shard.map_or(1, |s| s.index);
            let first = tracer.trace(scene, &pass_trace_settings(args.photons, args.seed, first_pass), &Silent);
            let gpu_settings = GpuSettings { estimator: args.estimator.on(&ctx), ..gpu_settings };
            let estimator = gpu_settings.estimator;
            let name = format!("gpu ({estimator:?} estimator, photons traced on the {device})");
            let run = GpuPasses::new(
                ctx,
                scene,
                (first_pass, &first),
                gpu_settings,
                args.photons,
                args.seed,
                schedules,
                tracer,
            )
            .and_then(|mut passes| {
                let done = passes::run(&mut passes, &plan)?;
                finish(done, &mut passes, &plan, &name, |p| p.nonfinite)
            });
            match run {
                Ok(result) => {
                    eprintln!(
                        "gpu: {adapter}, photons traced on the {device}, passes estimated ({estimator:?}) and averaged on the GPU"
                    );
                    return Ok(result);
                }
                Err(e) => eprintln!("gpu: {e:#}: rendering the passes with photon-cpu instead"),
            }
        }
    }
    let tracer = PhotonTracer::choose(args.trace, None, scene);
    let mut passes = CpuPasses {
        scene,
        settings,
        photons: args.photons,
        schedules,
        mean: ImageMean::new(w, h),
        nonfinite: 0,
        tracer,
    };
    let done = passes::run(&mut passes, &plan)?;
    finish(done, &mut passes, &plan, "photon-cpu", |p| p.nonfinite)
}

/// The fingerprint of the scene's content: the built-in scene's text or
/// the file's bytes (not the meshes and textures it names).
fn scene_fingerprint(spec: &str) -> Result<String> {
    match builtin::source(spec) {
        Some(text) => Ok(fingerprint(text.as_bytes())),
        None => Ok(fingerprint(&std::fs::read(spec).with_context(|| format!("reading {spec} again"))?)),
    }
}

/// Every flag that changes a pass's image, by name, as a shard's part
/// records them for the merge to compare (not --passes, --time, --shard,
/// the output, --threads: the same image whatever the thread count).
fn image_settings(args: &RenderArgs) -> std::collections::BTreeMap<String, String> {
    let mut map = std::collections::BTreeMap::new();
    let mut set = |key: &str, value: String| map.insert(key.to_string(), value);
    set("renderer", format!("{:?}", args.renderer));
    set("trace", format!("{:?}", args.trace));
    set("estimator", format!("{:?}", args.estimator));
    set("photons", args.photons.to_string());
    set("radius", format!("{:?}", args.radius));
    set("caustic-radius", format!("{:?}", args.caustic_radius));
    set("volume-radius", format!("{:?}", args.volume_radius));
    set("spp", format!("{:?}", args.spp));
    set("resolution", format!("{:?}", args.resolution.map(|r| (r.width, r.height))));
    set("camera", format!("{:?}", args.camera));
    set("environment", format!("{:?}", args.environment));
    set("vcm-strategies", format!("{:?}", args.vcm_strategies));
    set("seed", args.seed.to_string());
    set("at", format!("{:?}", args.at));
    set("shadow-map-size", args.shadow_map_size.to_string());
    set("area-light-samples", args.area_light_samples.to_string());
    set("volume-slices", args.volume_slices.to_string());
    set("normal-test", format!("{:?}", args.normal_test));
    set("lod", format!("{:?} {:?} {}", args.lod_near, args.lod_far, args.lod_groups));
    set("alpha", format!("{:?}", args.alpha));
    map
}

/// A bad flag or scene: the CLI exits with code 2 (as clap does for its own
/// parse errors) and writes nothing.
#[derive(Debug)]
pub struct UsageError(pub String);

impl std::fmt::Display for UsageError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.0)
    }
}

impl std::error::Error for UsageError {}

/// Radii outside [1e-5, 0.5] scene diagonals: below, the estimate's 1/r²
/// overflows or no photon is ever found; above, every photon covers every
/// pixel and a frame takes for ever.
pub const RADIUS_RANGE: (f32, f32) = (1e-5, 0.5);

fn radius_in_range(name: &str, v: Option<f32>, diagonal: f32) -> Result<()> {
    if let Some(r) = v {
        let (lo, hi) = (RADIUS_RANGE.0 * diagonal, RADIUS_RANGE.1 * diagonal);
        if !(r >= lo && r <= hi) {
            usage!(
                "--{name} {r}: must be between {lo:.3e} and {hi:.3e} (1e-5 to 0.5 of this scene's diagonal {diagonal:.3})"
            );
        }
    }
    Ok(())
}

fn positive(name: &str, v: Option<f32>) -> Result<()> {
    match v {
        Some(r) if !(r.is_finite() && r > 0.0) => {
            usage!("--{name} {r}: must be a positive, finite length")
        }
        _ => Ok(()),
    }
}

pub fn run(args: &RenderArgs) -> Result<()> {
    positive("radius", args.radius)?;
    positive("caustic-radius", args.caustic_radius)?;
    positive("volume-radius", args.volume_radius)?;
    for (name, v) in [("lod-near", args.lod_near), ("lod-far", args.lod_far)] {
        if let Some(d) = v {
            if !(d.is_finite() && d >= 0.0) {
                usage!("--{name} {d}: must be a finite distance ≥ 0");
            }
        }
    }
    if !(args.exposure.abs() <= 64.0) {
        usage!("--exposure {}: must be between -64 and 64 stops", args.exposure);
    }
    let ext = args.output.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase);
    if !matches!(ext.as_deref(), Some("png" | "exr")) {
        usage!("{}: unsupported image type (use .png or .exr)", args.output.display());
    }
    if let Some(shard) = args.shard {
        if ext.as_deref() != Some("exr") {
            usage!(
                "--shard: {} must be an .exr file (a part keeps sums; `hikari merge` writes the PNG)",
                args.output.display()
            );
        }
        if args.passes.is_none() && args.time.is_none() {
            usage!(
                "--shard {}/{} needs --passes N (the whole render's pass count) or --time",
                shard.index,
                shard.count
            );
        }
        if args.target_error.is_some() || args.checkpoint.is_some() {
            usage!(
                "--shard: --target-error and --checkpoint judge one image; a shard is a share of one (merge the parts)"
            );
        }
        if let Some(n) = args.passes.filter(|&n| shard.count > n) {
            usage!("--shard {}/{}: more shards than --passes {n} (some would have no pass)", shard.index, shard.count);
        }
    }
    if let Some(threads) = args.threads {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads as usize)
            .build_global()
            .context("setting the thread count")?;
    }

    let scene = load_scene(&args.scene, args.camera.as_deref(), args.environment.as_deref(), args.quiet)?;
    if let Some(frames) = args.frames {
        return render_frames(args, &scene, frames);
    }
    let scene = if scene.is_animated() { scene.at_time(args.at) } else { scene };
    render_scene(args, scene)
}

/// `--frames A..B`: each frame not yet written, in order, from the scene
/// as it stands at its time.
fn render_frames(args: &RenderArgs, scene: &Scene, (first, last): (u32, u32)) -> Result<()> {
    if frame_path(&args.output, 0).is_none() {
        usage!("--frames: {} has no # for the frame number (e.g. -o out-####.exr)", args.output.display());
    }
    if !scene.is_animated() {
        eprintln!("note: {} has no animation: every frame is the same image", args.scene);
    }
    let (mut rendered, mut skipped) = (0, 0);
    for frame in first..=last {
        let output = frame_path(&args.output, frame).expect("checked above");
        if output.exists() {
            skipped += 1;
            continue;
        }
        let at = (frame as f64 / args.fps) as f32;
        if !(at <= 1_000_000.0) {
            usage!("--frames: frame {frame} at {} fps is past the last time --at allows (1,000,000 s)", args.fps);
        }
        eprintln!("frame {frame} (t = {at} s) → {}", output.display());
        let frame_scene = if scene.is_animated() { scene.at_time(at) } else { scene.clone() };
        let frame_args = RenderArgs { output: output.clone(), at, frames: None, ..args.clone() };
        render_scene(&frame_args, frame_scene).with_context(|| format!("frame {frame} ({})", output.display()))?;
        rendered += 1;
    }
    eprintln!(
        "frames {first}..{last}: {rendered} rendered, {skipped} already written{}",
        if skipped > 0 { " (skipped)" } else { "" }
    );
    Ok(())
}

/// Renders `scene` (at its time already) as the flags say and writes the image or part.
fn render_scene(args: &RenderArgs, mut scene: Scene) -> Result<()> {
    let diagonal = scene.diagonal();
    radius_in_range("radius", args.radius, diagonal)?;
    radius_in_range("caustic-radius", args.caustic_radius, diagonal)?;
    radius_in_range("volume-radius", args.volume_radius, diagonal)?;
    let renderer = args.renderer;
    if let Some(resolution) = args.resolution {
        let (w, h) = resolution.resolve(scene.camera.aspect()).map_err(UsageError)?;
        scene.camera = scene.camera.with_resolution(w, h).map_err(UsageError)?;
    }
    let progress = TerminalProgress::new(args.quiet);
    let start = Instant::now();
    let progressive = progressive(args) || args.shard.is_some();
    let in_passes = |kind| render_in_passes(args, kind, &scene);
    let Passes { image, nonfinite, part } = match renderer {
        _ if progressive => in_passes(renderer)?,
        RendererKind::Path => {
            let settings = path::PathSettings { spp: args.spp.unwrap_or(64), seed: args.seed, ..Default::default() };
            let (image, nonfinite) = path::render(&scene, &settings, &progress);
            eprintln!("path tracing: {} spp", settings.spp);
            Passes { image, nonfinite, part: None }
        }
        RendererKind::Gpu | RendererKind::PhotonCpu => {
            let (image, nonfinite) = render_photons(args, renderer, &scene, &progress)?;
            Passes { image, nonfinite, part: None }
        }
        RendererKind::Vcm => in_passes(renderer)?,
    };
    if nonfinite > 0 {
        eprintln!("warning: {nonfinite} non-finite samples were dropped");
    }
    match (part, args.shard) {
        (Some(body), Some(shard)) => {
            let header = PartHeader {
                renderer: body.renderer,
                scene: args.scene.clone(),
                scene_hash: scene_fingerprint(&args.scene)?,
                settings: image_settings(args),
                width: image.width,
                height: image.height,
                total_passes: args.passes,
                shard: shard.index,
                shards: shard.count,
                passes: body.passes,
                stopped_early: body.stopped_early,
                time_limited: args.time.is_some(),
            };
            Part { header, sums: body.sums }.write(&args.output).map_err(anyhow::Error::msg)?;
        }
        _ => write_image(&args.output, &image, args.exposure)?,
    }
    eprintln!(
        "wrote {} ({}x{}) in {:.2} s total",
        args.output.display(),
        image.width,
        image.height,
        start.elapsed().as_secs_f64()
    );
    Ok(())
}

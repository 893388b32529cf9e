//! `hikari render`: arguments in, image or shard part out. What renders
//! (the renderer chosen once, its fallback, the passes and when they stop)
//! is the engine's (`hikari_engine::Session`).

use crate::passes::{self, Reporting, read_reference};
use crate::progress_bar::TerminalProgress;
use anyhow::{Context, Result};
use clap::Args;
use hikari_core::lod::LodSettings;
use hikari_core::output::{Aov, write_exr_with_aovs, write_image};
use hikari_core::progressive::DEFAULT_ALPHA;
use hikari_core::progressive::shard::{Part, PartHeader, Shard, fingerprint};
use hikari_core::render::aov::render_aovs;
use hikari_core::scene::{Scene, builtin};
pub use hikari_engine::settings::{
    DEFAULT_TARGET_ERROR, DEFAULT_TIME_LIMIT, EstimatorChoice, MAX_PHOTONS, RendererKind, TraceDevice, VcmStrategies,
};
use hikari_engine::{Log, Plan, RenderSettings, Session};
use std::path::PathBuf;
use std::time::{Duration, Instant};

/// Returns a `UsageError` (exit code 2) with a formatted message.
macro_rules! usage {
    ($($arg:tt)*) => {
        return Err(UsageError(format!($($arg)*)).into())
    };
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
    /// Auxiliary images for denoisers, comma-separated (albedo, normal,
    /// depth), written as further channels of the .exr output under
    /// Blender's pass names ("Denoising Albedo", "Denoising Normal",
    /// "Depth"): the first surface seen through mirrors and glass, from the
    /// camera alone, so the same for every renderer.
    #[arg(long, value_enum, value_delimiter = ',')]
    pub aov: Vec<AovName>,
    /// No progress bars.
    #[arg(short, long)]
    pub quiet: bool,
}

/// `--aov`'s names.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum AovName {
    /// The reflectance of the first non-specular surface seen.
    Albedo,
    /// Its shading normal (world space, unit length).
    Normal,
    /// The distance along the camera ray to the first surface (infinity where none).
    Depth,
}

impl From<AovName> for Aov {
    fn from(name: AovName) -> Aov {
        match name {
            AovName::Albedo => Aov::Albedo,
            AovName::Normal => Aov::Normal,
            AovName::Depth => Aov::Depth,
        }
    }
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

/// The engine's settings for these arguments.
fn render_settings(args: &RenderArgs) -> RenderSettings {
    let lod = match (args.lod_near, args.lod_far) {
        (Some(near), Some(far)) => Some(LodSettings { near, far, groups: args.lod_groups }),
        _ => None,
    };
    RenderSettings {
        renderer: args.renderer,
        trace: args.trace,
        estimator: args.estimator,
        photons: args.photons,
        radius: args.radius,
        caustic_radius: args.caustic_radius,
        volume_radius: args.volume_radius,
        spp: args.spp,
        seed: args.seed,
        vcm_strategies: args.vcm_strategies,
        area_light_samples: args.area_light_samples,
        shadow_map_size: args.shadow_map_size,
        volume_slices: args.volume_slices,
        normal_test: args.normal_test,
        lod,
        alpha: args.alpha,
    }
}

/// When the passes stop, as the flags say (checkpoints and a reference
/// ask for passes).
fn render_plan(args: &RenderArgs) -> Plan {
    Plan {
        passes: args.passes,
        time: args.time.map(Duration::from_secs_f64),
        target_error: args.target_error,
        shard: args.shard,
        in_passes: args.reference.is_some() || args.checkpoint.is_some(),
    }
}

/// A fraction in (0, 1).
fn parse_fraction(text: &str) -> Result<f64, String> {
    match text.parse::<f64>() {
        Ok(v) if v > 0.0 && v < 1.0 => Ok(v),
        _ => Err(format!("{text}: must be a number between 0 and 1 (e.g. 0.02 for 2%)")),
    }
}

/// What the terminal shows while the passes run; a bad reference or
/// checkpoint is a usage error.
fn reporting(args: &RenderArgs, scene: &Scene, settings: &RenderSettings, plan: &Plan) -> Result<Reporting> {
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
    if args.checkpoint.is_some()
        && args.passes.is_none_or(|n| n == 1)
        && plan.time_or_default(settings).is_none()
        && plan.target_error_or_default(settings).is_none()
    {
        usage!("--checkpoint needs --passes (more than 1), --time or --target-error");
    }
    if plan.by_default(settings) && !args.quiet {
        eprintln!(
            "rendering passes until the estimated noise is {}% or {DEFAULT_TIME_LIMIT} s have passed (--passes 1: the seed's single pass)",
            100.0 * DEFAULT_TARGET_ERROR
        );
    }
    Ok(Reporting {
        shard: args.shard,
        checkpoint: args.checkpoint.map(Duration::from_secs_f64),
        reference,
        output: args.output.clone(),
        exposure: args.exposure,
        quiet: args.quiet,
    })
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

pub fn run(args: &RenderArgs) -> Result<()> {
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
    if !args.aov.is_empty() && ext.as_deref() != Some("exr") {
        usage!("--aov: {} must be an .exr file (the AOVs are further channels of it)", args.output.display());
    }
    if !args.aov.is_empty() && args.shard.is_some() {
        usage!("--aov: a shard's part keeps sums; render the AOVs with the merged image's settings instead");
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
    let settings = render_settings(args);
    settings.check(&scene, |name| format!("--{name}")).map_err(UsageError)?;
    if let Some(resolution) = args.resolution {
        let (w, h) = resolution.resolve(scene.camera.aspect()).map_err(UsageError)?;
        scene.camera = scene.camera.with_resolution(w, h).map_err(UsageError)?;
    }
    let progress = TerminalProgress::new(args.quiet);
    let start = Instant::now();
    let plan = render_plan(args);
    let progressive = plan.progressive(&settings);
    let reporting = if progressive { Some(reporting(args, &scene, &settings, &plan)?) } else { None };
    let session = Session::new(&scene, settings, plan, Log::stderr(), &progress)?;
    let outcome = match &reporting {
        Some(reporting) => passes::run(session, reporting)?,
        None => session.run(|_, _| Ok(()))?,
    };
    let (image, nonfinite) = (&outcome.image, outcome.nonfinite);
    if nonfinite > 0 {
        eprintln!("warning: {nonfinite} non-finite samples were dropped");
    }
    match (&outcome.sums, args.shard) {
        (Some(sums), Some(shard)) => {
            let header = PartHeader {
                renderer: outcome.renderer.clone(),
                scene: args.scene.clone(),
                scene_hash: scene_fingerprint(&args.scene)?,
                settings: image_settings(args),
                width: image.width,
                height: image.height,
                total_passes: args.passes,
                shard: shard.index,
                shards: shard.count,
                passes: outcome.passes.clone(),
                stopped_early: outcome.stopped_early,
                time_limited: args.time.is_some(),
            };
            Part { header, sums: sums.clone() }.write(&args.output).map_err(anyhow::Error::msg)?;
        }
        _ if !args.aov.is_empty() => {
            let which: Vec<Aov> = args.aov.iter().map(|&a| a.into()).collect();
            write_exr_with_aovs(&args.output, image, &render_aovs(&scene), &which)?;
        }
        _ => write_image(&args.output, image, args.exposure)?,
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

//! `hikari render`: load a scene, trace photons, render, write the image.

use crate::progress_bar::TerminalProgress;
use anyhow::{Context, Result, bail};
use clap::{Args, ValueEnum};
use hikari_core::lod::LodSettings;
use hikari_core::output::write_image;
use hikari_core::photon::{TraceSettings, trace_photons};
use hikari_core::render::{Image, path, photon_cpu};
use hikari_core::scene::{Scene, builtin};
use hikari_gpu::{GpuContext, GpuRenderer, GpuSettings};
use std::path::PathBuf;
use std::time::Instant;

#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum RendererKind {
    /// The seed's photon splatting on the GPU (falls back to photon-cpu
    /// when no GPU adapter is found, or on a software adapter for media
    /// seen through mirrors or glass).
    Gpu,
    /// The seed's fixed-radius photon mapping on the CPU.
    PhotonCpu,
    /// Path tracer (ground truth; slow to converge).
    Path,
}

#[derive(Args, Debug)]
pub struct RenderArgs {
    /// A built-in scene name (see `hikari scenes`) or a path to a .toml scene file.
    #[arg(default_value = builtin::DEFAULT)]
    pub scene: String,
    /// Output image: .png (tone-mapped sRGB) or .exr (linear float RGB).
    #[arg(short, long, default_value = "hikari.png")]
    pub output: PathBuf,
    #[arg(long, value_enum, default_value_t = RendererKind::Gpu)]
    pub renderer: RendererKind,
    /// Photon paths emitted from the lights.
    #[arg(long, default_value_t = 200_000, value_parser = clap::value_parser!(u64).range(1..))]
    pub photons: u64,
    /// Global-map radius r in scene units [default: 3% of the scene diagonal].
    #[arg(long, allow_negative_numbers = true)]
    pub radius: Option<f32>,
    /// Caustic-map radius in scene units [default: 1% of the scene diagonal].
    #[arg(long, allow_negative_numbers = true)]
    pub caustic_radius: Option<f32>,
    /// Samples per pixel [default: 4 for photon-cpu, 64 for path].
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..))]
    pub spp: Option<u32>,
    /// Override the scene's resolution, e.g. 1280x720.
    #[arg(long, value_parser = parse_resolution)]
    pub resolution: Option<(u32, u32)>,
    /// Random seed: the same seed gives the same image whatever the thread count.
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// Worker threads [default: all cores].
    #[arg(long)]
    pub threads: Option<usize>,
    /// Exposure in stops applied before PNG tone mapping.
    #[arg(long, default_value_t = 0.0, allow_negative_numbers = true)]
    pub exposure: f32,
    /// Shadow-map side in texels for each shadow view (gpu).
    #[arg(long, default_value_t = 1024, value_parser = clap::value_parser!(u32).range(16..=8192))]
    pub shadow_map_size: u32,
    /// Samples per area light: shadow rays per shaded point (photon-cpu),
    /// shadow-mapped points on the light (gpu).
    #[arg(long, default_value_t = 4, value_parser = clap::value_parser!(u32).range(1..))]
    pub area_light_samples: u32,
    /// Volume-map radius in scene units [default: 3% of the scene diagonal].
    #[arg(long, allow_negative_numbers = true)]
    pub volume_radius: Option<f32>,
    /// Optical-depth slices along each view ray through region media (gpu).
    #[arg(long, default_value_t = 8, value_parser = clap::value_parser!(u32).range(1..=64))]
    pub volume_slices: u32,
    /// Count only photons that arrived from the side the surface faces the
    /// eye (stops light leaking through thin walls; darkens inside corners).
    #[arg(long)]
    pub normal_test: bool,
    /// LOD (gpu): photons nearer the eye than this are fully detailed when
    /// lod-near < lod-far, fully culled when lod-near > lod-far (scene units).
    #[arg(long, requires = "lod_far", allow_negative_numbers = true)]
    pub lod_near: Option<f32>,
    /// LOD (gpu): the other end of the detail ramp (scene units).
    #[arg(long, requires = "lod_near", allow_negative_numbers = true)]
    pub lod_far: Option<f32>,
    /// LOD (gpu): number of photon groups A.
    #[arg(long, default_value_t = 20, value_parser = clap::value_parser!(u32).range(1..=1000))]
    pub lod_groups: u32,
    /// No progress bars.
    #[arg(short, long)]
    pub quiet: bool,
}

fn parse_resolution(s: &str) -> Result<(u32, u32), String> {
    let (w, h) = s.split_once(['x', 'X']).ok_or_else(|| format!("`{s}`: expected WIDTHxHEIGHT, e.g. 640x480"))?;
    let parse = |v: &str| v.trim().parse::<u32>().map_err(|_| format!("`{s}`: expected WIDTHxHEIGHT, e.g. 640x480"));
    let (w, h) = (parse(w)?, parse(h)?);
    if w == 0 || h == 0 || w > 16384 || h > 16384 {
        return Err(format!("`{s}`: each side must be between 1 and 16384"));
    }
    Ok((w, h))
}

/// Traces photons, then splats them on the GPU or estimates them on the CPU.
fn render_photons(
    args: &RenderArgs,
    renderer: RendererKind,
    scene: &Scene,
    progress: &TerminalProgress,
) -> Result<(Image, u64)> {
    let gpu = match renderer {
        RendererKind::Gpu => match GpuContext::new() {
            Ok(ctx) => match GpuRenderer::unsupported_on(scene, &ctx) {
                Some(reason) => {
                    eprintln!("{reason}: using photon-cpu");
                    None
                }
                None => Some(ctx),
            },
            Err(e) => {
                eprintln!("{e}: falling back to the CPU renderer (photon-cpu)");
                None
            }
        },
        _ => None,
    };
    let trace_start = Instant::now();
    let traced =
        trace_photons(scene, &TraceSettings { photons: args.photons, seed: args.seed, ..Default::default() }, progress);
    let trace_time = trace_start.elapsed().as_secs_f64();
    eprintln!(
        "photons: {} emitted, {} stored in the global map, {} in the caustic map, {} in the volume map; {:.2} M paths/s ({:.2} s)",
        traced.stats.emitted,
        traced.global.len(),
        traced.caustic.len(),
        traced.volume.len(),
        traced.stats.emitted as f64 / trace_time / 1e6,
        trace_time
    );
    let settings = photon_cpu::PhotonCpuSettings {
        radius: args.radius,
        caustic_radius: args.caustic_radius,
        spp: args.spp.unwrap_or(4),
        seed: args.seed,
        area_light_samples: args.area_light_samples,
        normal_test: args.normal_test,
        volume_radius: args.volume_radius,
        ..Default::default()
    };
    let (global, caustic) = settings.estimate_params(scene);
    eprintln!("radius {:.4}, caustic radius {:.4}", global.radius, caustic.radius);
    if let Some(ctx) = gpu {
        let adapter = ctx.describe();
        if !ctx.float32_blend {
            eprintln!("note: this adapter cannot blend 32-bit float targets; photon splats accumulate in Rgba16Float");
        }
        let lod = match (args.lod_near, args.lod_far) {
            (Some(near), Some(far)) => Some(LodSettings { near, far, groups: args.lod_groups }),
            _ => None,
        };
        let gpu_settings = GpuSettings {
            area_light_samples: args.area_light_samples,
            shadow_map_size: args.shadow_map_size,
            lod,
            volume_radius: args.volume_radius.unwrap_or_else(|| photon_cpu::default_radius(scene)),
            volume_slices: args.volume_slices,
            ..GpuSettings::new(global, caustic)
        };
        let setup_start = Instant::now();
        let renderer = GpuRenderer::new(ctx, scene, &traced, gpu_settings);
        let setup = setup_start.elapsed().as_secs_f64();
        let frame_start = Instant::now();
        renderer.render();
        let result = renderer.read_image()?;
        eprintln!(
            "gpu: {adapter}; setup {setup:.2} s, frame and readback {:.3} s (1 sample per pixel)",
            frame_start.elapsed().as_secs_f64()
        );
        return Ok(result);
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

fn positive(name: &str, v: Option<f32>) -> Result<()> {
    match v {
        Some(r) if !(r.is_finite() && r > 0.0) => {
            bail!("--{name} {r}: must be a positive, finite length")
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
                bail!("--{name} {d}: must be a finite distance ≥ 0");
            }
        }
    }
    if !args.exposure.is_finite() {
        bail!("--exposure {}: must be finite", args.exposure);
    }
    let ext = args.output.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase);
    if !matches!(ext.as_deref(), Some("png" | "exr")) {
        bail!("{}: unsupported image type (use .png or .exr)", args.output.display());
    }
    if let Some(threads) = args.threads {
        rayon::ThreadPoolBuilder::new().num_threads(threads).build_global().context("setting the thread count")?;
    }

    let mut scene = Scene::load(&args.scene)?;
    let renderer = args.renderer;
    if let Some((w, h)) = args.resolution {
        scene.camera = scene.camera.with_resolution(w, h).map_err(anyhow::Error::msg)?;
    }
    let progress = TerminalProgress::new(args.quiet);
    let start = Instant::now();
    let (image, nonfinite) = match renderer {
        RendererKind::Path => {
            let settings = path::PathSettings { spp: args.spp.unwrap_or(64), seed: args.seed, ..Default::default() };
            let result = path::render(&scene, &settings, &progress);
            eprintln!("path tracing: {} spp", settings.spp);
            result
        }
        RendererKind::Gpu | RendererKind::PhotonCpu => render_photons(args, renderer, &scene, &progress)?,
    };
    if nonfinite > 0 {
        eprintln!("warning: {nonfinite} non-finite samples were dropped");
    }
    write_image(&args.output, &image, args.exposure)?;
    eprintln!(
        "wrote {} ({}x{}) in {:.2} s total",
        args.output.display(),
        image.width,
        image.height,
        start.elapsed().as_secs_f64()
    );
    Ok(())
}

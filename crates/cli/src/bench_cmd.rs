//! `hikari bench`: the seed's chapter-6 table for surfaces, on this machine's
//! GPU: frames per second and a per-pass breakdown (wall-clock around each
//! pass's submit). Photon tracing is not timed.

use anyhow::{Context, Result, bail};
use clap::Args;
use hikari_core::lod::LodSettings;
use hikari_core::photon::{TraceSettings, trace_photons};
use hikari_core::progress::Silent;
use hikari_core::render::photon_cpu::PhotonCpuSettings;
use hikari_core::scene::Scene;
use hikari_gpu::renderer::{SEED_CORNELL_LOD, Stage};
use hikari_gpu::{GpuContext, GpuRenderer, GpuSettings};
use std::time::Instant;

#[derive(Args, Debug)]
pub struct BenchArgs {
    /// Frames timed per row (after one warm-up frame).
    #[arg(long, default_value_t = 20, value_parser = clap::value_parser!(u32).range(1..))]
    pub frames: u32,
    /// Also run 1920×1080 with 1,000,000 photons (meant for real GPUs).
    #[arg(long)]
    pub large: bool,
}

struct Row {
    label: &'static str,
    scene: &'static str,
    size: (u32, u32),
    photons: u64,
    lod: Option<LodSettings>,
}

pub fn run(args: &BenchArgs) -> Result<()> {
    let ctx = GpuContext::new().context("hikari bench measures the GPU renderer")?;
    println!("adapter: {}", ctx.describe());
    if !ctx.float32_blend {
        println!("note: no 32-bit float blending on this adapter; radiance targets are Rgba16Float");
    }
    let mut rows = vec![
        Row {
            label: "cornell-box, 10,000 photons, LOD off",
            scene: "cornell-box",
            size: (512, 512),
            photons: 10_000,
            lod: None,
        },
        Row {
            label: "cornell-box, 10,000 photons, LOD n=20 f=7 (scaled)",
            scene: "cornell-box",
            size: (512, 512),
            photons: 10_000,
            lod: Some(SEED_CORNELL_LOD),
        },
        Row {
            label: "cornell-box, 2,000 photons, LOD off",
            scene: "cornell-box",
            size: (512, 512),
            photons: 2_000,
            lod: None,
        },
    ];
    if args.large {
        rows.push(Row {
            label: "cornell-box 1920x1080, 1,000,000 photons, LOD off",
            scene: "cornell-box",
            size: (1920, 1080),
            photons: 1_000_000,
            lod: None,
        });
    }
    let mut ctx = Some(ctx);
    for row in rows {
        let Some(context) = ctx.take() else { bail!("GPU context lost") };
        let (renderer, drawn) = bench_row(context, &row, args.frames)?;
        ctx = Some(renderer.ctx);
        let _ = drawn;
    }
    Ok(())
}

fn bench_row(ctx: GpuContext, row: &Row, frames: u32) -> Result<(GpuRenderer, u32)> {
    let mut scene = Scene::load(row.scene)?;
    scene.camera = scene.camera.with_resolution(row.size.0, row.size.1).map_err(anyhow::Error::msg)?;
    let traced = trace_photons(&scene, &TraceSettings { photons: row.photons, seed: 1, ..Default::default() }, &Silent);
    let (global, caustic) = PhotonCpuSettings::default().estimate_params(&scene);
    let settings = GpuSettings { lod: row.lod, ..GpuSettings::new(global, caustic) };
    let renderer = GpuRenderer::new(ctx, &scene, &traced, settings);
    renderer.render();
    renderer.wait()?;
    let start = Instant::now();
    for _ in 0..frames {
        renderer.render();
    }
    renderer.wait()?;
    let frame = start.elapsed().as_secs_f64() / frames as f64;
    let (drawn, _) = renderer.drawn_photons()?;
    let (breakdown, timestamps) = renderer.render_timed()?;
    println!(
        "{} at {}x{}: {:.2} fps ({:.2} ms/frame), {} global photons drawn",
        row.label,
        row.size.0,
        row.size.1,
        1.0 / frame,
        frame * 1e3,
        drawn
    );
    let parts: Vec<String> =
        breakdown.iter().map(|(stage, t): &(Stage, f64)| format!("{} {:.2} ms", stage.name(), t * 1e3)).collect();
    let how = if timestamps { "GPU timestamps" } else { "wall-clock, separate submits" };
    println!("    per pass ({how}): {}", parts.join(", "));
    Ok((renderer, drawn))
}

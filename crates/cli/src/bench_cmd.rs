//! `hikari bench`: the seed's chapter-6 tables for surfaces and media, on
//! this machine's GPU: frames per second and a per-pass breakdown (GPU
//! timestamps where the adapter has them). Photon tracing is not timed in
//! the static rows; the dynamic rows (what the viewer does) time a camera
//! that moves every frame, photons re-traced on the CPU every frame, and a
//! light that moves every frame (the scene posed, its BVH rebuilt, its
//! photons re-traced and uploaded with the moved scene), photons re-traced
//! by the GPU tracer every frame; and the tracing rates of both tracers.

use anyhow::{Context, Result};
use clap::Args;
use hikari_core::lod::LodSettings;
use hikari_core::photon::{TraceSettings, trace_photons};
use hikari_core::progress::Silent;
use hikari_core::render::photon_cpu::PhotonCpuSettings;
use hikari_core::scene::Scene;
use hikari_gpu::features::SceneFeatures;
use hikari_gpu::renderer::{SEED_CORNELL_LOD, Stage};
use hikari_gpu::tiled::Estimator;
use hikari_gpu::trace::GpuTracer;
use hikari_gpu::{GpuContext, GpuRenderer, GpuSettings};
use std::time::Instant;

#[derive(Args, Debug)]
pub struct BenchArgs {
    /// Frames timed per row (after one warm-up frame), at most.
    #[arg(long, default_value_t = 20, value_parser = clap::value_parser!(u32).range(1..))]
    pub frames: u32,
    /// Seconds a row's timed frames may take: a row stops after its frames
    /// or once past this, after 3 frames at least (fewer only where
    /// --frames asks for fewer), so the table finishes in minutes even on a
    /// software rasterizer. 0: no limit.
    #[arg(long, default_value_t = 4.0)]
    pub budget: f64,
    /// Only the rows whose label contains this text (the tracing rates are
    /// always printed unless --no-tracing).
    #[arg(long)]
    pub only: Option<String>,
    /// Leave out the photon-tracing rates.
    #[arg(long)]
    pub no_tracing: bool,
    /// Pipelines made as if every scene also used these features
    /// (comma-separated: textured, cut-outs, glossy, coated, sheened,
    /// sampled-lights, sky-image, media, bent, mixed, layered, or all): what each costs a scene without it.
    #[arg(long, value_delimiter = ',', value_parser = parse_feature)]
    pub with_features: Vec<SceneFeatures>,
    /// Also run 1920×1080 with 1,000,000 photons (meant for real GPUs).
    #[arg(long)]
    pub large: bool,
    /// Only the photon-tracing rates (CPU and GPU tracers).
    #[arg(long)]
    pub tracing_only: bool,
}

/// One `--with-features` name as the features it turns on.
fn parse_feature(name: &str) -> Result<SceneFeatures, String> {
    let none = SceneFeatures::NONE;
    Ok(match name {
        "textured" => SceneFeatures { textured: true, ..none },
        "cut-outs" => SceneFeatures { cut_outs: true, ..none },
        "glossy" => SceneFeatures { glossy: true, ..none },
        "coated" => SceneFeatures { glossy: true, coated: true, ..none },
        "sheened" => SceneFeatures { glossy: true, sheened: true, ..none },
        "sampled-lights" => SceneFeatures { sampled_lights: true, ..none },
        "sky-image" => SceneFeatures { sky_image: true, ..none },
        "media" => SceneFeatures { media: true, ..none },
        "bent" => SceneFeatures { bent: true, ..none },
        "mixed" => SceneFeatures { glossy: true, mixed: true, ..none },
        "layered" => SceneFeatures { textured: true, glossy: true, layered: true, ..none },
        "all" => SceneFeatures::ALL,
        _ => {
            return Err(format!(
                "{name:?} is none of textured, cut-outs, glossy, coated, sheened, sampled-lights, sky-image, media, bent, mixed, layered, all"
            ));
        }
    })
}

struct Row {
    label: &'static str,
    scene: &'static str,
    size: (u32, u32),
    /// Emitted photons, or (media rows) the volume photons wanted: the
    /// emitted count is then chosen to store about that many.
    photons: u64,
    volume: bool,
    lod: Option<LodSettings>,
    motion: Motion,
    estimator: Estimator,
}

/// What changes between the timed frames.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Motion {
    Still,
    /// The camera turns a little around its target every frame.
    Orbit,
    /// A new photon set is traced (all cores) and uploaded every frame.
    Retrace,
    /// A new photon set is traced by the GPU tracer, read back and uploaded
    /// every frame.
    RetraceOnGpu,
    /// The first light orbits (`orbiting_light`), 1/60 s further every
    /// frame: pose, trace, `set_scene`, render.
    MovingLight,
}

/// `scene` with its first light orbiting a vertical axis 15% of the scene's
/// diagonal away, once every 5 s.
fn orbiting_light(mut scene: Scene) -> Scene {
    use hikari_core::scene::{Animation, Motion as Move, Target};
    let center = scene.lights[0].anchor() + glam::Vec3::X * 0.15 * scene.diagonal();
    let motion = Move::Rotate { center, axis: glam::Vec3::Y, period: 5.0 };
    scene.animations.push(Animation { target: Target::Light(0), motion });
    scene
}

/// A dynamic row: `scene` at `size` with `photons` re-traced every frame as its light moves.
fn moving_light_row(label: &'static str, scene: &'static str, size: (u32, u32), photons: u64) -> Row {
    Row {
        label,
        scene,
        size,
        photons,
        volume: false,
        lod: None,
        motion: Motion::MovingLight,
        estimator: Estimator::Raster,
    }
}

/// The example glTF file (textures, glossy metal, glass, a sun, a spot, a
/// glowing strip), from the source tree the binary was built in.
const SHOWCASE: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../../scenes/showcase.glb");

/// A generated glTF file of 1,000,000 triangles (`test_scenes::wavy_grid_glb`).
const GRID: &str = "generated 1M-triangle grid";

/// A row's scene: a built-in name or path, or the generated grid, written
/// to a temporary file, loaded and removed.
fn load_scene(name: &str) -> Result<Scene> {
    if name != GRID {
        return Ok(Scene::load(name)?);
    }
    let path = std::env::temp_dir().join(format!("hikari-bench-grid-{}.glb", std::process::id()));
    std::fs::write(&path, hikari_core::test_scenes::wavy_grid_glb(1_000_000))
        .with_context(|| format!("writing {}", path.display()))?;
    let scene = Scene::load(&path.to_string_lossy());
    let _ = std::fs::remove_file(&path);
    Ok(scene?)
}

/// The seed's fog-scene LOD settings, in scene units as given (its scene's
/// size is not stated; fog-stage is 8 units wide).
const SEED_FOG_LOD: LodSettings = LodSettings { near: 25.0, far: 3.0, groups: 20 };
const SEED_FOG_LOD_FAR: LodSettings = LodSettings { near: 0.0, far: 20.0, groups: 20 };

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
            volume: false,
            lod: None,
            motion: Motion::Still,
            estimator: Estimator::Raster,
        },
        Row {
            label: "cornell-box, 10,000 photons, LOD n=20 f=7 (scaled)",
            scene: "cornell-box",
            size: (512, 512),
            photons: 10_000,
            volume: false,
            lod: Some(SEED_CORNELL_LOD),
            motion: Motion::Still,
            estimator: Estimator::Raster,
        },
        Row {
            label: "cornell-box, 10,000 photons, LOD off, tiled estimator",
            scene: "cornell-box",
            size: (512, 512),
            photons: 10_000,
            volume: false,
            lod: None,
            motion: Motion::Still,
            estimator: Estimator::Tiled,
        },
        Row {
            label: "cornell-caustic, 200,000 photons, LOD off",
            scene: "cornell-caustic",
            size: (512, 512),
            photons: 200_000,
            volume: false,
            lod: None,
            motion: Motion::Still,
            estimator: Estimator::Raster,
        },
        Row {
            label: "cornell-caustic, 200,000 photons, LOD off, tiled estimator",
            scene: "cornell-caustic",
            size: (512, 512),
            photons: 200_000,
            volume: false,
            lod: None,
            motion: Motion::Still,
            estimator: Estimator::Tiled,
        },
        Row {
            label: "cornell-box, 2,000 photons, LOD off",
            scene: "cornell-box",
            size: (512, 512),
            photons: 2_000,
            volume: false,
            lod: None,
            motion: Motion::Still,
            estimator: Estimator::Raster,
        },
        Row {
            label: "fog-stage, 50,000 volume photons, LOD off",
            scene: "fog-stage",
            size: (512, 512),
            photons: 50_000,
            volume: true,
            lod: None,
            motion: Motion::Still,
            estimator: Estimator::Raster,
        },
        Row {
            label: "fog-stage, 50,000 volume photons, LOD n=25 f=3",
            scene: "fog-stage",
            size: (512, 512),
            photons: 50_000,
            volume: true,
            lod: Some(SEED_FOG_LOD),
            motion: Motion::Still,
            estimator: Estimator::Raster,
        },
        Row {
            label: "fog-stage, 25,000 volume photons, LOD n=0 f=20",
            scene: "fog-stage",
            size: (512, 512),
            photons: 25_000,
            volume: true,
            lod: Some(SEED_FOG_LOD_FAR),
            motion: Motion::Still,
            estimator: Estimator::Raster,
        },
        Row {
            label: "cornell-box, 10,000 photons, camera moving every frame",
            scene: "cornell-box",
            size: (512, 512),
            photons: 10_000,
            volume: false,
            lod: None,
            motion: Motion::Orbit,
            estimator: Estimator::Raster,
        },
        Row {
            label: "cornell-box, 10,000 photons re-traced every frame",
            scene: "cornell-box",
            size: (512, 512),
            photons: 10_000,
            volume: false,
            lod: None,
            motion: Motion::Retrace,
            estimator: Estimator::Raster,
        },
        Row {
            label: "cornell-box, 100,000 photons re-traced on the GPU every frame",
            scene: "cornell-box",
            size: (512, 512),
            photons: 100_000,
            volume: false,
            lod: None,
            motion: Motion::RetraceOnGpu,
            estimator: Estimator::Raster,
        },
        Row {
            label: "showcase.glb, 50,000 photons",
            scene: SHOWCASE,
            size: (512, 512),
            photons: 50_000,
            volume: false,
            lod: None,
            motion: Motion::Still,
            estimator: Estimator::Raster,
        },
        Row {
            label: "showcase.glb, 50,000 photons, camera moving every frame",
            scene: SHOWCASE,
            size: (512, 512),
            photons: 50_000,
            volume: false,
            lod: None,
            motion: Motion::Orbit,
            estimator: Estimator::Raster,
        },
        Row {
            label: "1M-triangle glTF grid, 20,000 photons",
            scene: GRID,
            size: (512, 512),
            photons: 20_000,
            volume: false,
            lod: None,
            motion: Motion::Still,
            estimator: Estimator::Raster,
        },
        moving_light_row(
            "cornell-box, moving light, 20,000 photons re-traced every frame",
            "cornell-box",
            (512, 512),
            20_000,
        ),
        moving_light_row(
            "cornell-box, moving light, 50,000 photons re-traced every frame",
            "cornell-box",
            (512, 512),
            50_000,
        ),
        moving_light_row(
            "cornell-box, moving light, 100,000 photons re-traced every frame",
            "cornell-box",
            (512, 512),
            100_000,
        ),
    ];
    if args.large {
        rows.push(Row {
            label: "cornell-box 1920x1080, 1,000,000 photons, LOD off, tiled estimator",
            scene: "cornell-box",
            size: (1920, 1080),
            photons: 1_000_000,
            volume: false,
            lod: None,
            motion: Motion::Still,
            estimator: Estimator::Tiled,
        });
        for estimator in [Estimator::Raster, Estimator::Tiled] {
            rows.push(Row {
                label: if estimator == Estimator::Tiled {
                    "cornell-box 1920x1080, 1,000,000 photons re-traced on the GPU every frame, tiled estimator"
                } else {
                    "cornell-box 1920x1080, 1,000,000 photons re-traced on the GPU every frame (raster)"
                },
                scene: "cornell-box",
                size: (1920, 1080),
                photons: 1_000_000,
                volume: false,
                lod: None,
                motion: Motion::RetraceOnGpu,
                estimator,
            });
        }
        rows.push(Row {
            label: "cornell-box 1920x1080, 1,000,000 photons, LOD off",
            scene: "cornell-box",
            size: (1920, 1080),
            photons: 1_000_000,
            volume: false,
            lod: None,
            motion: Motion::Still,
            estimator: Estimator::Raster,
        });
        rows.push(Row {
            label: "fog-stage 1920x1080, 1,000,000 volume photons, LOD off",
            scene: "fog-stage",
            size: (1920, 1080),
            photons: 1_000_000,
            volume: true,
            lod: None,
            motion: Motion::Still,
            estimator: Estimator::Raster,
        });
        for scene in ["cornell-box", "cornell-caustic"] {
            rows.push(moving_light_row(
                if scene == "cornell-box" {
                    "cornell-box 1920x1080, moving light, 100,000 photons re-traced every frame"
                } else {
                    "cornell-caustic 1920x1080, moving light, 100,000 photons re-traced every frame"
                },
                scene,
                (1920, 1080),
                100_000,
            ));
        }
    }
    // A row the adapter cannot run (media without f32 blending, a size over
    // its limits) is reported and the table goes on.
    let wanted = |row: &&Row| args.only.as_deref().is_none_or(|text| row.label.contains(text));
    for row in rows.iter().filter(|_| !args.tracing_only).filter(wanted) {
        if let Err(e) = bench_row(ctx.clone(), row, args) {
            println!("{}: not run on this adapter: {e:#}", row.label);
        }
    }
    if args.no_tracing {
        return Ok(());
    }
    println!("photon tracing, million photon paths per second (best of 3):");
    let sizes: &[u64] = if args.large { &[200_000, 1_000_000, 4_000_000] } else { &[200_000] };
    for name in ["cornell-box", "cornell-caustic", "fog-stage"] {
        for &photons in sizes {
            if let Err(e) = bench_tracing(&ctx, name, photons, &args.with_features) {
                println!("{name}, {photons} paths: not run on this adapter: {e:#}");
            }
        }
    }
    Ok(())
}

/// The CPU tracer (all cores) against the GPU tracer, with and without
/// reading the maps back.
fn bench_tracing(ctx: &GpuContext, name: &str, photons: u64, with: &[SceneFeatures]) -> Result<()> {
    let scene = Scene::load(name)?;
    let settings = TraceSettings { photons, seed: 1, ..Default::default() };
    let best = |f: &mut dyn FnMut() -> Result<()>| -> Result<f64> {
        let mut best = f64::INFINITY;
        for _ in 0..3 {
            let start = Instant::now();
            f()?;
            best = best.min(start.elapsed().as_secs_f64());
        }
        Ok(photons as f64 / best / 1e6)
    };
    let cpu = best(&mut || {
        trace_photons(&scene, &settings, &Silent);
        Ok(())
    })?;
    let mut tracer = GpuTracer::with_features(ctx, &scene, features_for(&scene, with))?;
    // Warm-up: pipelines compiled, batch buffers sized.
    tracer.trace(ctx, &settings)?;
    let on_gpu = best(&mut || {
        tracer.trace_on_gpu(ctx, &settings)?;
        Ok(())
    })?;
    let with_readback = best(&mut || {
        tracer.trace(ctx, &settings)?;
        Ok(())
    })?;
    println!(
        "    {name}, {photons} paths: CPU {cpu:.2}, GPU {on_gpu:.2} (maps left on the GPU), GPU {with_readback:.2} (maps read back)"
    );
    Ok(())
}

/// What the pipelines for `scene` are specialised to: its own features and `with`.
fn features_for(scene: &Scene, with: &[SceneFeatures]) -> SceneFeatures {
    with.iter().fold(SceneFeatures::of_scene(scene), |all, more| all.union(*more))
}

/// Times `row`: up to `--frames` frames, stopping once `--budget` seconds
/// have passed after at least 3 (or `--frames`, if fewer).
fn bench_row(ctx: GpuContext, row: &Row, args: &BenchArgs) -> Result<(GpuRenderer, u32)> {
    let (frames, budget) = (args.frames, args.budget);
    let mut scene = load_scene(row.scene)?;
    scene.camera = scene.camera.with_resolution(row.size.0, row.size.1).map_err(anyhow::Error::msg)?;
    let base = orbiting_light(scene.clone());
    let trace = |photons| trace_photons(&scene, &TraceSettings { photons, seed: 1, ..Default::default() }, &Silent);
    let traced = if row.volume {
        // Volume photons per emitted path, from a small trial.
        let trial = trace(10_000);
        let per_path = (trial.volume.len() as f64 / 10_000.0).max(1e-3);
        trace((row.photons as f64 / per_path).round().max(1.0) as u64)
    } else {
        trace(row.photons)
    };
    let (global, caustic) = PhotonCpuSettings::default().estimate_params(&scene);
    let settings = GpuSettings {
        estimator: row.estimator,
        lod: row.lod,
        volume_radius: hikari_core::render::photon_cpu::default_radius(&scene),
        ..GpuSettings::new(global, caustic)
    };
    let features = features_for(&scene, &args.with_features);
    let mut renderer = GpuRenderer::with_features(ctx, &scene, &traced, settings, features)?;
    renderer.render()?;
    let mut tracing = 0.0;
    // The GPU tracer is made and run once before the timed frames, as the
    // viewer makes it once: a software adapter compiles a pipeline at its
    // first use (seconds for the tracer, then kept in Mesa's disk cache).
    let mut gpu_tracer = None;
    if row.motion == Motion::RetraceOnGpu {
        let start = Instant::now();
        let mut tracer = GpuTracer::with_features(&renderer.ctx, &scene, features)?;
        // Its warm-up trace: a software adapter compiles on first use.
        tracer.trace(&renderer.ctx, &TraceSettings { photons: row.photons, seed: 1, ..Default::default() })?;
        gpu_tracer = Some(tracer);
        println!(
            "    (GPU tracer made and warmed up in {:.0} ms, before the timed frames)",
            start.elapsed().as_secs_f64() * 1e3
        );
    }
    let mut global_count = traced.indirect().len();
    let start = Instant::now();
    let mut timed = 0;
    for k in 0..frames {
        if k >= 3 && budget > 0.0 && start.elapsed().as_secs_f64() > budget {
            break;
        }
        timed += 1;
        match row.motion {
            Motion::Still => {}
            Motion::Orbit => {
                let c = &scene.camera;
                let turn = glam::Quat::from_axis_angle(c.up.normalize(), 0.01 * (k + 1) as f32);
                let position = c.look_at + turn * (c.position - c.look_at);
                let moved = hikari_core::camera::Camera::new(position, c.look_at, c.up, c.fov_y, c.width, c.height)
                    .map_err(anyhow::Error::msg)?;
                renderer.set_camera(&moved)?;
            }
            Motion::Retrace => {
                let trace_start = Instant::now();
                let settings = TraceSettings { photons: row.photons, seed: 2 + k as u64, ..Default::default() };
                let fresh = trace_photons(&scene, &settings, &Silent);
                tracing += trace_start.elapsed().as_secs_f64();
                renderer.set_photons(&scene, &fresh)?;
                global_count = fresh.indirect().len();
            }
            Motion::RetraceOnGpu => {
                let trace_start = Instant::now();
                let settings = TraceSettings { photons: row.photons, seed: 2 + k as u64, ..Default::default() };
                let tracer = gpu_tracer.as_mut().context("the GPU tracer is made before the frames")?;
                let fresh = tracer.trace(&renderer.ctx, &settings)?.0;
                tracing += trace_start.elapsed().as_secs_f64();
                renderer.set_photons(&scene, &fresh)?;
                global_count = fresh.indirect().len();
            }
            Motion::MovingLight => {
                let trace_start = Instant::now();
                let posed = base.at_time((k + 1) as f32 / 60.0);
                let settings = TraceSettings { photons: row.photons, seed: 2 + k as u64, ..Default::default() };
                let fresh = trace_photons(&posed, &settings, &Silent);
                tracing += trace_start.elapsed().as_secs_f64();
                renderer.set_scene(&posed, &fresh)?;
                global_count = fresh.indirect().len();
            }
        }
        renderer.render()?;
    }
    renderer.wait()?;
    let frames = timed;
    let frame = start.elapsed().as_secs_f64() / frames as f64;

    let (global_drawn, _) = renderer.drawn_photons()?;
    let (drawn, what) = if row.volume {
        (renderer.drawn_volume_photons()?, format!("of {} volume photons drawn", traced.volume.len()))
    } else {
        (global_drawn, format!("of {global_count} global photons drawn"))
    };
    let (breakdown, timestamps) = renderer.render_timed()?;
    println!(
        "{} at {}x{}: {:.2} fps ({:.2} ms/frame), {drawn} {what}",
        row.label,
        row.size.0,
        row.size.1,
        1.0 / frame,
        frame * 1e3,
    );
    let parts: Vec<String> =
        breakdown.iter().map(|(stage, t): &(Stage, f64)| format!("{} {:.2} ms", stage.name(), t * 1e3)).collect();
    let how = if timestamps { "GPU timestamps" } else { "wall-clock, separate submits" };
    println!("    per pass ({how}): {}", parts.join(", "));
    let per_frame = tracing / frames as f64 * 1e3;
    match row.motion {
        Motion::Retrace => println!("    tracing {per_frame:.2} ms of each frame (CPU, all cores)"),
        Motion::MovingLight => println!("    posing and tracing {per_frame:.2} ms of each frame (CPU, all cores)"),
        Motion::RetraceOnGpu => println!("    tracing and reading back {per_frame:.2} ms of each frame (GPU tracer)"),
        _ => {}
    }
    Ok((renderer, drawn))
}

//! The structured scene fuzzer (`hikari_core::fuzz`) through the GPU
//! renderer: mutants of the built-in scenes render finite at 8×8, or the
//! renderer refuses them with a reason the CLI turns into the photon-cpu
//! fallback (a limit or the loop budget). A panic, a wgpu error or a
//! non-finite pixel is a failure.

use hikari_core::fuzz::{self, Outcome, Renderer, check_text, mutate};
use hikari_core::photon::{TraceSettings, trace_photons};
use hikari_core::progress::Silent;
use hikari_core::render::photon_cpu::PhotonCpuSettings;
use hikari_core::sampling::Rng;
use hikari_core::scene::{Scene, builtin};
use hikari_gpu::test_support::test_context;
use hikari_gpu::{GpuContext, GpuError, GpuRenderer, GpuSettings};
use std::cell::Cell;
use std::time::{Duration, Instant};

const SLOW: Duration = Duration::from_secs(60);

/// The GPU renderer as the fuzzer calls it: 300 photons, one frame. A
/// refusal the CLI falls back on counts in `refused` (and draws black);
/// any other GPU error panics, which `check_text` reports.
fn gpu_renderer<'a>(ctx: &'a GpuContext, refused: &'a Cell<u64>) -> Renderer<'a> {
    Renderer {
        name: "gpu",
        render: Box::new(move |scene: &Scene| {
            let traced = trace_photons(scene, &TraceSettings { photons: 300, seed: 1, max_bounces: 16 }, &Silent);
            let (global, caustic) = PhotonCpuSettings::default().estimate_params(scene);
            let settings = GpuSettings {
                area_light_samples: 1,
                shadow_map_size: 64,
                volume_radius: global.radius,
                ..GpuSettings::new(global, caustic)
            };
            let frame = GpuRenderer::new(ctx.clone(), scene, &traced, settings).and_then(|gpu| {
                gpu.render()?;
                gpu.read_image()
            });
            match frame {
                Ok(image) => image,
                Err(GpuError::TooLarge(_) | GpuError::LoopBudget(_) | GpuError::SceneUnsupported(_)) => {
                    refused.set(refused.get() + 1);
                    (hikari_core::render::Image::new(fuzz::SIZE, fuzz::SIZE), 0)
                }
                Err(e) => panic!("GPU error: {e}"),
            }
        }),
    }
}

/// Mutants from `seed` until `cases` are done or `budget` is spent: the
/// counts (done, rendered, rejected by the loader, refused by the GPU) and
/// the failures.
fn run(seed: u64, cases: u64, budget: Duration) -> ((u64, u64, u64, u64), Vec<String>) {
    fuzz::quiet_panics();
    let ctx = test_context("gpu fuzz");
    let refused = Cell::new(0);
    let renderers = [gpu_renderer(&ctx, &refused)];
    let start = Instant::now();
    let (mut done, mut rendered, mut rejected) = (0, 0, 0);
    let mut failures = Vec::new();
    while done < cases && start.elapsed() < budget {
        let name = builtin::NAMES[(done % builtin::NAMES.len() as u64) as usize];
        let text = mutate(builtin::source(name).unwrap(), &mut Rng::for_item(seed, done));
        match check_text(&text, &format!("builtin:{name}"), None, &renderers, SLOW) {
            Ok(Outcome::Rendered) => rendered += 1,
            Ok(Outcome::Rejected(_)) => rejected += 1,
            Err(why) => failures.push(format!("seed {seed} case {done} ({name}): {why}\n{text}")),
        }
        done += 1;
    }
    ((done, rendered, rejected, refused.get()), failures)
}

#[test]
fn mutants_render_finite_on_the_gpu_or_are_refused_with_a_reason() {
    let ((done, rendered, rejected, refused), failures) = run(7, 24, Duration::from_secs(120));
    eprintln!("gpu fuzz: {done} mutants, {rendered} rendered ({refused} refused by the GPU), {rejected} rejected");
    assert!(failures.is_empty(), "{}", failures.join("\n\n"));
    assert!(rendered >= done / 10, "{rendered} of {done} mutants rendered");
}

/// A longer run for local use: HIKARI_FUZZ_SEED, HIKARI_FUZZ_SECONDS.
#[test]
#[ignore = "long: run by hand"]
fn gpu_fuzz_for_a_while() {
    let var = |name: &str, default: u64| std::env::var(name).ok().and_then(|v| v.parse().ok()).unwrap_or(default);
    let seed = var("HIKARI_FUZZ_SEED", 0);
    let start = Instant::now();
    let ((done, rendered, rejected, refused), failures) =
        run(seed, u64::MAX, Duration::from_secs(var("HIKARI_FUZZ_SECONDS", 600)));
    println!(
        "gpu fuzz: seed {seed}: {done} mutants in {:.0} s, {rendered} rendered ({refused} refused by the GPU), {rejected} rejected, {} failed",
        start.elapsed().as_secs_f64(),
        failures.len()
    );
    assert!(failures.is_empty(), "{}", failures.join("\n\n"));
}

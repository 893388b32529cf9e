//! A render: the renderer chosen once for a scene and settings (the GPU
//! with its fallback to photon-cpu and the one-line reason), then passes
//! pulled one at a time until the plan, a time, a noise target or an
//! interrupt stops them. Every front end drives this: the CLI's bar and
//! checkpoints, Python's iterator of passes.

use crate::log::Log;
use crate::passes::PassRenderer;
use crate::renderers::{CpuPasses, GpuPasses, OnePass, PathPasses, VcmPasses};
use crate::settings::{PATH_PASS_SPP, PATH_SPP, Plan, RenderSettings, RendererKind};
use crate::tracer::PhotonTracer;
use anyhow::Result;
use hikari_core::photon::{TraceSettings, TracedPhotons, trace_photons};
use hikari_core::progress::{Progress, Silent};
use hikari_core::progressive::shard::Shard;
use hikari_core::progressive::{ImageMean, Schedules, pass_trace_settings};
use hikari_core::render::{Image, path, photon_cpu, vcm};
use hikari_core::scene::Scene;
use hikari_gpu::tiled::Estimator;
use hikari_gpu::{GpuContext, GpuError, GpuRenderer, GpuSettings};
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Instant;

/// Why the passes stopped.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum StopReason {
    PassCount,
    TargetError,
    TimeLimit,
    Interrupt,
}

impl StopReason {
    /// As the CLI says it ("stopped by …").
    pub fn describe(self) -> &'static str {
        match self {
            StopReason::PassCount => "the pass count",
            StopReason::TargetError => "the target error",
            StopReason::TimeLimit => "the time limit",
            StopReason::Interrupt => "Ctrl-C",
        }
    }
}

/// One pass done.
#[derive(Clone, Debug, PartialEq)]
pub struct PassReport {
    /// The pass's number (1, 2, …; a shard's own numbers).
    pub pass: u32,
    /// Passes rendered so far, this one included.
    pub count: u32,
    /// The mean's estimated relative error, once it can be estimated.
    pub noise: Option<f64>,
    /// Seconds since the first pass began.
    pub seconds: f64,
    /// The global radius of the next pass, where the renderer has one.
    pub next_radius: Option<f32>,
    /// Whether this was the last pass (the session has stopped).
    pub last: Option<StopReason>,
}

/// A render under way.
pub struct Session<'a> {
    scene: &'a Scene,
    settings: RenderSettings,
    plan: Plan,
    log: Log,
    progress: &'a dyn Progress,
    renderer: Box<dyn PassRenderer + 'a>,
    name: String,
    /// Whether a failure of this renderer falls back to photon-cpu.
    on_gpu: bool,
    next: Option<u32>,
    rendered: Vec<u32>,
    start: Option<Instant>,
    stopped: Option<StopReason>,
    interrupt: Option<Arc<AtomicBool>>,
}

impl<'a> Session<'a> {
    /// Chooses the renderer for `scene` (posed at its time, at its
    /// camera's resolution) once: notes go to `log`, progress within a
    /// pass (the single pass's tracing and rendering) to `progress`.
    pub fn new(
        scene: &'a Scene,
        settings: RenderSettings,
        plan: Plan,
        log: Log,
        progress: &'a dyn Progress,
    ) -> Result<Self> {
        let none = OnePass::new(|| Err(anyhow::anyhow!("no renderer chosen")));
        let mut session = Self::with_renderer(scene, settings, plan, log, progress, Box::new(none), "");
        session.choose()?;
        Ok(session)
    }

    /// A session of `renderer`'s passes, named `name` (a front end's own
    /// renderer, or a test's), stopped as `plan` and `settings` say.
    pub fn with_renderer(
        scene: &'a Scene,
        settings: RenderSettings,
        plan: Plan,
        log: Log,
        progress: &'a dyn Progress,
        renderer: Box<dyn PassRenderer + 'a>,
        name: &str,
    ) -> Self {
        let next = plan.shard.unwrap_or(Shard::WHOLE).passes(plan.pass_count(&settings)).next();
        Session {
            scene,
            settings,
            plan,
            log,
            progress,
            renderer,
            name: name.to_string(),
            on_gpu: false,
            next,
            rendered: Vec::new(),
            start: None,
            stopped: None,
            interrupt: None,
        }
    }

    /// Passes stop after the one under way once `flag` is set (Ctrl-C).
    pub fn interrupt_on(mut self, flag: Arc<AtomicBool>) -> Self {
        self.interrupt = Some(flag);
        self
    }

    /// The renderer that runs (after any fallback), with how: "gpu
    /// (Raster estimator, photons traced on the cpu)", "photon-cpu", ….
    pub fn renderer_name(&self) -> &str {
        &self.name
    }

    pub fn settings(&self) -> &RenderSettings {
        &self.settings
    }

    /// The passes this session renders at most (u32::MAX: until a time or noise target).
    pub fn planned_passes(&self) -> u32 {
        self.plan.shard.unwrap_or(Shard::WHOLE).len(self.plan.pass_count(&self.settings))
    }

    /// Renders the next pass, or None once stopped. A GPU failure renders
    /// the passes again from the first with photon-cpu, saying why.
    pub fn next_pass(&mut self) -> Result<Option<PassReport>> {
        if self.stopped.is_some() {
            return Ok(None);
        }
        let Some(pass) = self.next else {
            self.stopped = Some(StopReason::PassCount);
            return Ok(None);
        };
        // Interrupted between passes (while the caller looked at the last).
        if !self.rendered.is_empty() && self.interrupted() {
            self.stopped = Some(StopReason::Interrupt);
            return Ok(None);
        }
        let start = *self.start.get_or_insert_with(Instant::now);
        if let Err(e) = self.renderer.render_pass(pass) {
            if !self.on_gpu {
                return Err(e);
            }
            let rendering = if self.progressive() { "rendering the passes" } else { "rendering" };
            self.log.note(&format!("gpu: {e:#}: {rendering} with photon-cpu instead"));
            self.use_photon_cpu(self.progressive());
            self.rendered.clear();
            self.next = self.plan.shard.unwrap_or(Shard::WHOLE).passes(self.plan.pass_count(&self.settings)).next();
            return self.next_pass();
        }
        self.rendered.push(pass);
        let count = self.rendered.len() as u32;
        let step = self.plan.shard.unwrap_or(Shard::WHOLE).count;
        let total = self.plan.pass_count(&self.settings);
        self.next = pass.checked_add(step).filter(|&n| n <= total);
        let noise = self.renderer.noise();
        let seconds = start.elapsed().as_secs_f64();
        let target = self.plan.target_error_or_default(&self.settings);
        let time = self.plan.time_or_default(&self.settings);
        self.stopped = if self.next.is_none() {
            Some(StopReason::PassCount)
        } else if count >= 4 && target.zip(noise).is_some_and(|(t, e)| e <= t) {
            Some(StopReason::TargetError)
        } else if time.is_some_and(|t| start.elapsed() >= t) {
            Some(StopReason::TimeLimit)
        } else if self.interrupted() {
            Some(StopReason::Interrupt)
        } else {
            None
        };
        let next_radius = self.next.and_then(|n| self.renderer.radius(n));
        Ok(Some(PassReport { pass, count, noise, seconds, next_radius, last: self.stopped }))
    }

    /// Renders the remaining passes, calling `each` after each.
    pub fn run(mut self, mut each: impl FnMut(&PassReport, &mut Self) -> Result<()>) -> Result<Outcome> {
        while let Some(report) = self.next_pass()? {
            each(&report, &mut self)?;
        }
        self.finish()
    }

    /// The mean of the passes so far.
    pub fn image(&mut self) -> Result<Image> {
        self.renderer.mean()
    }

    /// The mean's estimated relative error so far.
    pub fn noise(&mut self) -> Option<f64> {
        self.renderer.noise()
    }

    /// What the passes made (the passes stop here if they had not).
    pub fn finish(mut self) -> Result<Outcome> {
        let image = self.renderer.mean()?;
        let sums = if self.plan.shard.is_some() { Some(self.renderer.sums()?) } else { None };
        let stopped_by = self.stopped.unwrap_or(StopReason::Interrupt);
        Ok(Outcome {
            image,
            sums,
            stopped_early: self.next.is_some(),
            stopped_by,
            seconds: self.start.map_or(0.0, |s| s.elapsed().as_secs_f64()),
            noise: self.renderer.noise(),
            nonfinite: self.renderer.nonfinite(),
            renderer: self.name,
            passes: self.rendered,
        })
    }

    fn interrupted(&self) -> bool {
        self.interrupt.as_ref().is_some_and(|f| f.load(Ordering::SeqCst))
    }

    fn progressive(&self) -> bool {
        self.plan.progressive(&self.settings)
    }

    /// The renderer for the settings: the single pass or passes.
    fn choose(&mut self) -> Result<()> {
        let progressive = self.progressive();
        match self.settings.renderer {
            RendererKind::Path if !progressive => {
                let settings = path::PathSettings {
                    spp: self.settings.spp.unwrap_or(PATH_SPP),
                    seed: self.settings.seed,
                    ..Default::default()
                };
                let (scene, progress, log) = (self.scene, self.progress, self.log.clone());
                self.renderer = Box::new(OnePass::new(move || {
                    let done = path::render(scene, &settings, progress);
                    log.note(&format!("path tracing: {} spp", settings.spp));
                    Ok(done)
                }));
                self.name = "path".into();
            }
            RendererKind::Path => {
                let spp = self.settings.spp.unwrap_or(if self.plan.open_ended(&self.settings) {
                    PATH_PASS_SPP
                } else {
                    PATH_SPP
                });
                let settings = path::PathSettings { spp, seed: self.settings.seed, ..Default::default() };
                self.log.note(&format!("path tracing in passes of {} spp", settings.spp));
                let mean = self.mean();
                self.renderer = Box::new(PathPasses { scene: self.scene, settings, mean, nonfinite: 0 });
                self.name = "path".into();
            }
            RendererKind::Vcm => {
                let s = &self.settings;
                let settings = vcm::VcmSettings {
                    seed: s.seed,
                    strategies: s.vcm_strategies.into(),
                    radius: s.radius,
                    volume_radius: s.volume_radius,
                    alpha: s.alpha,
                    ..Default::default()
                };
                let radius = settings.radius.unwrap_or_else(|| vcm::default_radius(self.scene));
                let in_media = if self.scene.media.is_empty() {
                    String::new()
                } else {
                    let volume = settings.volume_radius.unwrap_or_else(|| vcm::default_volume_radius(self.scene));
                    format!(" ({volume:.4} in media)")
                };
                self.log.note(&format!(
                    "vcm ({:?}): one light and one camera subpath per pixel a pass, first merging radius {radius:.4}{in_media}, α = {}",
                    settings.strategies, s.alpha
                ));
                let mean = self.mean();
                self.renderer = Box::new(VcmPasses {
                    scene: self.scene,
                    settings,
                    mean,
                    nonfinite: 0,
                    workspace: Default::default(),
                });
                self.name = "vcm".into();
            }
            RendererKind::Gpu | RendererKind::PhotonCpu if !progressive => self.one_photon_pass()?,
            RendererKind::Gpu | RendererKind::PhotonCpu => self.photon_passes()?,
        }
        Ok(())
    }

    fn mean(&self) -> ImageMean {
        ImageMean::new(self.scene.camera.width, self.scene.camera.height)
    }

    fn schedules(&self) -> Schedules {
        let (scene, s) = (self.scene, &self.settings);
        let (global, caustic) = s.photon_cpu(true).estimate_params(scene);
        let volume = s.volume_radius.unwrap_or_else(|| hikari_core::progressive::default_volume_radius(scene));
        Schedules::new([global.radius, caustic.radius, volume], s.alpha)
    }

    /// Progressive photon mapping: on the GPU where it opens and fits,
    /// else photon-cpu.
    fn photon_passes(&mut self) -> Result<()> {
        let (scene, s) = (self.scene, self.settings.clone());
        let schedules = self.schedules();
        let [global, caustic, volume] = schedules.radii(1);
        self.log.note(&format!(
            "progressive: {} photon paths per pass, α = {}; first radii {global:.4} (global), {caustic:.4} (caustic){}",
            s.photons,
            s.alpha,
            if scene.media.is_empty() { String::new() } else { format!(", {volume:.4} (volume)") }
        ));
        if s.renderer == RendererKind::Gpu {
            let cpu = s.photon_cpu(true);
            let gpu_settings = s.gpu(scene, &cpu);
            let expected = expected_map_sizes(scene, s.photons, s.seed);
            if let Some(ctx) = open_gpu(scene, &gpu_settings, expected, &self.log) {
                let adapter = ctx.describe();
                let mut tracer = PhotonTracer::choose(s.trace, Some(&ctx), scene, self.log.clone());
                let device = tracer.device();
                // A shard's first pass builds the renderer (a shard with no passes: pass 1).
                let first_pass = self.plan.shard.map_or(1, |sh| sh.index);
                let first = tracer.trace(scene, &pass_trace_settings(s.photons, s.seed, first_pass), &Silent);
                let gpu_settings = GpuSettings { estimator: s.estimator.on(&ctx), ..gpu_settings };
                let estimator = gpu_settings.estimator;
                match GpuPasses::new(
                    ctx,
                    scene,
                    (first_pass, &first),
                    gpu_settings,
                    s.photons,
                    s.seed,
                    schedules,
                    tracer,
                ) {
                    Ok(passes) => {
                        self.log.note(&format!(
                            "gpu: {adapter}, photons traced on the {device}, passes estimated ({estimator:?}) and averaged on the GPU"
                        ));
                        self.renderer = Box::new(passes);
                        self.name = format!("gpu ({estimator:?} estimator, photons traced on the {device})");
                        self.on_gpu = true;
                        return Ok(());
                    }
                    Err(e) => self.log.note(&format!("gpu: {e:#}: rendering the passes with photon-cpu instead")),
                }
            }
        }
        self.use_photon_cpu(true);
        Ok(())
    }

    /// photon-cpu in passes (`progressive`) or as the single pass.
    fn use_photon_cpu(&mut self, progressive: bool) {
        self.on_gpu = false;
        self.name = "photon-cpu".into();
        if !progressive {
            let (scene, s, log, progress) = (self.scene, self.settings.clone(), self.log.clone(), self.progress);
            self.renderer = Box::new(OnePass::new(move || {
                let settings = s.photon_cpu(false);
                let mut tracer = PhotonTracer::choose(s.trace, None, scene, log.clone());
                let traced = trace_logged(&mut tracer, scene, &s, progress, &log);
                Ok(render_photon_cpu(scene, &traced, &settings, progress, &log))
            }));
            return;
        }
        let s = &self.settings;
        self.renderer = Box::new(CpuPasses {
            scene: self.scene,
            settings: s.photon_cpu(true),
            photons: s.photons,
            schedules: self.schedules(),
            mean: self.mean(),
            nonfinite: 0,
            tracer: PhotonTracer::choose(s.trace, None, self.scene, self.log.clone()),
        });
    }

    /// The seed's single pass: photons traced once, splatted on the GPU
    /// (falling back to photon-cpu on any failure) or estimated by photon-cpu.
    fn one_photon_pass(&mut self) -> Result<()> {
        let (scene, s, log, progress) = (self.scene, self.settings.clone(), self.log.clone(), self.progress);
        let settings = s.photon_cpu(false);
        let gpu_settings = s.gpu(scene, &settings);
        let needs_estimate = s.renderer == RendererKind::Gpu || s.photons > 2_000_000;
        let expected = if needs_estimate { expected_map_sizes(scene, s.photons, s.seed) } else { [0; 3] };
        if s.photons > 2_000_000 {
            let stored: u64 = expected.iter().sum();
            log.note(&format!(
                "note: {} photon paths will store about {} M photons: about {} MiB of photon maps",
                s.photons,
                stored / 1_000_000,
                (stored * 20) >> 20
            ));
        }
        let gpu = match s.renderer {
            RendererKind::Gpu => open_gpu(scene, &gpu_settings, expected, &log),
            _ => None,
        };
        let Some(ctx) = gpu else {
            self.use_photon_cpu(false);
            return Ok(());
        };
        self.name = "gpu".into();
        self.renderer = Box::new(OnePass::new(move || {
            let mut tracer = PhotonTracer::choose(s.trace, Some(&ctx), scene, log.clone());
            let traced = trace_logged(&mut tracer, scene, &s, progress, &log);
            let gpu_settings = GpuSettings { estimator: s.estimator.on(&ctx), ..gpu_settings.clone() };
            match render_on_gpu(ctx.clone(), scene, &traced, gpu_settings, &log) {
                Ok(result) => Ok(result),
                Err(e) => {
                    // The photons are traced: photon-cpu estimates these.
                    log.note(&format!("gpu: {e}: rendering with photon-cpu instead"));
                    Ok(render_photon_cpu(scene, &traced, &settings, progress, &log))
                }
            }
        }));
        Ok(())
    }
}

/// What a session made.
#[derive(Clone, Debug)]
pub struct Outcome {
    /// The mean of the passes (NaN and Inf dropped).
    pub image: Image,
    /// A shard's per-pixel sums, for the merge.
    pub sums: Option<Vec<[f64; 3]>>,
    /// The passes rendered, in order.
    pub passes: Vec<u32>,
    /// Whether it stopped before its last pass (time, target error, interrupt).
    pub stopped_early: bool,
    pub stopped_by: StopReason,
    pub seconds: f64,
    pub noise: Option<f64>,
    /// Non-finite samples dropped.
    pub nonfinite: u64,
    /// The renderer that ran (after any fallback), with how.
    pub renderer: String,
}

/// Traces the single pass's photons, saying how many and how fast.
fn trace_logged(
    tracer: &mut PhotonTracer,
    scene: &Scene,
    s: &RenderSettings,
    progress: &dyn Progress,
    log: &Log,
) -> TracedPhotons {
    let trace_start = Instant::now();
    let traced =
        tracer.trace(scene, &TraceSettings { photons: s.photons, seed: s.seed, ..Default::default() }, progress);
    let trace_time = trace_start.elapsed().as_secs_f64();
    log.note(&format!(
        "photons (traced on the {}): {} emitted, {} stored in the global map, {} in the caustic map, {} in the volume map; {:.2} M paths/s ({:.2} s)",
        tracer.device(),
        traced.stats.emitted,
        traced.global.len(),
        traced.caustic.len(),
        traced.volume.len(),
        traced.stats.emitted as f64 / trace_time / 1e6,
        trace_time
    ));
    let (global, caustic) = s.photon_cpu(false).estimate_params(scene);
    log.note(&format!("radius {:.4}, caustic radius {:.4}", global.radius, caustic.radius));
    traced
}

fn render_photon_cpu(
    scene: &Scene,
    traced: &TracedPhotons,
    settings: &photon_cpu::PhotonCpuSettings,
    progress: &dyn Progress,
    log: &Log,
) -> (Image, u64) {
    let build_start = Instant::now();
    let cpu = photon_cpu::PhotonCpuRenderer::new(scene, traced, settings);
    let build_time = build_start.elapsed().as_secs_f64();
    let render_start = Instant::now();
    let result = cpu.render(progress);
    log.note(&format!(
        "photon-cpu: photon-map indexes {build_time:.2} s, render {:.2} s ({} spp)",
        render_start.elapsed().as_secs_f64(),
        settings.spp
    ));
    result
}

/// Photons each map will hold for `photons` paths, from a pilot trace of a
/// few thousand paths (with 25% to spare), so limits are checked before
/// the real trace.
fn expected_map_sizes(scene: &Scene, photons: u64, seed: u64) -> [u64; 3] {
    const PILOT: u64 = 4096;
    let pilot =
        trace_photons(scene, &TraceSettings { photons: PILOT, seed: seed ^ 0x9e37, ..Default::default() }, &Silent);
    let per_path = |stored: usize| (stored as f64 / PILOT as f64 * photons as f64 * 1.25).ceil() as u64 + 64;
    [per_path(pilot.indirect().len()), per_path(pilot.caustic.len()), per_path(pilot.volume.len())]
}

/// An adapter that can draw `scene` with `settings`, or None after one line
/// saying why not.
fn open_gpu(scene: &Scene, settings: &GpuSettings, expected: [u64; 3], log: &Log) -> Option<GpuContext> {
    let ctx = match GpuContext::new() {
        Ok(ctx) => ctx,
        Err(e) => {
            log.note(&format!("{e}: rendering with photon-cpu instead"));
            return None;
        }
    };
    if let Err(e) = GpuRenderer::check_fits(&ctx, scene, settings, expected) {
        log.note(&format!("gpu {}: {e}: rendering with photon-cpu instead", ctx.describe()));
        return None;
    }
    for note in hikari_gpu::renderer::adapter_notes(&ctx, scene) {
        log.note(&note);
    }
    Some(ctx)
}

/// One frame on the GPU, read back.
fn render_on_gpu(
    ctx: GpuContext,
    scene: &Scene,
    traced: &TracedPhotons,
    settings: GpuSettings,
    log: &Log,
) -> Result<(Image, u64), GpuError> {
    let adapter = format!("{}, {:?} estimator", ctx.describe(), settings.estimator);
    if !ctx.float32_blend && settings.estimator == Estimator::Raster {
        log.note(&format!(
            "note: {} cannot blend 32-bit float targets; photon splats accumulate in 16-bit floats (about 3 significant digits)",
            ctx.describe()
        ));
    }
    let setup_start = Instant::now();
    let renderer = GpuRenderer::new(ctx, scene, traced, settings)?;
    let setup = setup_start.elapsed().as_secs_f64();
    let frame_start = Instant::now();
    renderer.render()?;
    let result = renderer.read_image()?;
    let slices = renderer.specular_slices();
    let split = if slices > 1 { format!(", specular gathers split into {slices} dispatches") } else { String::new() };
    log.note(&format!(
        "gpu: {adapter}; setup {setup:.2} s, frame and readback {:.3} s (1 sample per pixel{split})",
        frame_start.elapsed().as_secs_f64()
    ));
    Ok(result)
}

#[cfg(test)]
mod tests {
    use super::*;
    use hikari_core::progressive::shard::Shard;
    use std::time::Duration;

    fn scene(width: u32) -> Scene {
        let mut scene = Scene::load("cornell-box").unwrap();
        scene.camera = scene.camera.with_resolution(width, width).unwrap();
        scene
    }

    fn quiet() -> Log {
        Log::to(|_| {})
    }

    /// Passes whose images are the pass number: the mean of n passes is
    /// (n + 1) / 2; noise 1/n where `noisy`.
    struct Counting {
        last: u32,
        asked: Vec<u32>,
        noisy: bool,
    }

    fn counting(noisy: bool) -> Box<Counting> {
        Box::new(Counting { last: 0, asked: Vec::new(), noisy })
    }

    impl PassRenderer for Counting {
        fn render_pass(&mut self, pass: u32) -> Result<()> {
            self.asked.push(pass);
            self.last = pass;
            Ok(())
        }
        fn mean(&mut self) -> Result<Image> {
            let mut image = Image::new(1, 1);
            image.pixels[0] = glam::Vec3::splat((self.asked.len() as f32 + 1.0) / 2.0);
            Ok(image)
        }
        fn radius(&self, _: u32) -> Option<f32> {
            None
        }
        fn noise(&mut self) -> Option<f64> {
            self.noisy.then(|| 1.0 / self.asked.len() as f64)
        }
        fn sums(&mut self) -> Result<Vec<[f64; 3]>> {
            Ok(vec![[self.asked.iter().map(|&p| p as f64).sum(); 3]])
        }
    }

    fn run_counting(plan: Plan, noisy: bool) -> Outcome {
        let scene = scene(4);
        let session =
            Session::with_renderer(&scene, RenderSettings::default(), plan, quiet(), &Silent, counting(noisy), "t");
        session.run(|_, _| Ok(())).unwrap()
    }

    #[test]
    fn stops_at_the_pass_count_or_the_time_limit() {
        let done = run_counting(Plan { passes: Some(5), ..Default::default() }, false);
        assert_eq!((done.passes.len(), done.image.pixels[0].x, done.stopped_early), (5, 3.0, false));
        assert_eq!(done.stopped_by, StopReason::PassCount);
        let done = run_counting(Plan { time: Some(Duration::ZERO), ..Default::default() }, false);
        assert_eq!((done.passes.len(), done.stopped_early), (1, true), "a time limit still renders one pass");
        assert_eq!(done.stopped_by, StopReason::TimeLimit);
    }

    #[test]
    fn a_shard_renders_its_share_of_the_passes() {
        for (k, m, expected) in [(1, 3, vec![1, 4, 7]), (3, 3, vec![3, 6]), (7, 7, vec![7]), (2, 2, vec![2, 4, 6])] {
            let plan = Plan { passes: Some(7), shard: Some(Shard { index: k, count: m }), ..Default::default() };
            let done = run_counting(plan, false);
            assert_eq!((&done.passes, done.stopped_early), (&expected, false));
            let sum: u32 = expected.iter().sum();
            assert_eq!(done.sums, Some(vec![[sum as f64; 3]]), "a shard hands back its sums");
        }
        // More shards than passes: shard 9 of 9 has none of 7.
        let plan = Plan { passes: Some(7), shard: Some(Shard { index: 9, count: 9 }), ..Default::default() };
        let scene = scene(4);
        let mut session =
            Session::with_renderer(&scene, RenderSettings::default(), plan, quiet(), &Silent, counting(false), "t");
        assert_eq!(session.next_pass().unwrap(), None);
    }

    #[test]
    fn stops_at_the_target_error() {
        let target = |t| Plan { target_error: Some(t), ..Default::default() };
        assert_eq!(run_counting(target(0.1), true).passes.len(), 10);
        let done = run_counting(target(0.9), true);
        assert_eq!((done.passes.len(), done.stopped_by), (4, StopReason::TargetError), "at least 4 passes");
        let plan = Plan { passes: Some(7), target_error: Some(0.5), ..Default::default() };
        assert_eq!(run_counting(plan, false).passes.len(), 7, "no estimate: the pass count");
    }

    #[test]
    fn nothing_said_stops_at_the_default_noise_or_time() {
        let settings = RenderSettings::default();
        let plan = Plan::default();
        assert!(plan.by_default(&settings) && plan.progressive(&settings));
        assert_eq!(plan.target_error_or_default(&settings), Some(crate::settings::DEFAULT_TARGET_ERROR));
        let path_spp = RenderSettings { renderer: RendererKind::Path, spp: Some(16), ..settings };
        assert!(!plan.progressive(&path_spp), "the path tracer with spp alone renders one pass");
        assert_eq!(run_counting(Plan::default(), true).stopped_by, StopReason::TargetError);
    }

    #[test]
    fn an_interrupt_stops_after_the_pass_under_way() {
        let scene = scene(4);
        let flag = Arc::new(AtomicBool::new(false));
        let plan = Plan { passes: Some(100), ..Default::default() };
        let session =
            Session::with_renderer(&scene, RenderSettings::default(), plan, quiet(), &Silent, counting(false), "t")
                .interrupt_on(flag.clone());
        let done = session
            .run(|pass, _| {
                if pass.count == 3 {
                    flag.store(true, Ordering::SeqCst);
                }
                Ok(())
            })
            .unwrap();
        assert_eq!((done.passes, done.stopped_by, done.stopped_early), (vec![1, 2, 3], StopReason::Interrupt, true));
    }

    #[test]
    fn reports_each_pass_and_the_mean_so_far() {
        let scene = scene(4);
        let plan = Plan { passes: Some(3), ..Default::default() };
        let mut session =
            Session::with_renderer(&scene, RenderSettings::default(), plan, quiet(), &Silent, counting(true), "t");
        let mut seen = Vec::new();
        while let Some(report) = session.next_pass().unwrap() {
            seen.push((report.pass, report.count, report.noise, report.last));
            assert_eq!(session.image().unwrap().pixels[0].x, (report.count as f32 + 1.0) / 2.0);
        }
        assert_eq!(
            seen,
            vec![
                (1, 1, Some(1.0), None),
                (2, 2, Some(0.5), None),
                (3, 3, Some(1.0 / 3.0), Some(StopReason::PassCount))
            ]
        );
    }

    /// The session's single photon-cpu pass is the core's render of the
    /// same photons, to the bit.
    #[test]
    fn one_photon_cpu_pass_is_the_cores_render() {
        let scene = scene(16);
        let settings =
            RenderSettings { renderer: RendererKind::PhotonCpu, photons: 2000, seed: 3, ..Default::default() };
        let plan = Plan { passes: Some(1), ..Default::default() };
        let session = Session::new(&scene, settings.clone(), plan, quiet(), &Silent).unwrap();
        assert_eq!(session.renderer_name(), "photon-cpu");
        let done = session.run(|_, _| Ok(())).unwrap();
        let traced = trace_photons(&scene, &TraceSettings { photons: 2000, seed: 3, ..Default::default() }, &Silent);
        let cpu = settings.photon_cpu(false);
        let (expected, _) = photon_cpu::PhotonCpuRenderer::new(&scene, &traced, &cpu).render(&Silent);
        assert_eq!(done.image.pixels, expected.pixels);
    }

    /// Passes of the path tracer are the core's passes, averaged.
    #[test]
    fn path_passes_are_the_cores_passes() {
        let scene = scene(8);
        let settings = RenderSettings { renderer: RendererKind::Path, spp: Some(2), seed: 5, ..Default::default() };
        let plan = Plan { passes: Some(2), ..Default::default() };
        let done = Session::new(&scene, settings, plan, quiet(), &Silent).unwrap().run(|_, _| Ok(())).unwrap();
        let pass =
            |pass| path::render(&scene, &path::PathSettings { spp: 2, seed: 5, pass, ..Default::default() }, &Silent).0;
        let (a, b) = (pass(1), pass(2));
        for ((got, a), b) in done.image.pixels.iter().zip(&a.pixels).zip(&b.pixels) {
            assert!((*got - (*a + *b) * 0.5).abs().max_element() <= 1e-5 * (1.0 + got.max_element()), "{got} {a} {b}");
        }
    }

    /// A GPU that cannot hold the settings (a sphere light's 256 samples of
    /// six 8192² shadow maps) is never a crash: photon-cpu renders, and a
    /// note says why.
    #[test]
    fn the_gpu_falls_back_to_photon_cpu_with_a_reason() {
        let mut scene = Scene::load("cornell-caustic").unwrap();
        scene.camera = scene.camera.with_resolution(8, 8).unwrap();
        let settings = RenderSettings {
            renderer: RendererKind::Gpu,
            photons: 500,
            shadow_map_size: 8192,
            area_light_samples: 256,
            ..Default::default()
        };
        let (log, notes) = Log::collected();
        let plan = Plan { passes: Some(2), ..Default::default() };
        let session = Session::new(&scene, settings, plan, log, &Silent).unwrap();
        assert_eq!(session.renderer_name(), "photon-cpu");
        let done = session.run(|_, _| Ok(())).unwrap();
        assert_eq!(done.passes, vec![1, 2]);
        let notes = notes.lock().unwrap();
        assert!(notes.iter().any(|n| n.contains("rendering with photon-cpu instead")), "{notes:?}");
    }
}

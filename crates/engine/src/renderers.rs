//! The renderers, pass by pass. Pass i traces with seed + i − 1 (the
//! photon renderers) or draws the next samples of the pixels' Sobol streams
//! (the path tracer, `PathSettings::pass`), so pass 1 is the single-pass
//! render and every pass depends on the seed and its number alone. The
//! seed's single pass (`OnePass`) is a renderer of one pass too.

use crate::passes::PassRenderer;
use crate::tracer::PhotonTracer;
use anyhow::Result;
use hikari_core::photon::TracedPhotons;
use hikari_core::progress::Silent;
use hikari_core::progressive::{ImageMean, Schedules, pass_jitter, pass_trace_settings, photon_cpu_estimate_pass};
use hikari_core::render::{Image, path, photon_cpu, vcm};
use hikari_core::scene::Scene;
use hikari_gpu::accumulate::AccumulatePass;
use hikari_gpu::{GpuContext, GpuRenderer, GpuSettings};

/// `photon-cpu`: each pass estimates its own photons at the schedule's radii.
pub struct CpuPasses<'a> {
    pub scene: &'a Scene,
    pub settings: photon_cpu::PhotonCpuSettings,
    pub photons: u64,
    pub schedules: Schedules,
    pub mean: ImageMean,
    /// Non-finite samples dropped, over all passes.
    pub nonfinite: u64,
    pub tracer: PhotonTracer,
}

impl PassRenderer for CpuPasses<'_> {
    fn nonfinite(&self) -> u64 {
        self.nonfinite
    }

    fn render_pass(&mut self, pass: u32) -> Result<()> {
        let settings = pass_trace_settings(self.photons, self.settings.seed, pass);
        let traced = self.tracer.trace(self.scene, &settings, &Silent);
        let (image, nonfinite) = photon_cpu_estimate_pass(self.scene, &self.settings, &traced, &self.schedules, pass);
        self.nonfinite += nonfinite;
        self.mean.add(&image);
        Ok(())
    }

    fn mean(&mut self) -> Result<Image> {
        Ok(self.mean.mean())
    }

    fn noise(&mut self) -> Option<f64> {
        self.mean.noise_estimate()
    }

    fn sums(&mut self) -> Result<Vec<[f64; 3]>> {
        Ok(self.mean.sums().to_vec())
    }

    fn radius(&self, pass: u32) -> Option<f32> {
        Some(self.schedules.global.radius(pass))
    }
}

/// The path tracer: each pass is `spp` more samples per pixel.
pub struct PathPasses<'a> {
    pub scene: &'a Scene,
    pub settings: path::PathSettings,
    pub mean: ImageMean,
    pub nonfinite: u64,
}

impl PassRenderer for PathPasses<'_> {
    fn nonfinite(&self) -> u64 {
        self.nonfinite
    }

    fn render_pass(&mut self, pass: u32) -> Result<()> {
        let settings = path::PathSettings { pass, ..self.settings.clone() };
        let (image, nonfinite) = path::render(self.scene, &settings, &Silent);
        self.nonfinite += nonfinite;
        self.mean.add(&image);
        Ok(())
    }

    fn mean(&mut self) -> Result<Image> {
        Ok(self.mean.mean())
    }

    fn noise(&mut self) -> Option<f64> {
        self.mean.noise_estimate()
    }

    fn sums(&mut self) -> Result<Vec<[f64; 3]>> {
        Ok(self.mean.sums().to_vec())
    }

    fn radius(&self, _: u32) -> Option<f32> {
        None
    }
}

/// Vertex connection and merging: each pass is one light and one camera
/// subpath per pixel at the pass's merging radius.
pub struct VcmPasses<'a> {
    pub scene: &'a Scene,
    pub settings: vcm::VcmSettings,
    pub mean: ImageMean,
    pub nonfinite: u64,
    pub workspace: vcm::Workspace,
}

impl PassRenderer for VcmPasses<'_> {
    fn nonfinite(&self) -> u64 {
        self.nonfinite
    }

    fn render_pass(&mut self, pass: u32) -> Result<()> {
        let (image, nonfinite) =
            vcm::render_pass_in(&mut self.workspace, self.scene, &self.settings, pass).map_err(anyhow::Error::msg)?;
        self.nonfinite += nonfinite;
        self.mean.add(&image);
        Ok(())
    }

    fn mean(&mut self) -> Result<Image> {
        Ok(self.mean.mean())
    }

    fn noise(&mut self) -> Option<f64> {
        self.mean.noise_estimate()
    }

    fn sums(&mut self) -> Result<Vec<[f64; 3]>> {
        Ok(self.mean.sums().to_vec())
    }

    fn radius(&self, pass: u32) -> Option<f32> {
        let first = self.settings.radius.unwrap_or_else(|| vcm::default_radius(self.scene));
        Some(hikari_core::progressive::RadiusSchedule::disc(first, self.settings.alpha).radius(pass))
    }
}

/// The GPU renderer: each pass uploads its photons (the specular pass's
/// grids rebuilt at the pass's radii), splats them at those radii from a
/// camera jittered within the pixel (`pass_jitter`) and adds the frame to a
/// running mean on the GPU; nothing is read back but the mean, at
/// checkpoints and at the end.
pub struct GpuPasses<'a> {
    scene: &'a Scene,
    renderer: GpuRenderer,
    mean: AccumulatePass,
    photons: u64,
    seed: u64,
    schedules: Schedules,
    /// The pass whose photons the renderer was built with, until it is rendered.
    first_built: Option<u32>,
    tracer: PhotonTracer,
    pub nonfinite: u64,
    /// The last noise estimate (`AccumulatePass::noise_due`: reading the
    /// means back each pass would cost more than the pass at large sizes).
    noise: Option<f64>,
}

impl<'a> GpuPasses<'a> {
    /// A renderer of `scene` built with pass `first_pass`'s photons `first`
    /// (traced with `pass_trace_settings`) at that pass's radii; other
    /// passes trace with `tracer`.
    #[allow(clippy::too_many_arguments)]
    pub fn new(
        ctx: GpuContext,
        scene: &'a Scene,
        (first_pass, first): (u32, &TracedPhotons),
        mut settings: GpuSettings,
        photons: u64,
        seed: u64,
        schedules: Schedules,
        tracer: PhotonTracer,
    ) -> Result<Self> {
        [settings.global.radius, settings.caustic.radius, settings.volume_radius] = schedules.radii(first_pass);
        settings.pass = first_pass;
        let mut renderer = GpuRenderer::new(ctx, scene, first, settings)?;
        if first_pass != 1 {
            let mut camera = renderer.camera().clone();
            camera.jitter = pass_jitter(first_pass);
            renderer.set_camera(&camera)?;
        }
        let mean = AccumulatePass::new(&renderer.ctx.device, renderer.resolved());
        Ok(GpuPasses {
            scene,
            renderer,
            mean,
            photons,
            seed,
            schedules,
            first_built: Some(first_pass),
            tracer,
            nonfinite: 0,
            noise: None,
        })
    }
}

impl PassRenderer for GpuPasses<'_> {
    fn nonfinite(&self) -> u64 {
        self.nonfinite
    }

    fn render_pass(&mut self, pass: u32) -> Result<()> {
        if self.first_built.take() != Some(pass) {
            let traced = self.tracer.trace(self.scene, &pass_trace_settings(self.photons, self.seed, pass), &Silent);
            let s = &mut self.renderer.settings;
            [s.global.radius, s.caustic.radius, s.volume_radius] = self.schedules.radii(pass);
            // Glossy lobes and area lights draw new samples each pass.
            s.pass = pass;
            self.renderer.set_photons(self.scene, &traced)?;
            // One sample per pixel a pass: each pass samples another point of the pixel.
            let mut camera = self.renderer.camera().clone();
            camera.jitter = pass_jitter(pass);
            self.renderer.set_camera(&camera)?;
        }
        self.renderer.render()?;
        let ctx = &self.renderer.ctx;
        let mut encoder = ctx.device.create_command_encoder(&Default::default());
        self.mean.record(&ctx.queue, &mut encoder);
        ctx.queue.submit([encoder.finish()]);
        if self.mean.noise_due() {
            self.noise = self.mean.read_noise(&self.renderer.ctx)?;
        }
        Ok(())
    }

    fn noise(&mut self) -> Option<f64> {
        self.noise
    }

    /// The mean (kept in f32 on the GPU) times the passes: the merge of GPU
    /// shards matches a single GPU run to f32's precision, not bit for bit.
    fn sums(&mut self) -> Result<Vec<[f64; 3]>> {
        let n = self.mean.count() as f64;
        Ok(self.mean()?.pixels.iter().map(|p| [p.x as f64 * n, p.y as f64 * n, p.z as f64 * n]).collect())
    }

    fn mean(&mut self) -> Result<Image> {
        let values = self.renderer.read(&self.mean.mean)?;
        let t = &self.renderer.targets.gbuffer;
        let mut image = Image::new(t.width, t.height);
        self.nonfinite = 0;
        for (pixel, value) in image.pixels.iter_mut().zip(values) {
            let v = value.truncate();
            if v.is_finite() {
                *pixel = v;
            } else {
                self.nonfinite += 1;
            }
        }
        Ok(image)
    }

    fn radius(&self, pass: u32) -> Option<f32> {
        Some(self.schedules.global.radius(pass))
    }
}

/// The seed's single pass, not a mean of passes: the path tracer at its
/// spp, or photons traced once and splatted on the GPU or estimated by
/// photon-cpu at its spp (`render` runs it, within-pass progress and all).
pub struct OnePass<'a> {
    render: Box<dyn FnMut() -> Result<(Image, u64)> + 'a>,
    image: Option<Image>,
    pub nonfinite: u64,
}

impl<'a> OnePass<'a> {
    pub fn new(render: impl FnMut() -> Result<(Image, u64)> + 'a) -> Self {
        OnePass { render: Box::new(render), image: None, nonfinite: 0 }
    }
}

impl PassRenderer for OnePass<'_> {
    fn render_pass(&mut self, _pass: u32) -> Result<()> {
        let (image, nonfinite) = (self.render)()?;
        self.image = Some(image);
        self.nonfinite = nonfinite;
        Ok(())
    }

    fn mean(&mut self) -> Result<Image> {
        self.image.clone().ok_or_else(|| anyhow::anyhow!("the single pass has not been rendered"))
    }

    fn sums(&mut self) -> Result<Vec<[f64; 3]>> {
        Ok(self.mean()?.pixels.iter().map(|p| [p.x as f64, p.y as f64, p.z as f64]).collect())
    }

    fn radius(&self, _: u32) -> Option<f32> {
        None
    }

    fn nonfinite(&self) -> u64 {
        self.nonfinite
    }
}

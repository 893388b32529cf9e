//! What a render is asked for: which renderer and its settings (what
//! changes the image), and when its passes stop. Every front end fills
//! these in; the defaults are the CLI's.

use hikari_core::lod::LodSettings;
use hikari_core::progressive::DEFAULT_ALPHA;
use hikari_core::progressive::shard::Shard;
use hikari_core::render::photon_cpu;
use hikari_core::scene::Scene;
use hikari_gpu::tiled::Estimator;
use hikari_gpu::{GpuContext, GpuSettings};
use std::time::Duration;

pub use crate::tracer::TraceDevice;

/// A render without a pass count, time or target error (nor spp with the
/// path tracer) renders passes until the noise they estimate falls to this
/// fraction of the image's mean, or for this many seconds, whichever first.
pub const DEFAULT_TARGET_ERROR: f64 = 0.02;
pub const DEFAULT_TIME_LIMIT: f64 = 20.0;
/// Samples per pixel of the path tracer's open-ended passes (without spp).
pub const PATH_PASS_SPP: u32 = 4;
/// The path tracer's samples per pixel in one pass without spp.
pub const PATH_SPP: u32 = 64;
/// photon-cpu's samples per pixel in one pass without spp.
pub const PHOTON_CPU_SPP: u32 = 4;
/// Photon paths emitted per pass without a count.
pub const DEFAULT_PHOTONS: u64 = 200_000;

#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[cfg_attr(feature = "clap", derive(clap::ValueEnum))]
pub enum RendererKind {
    /// The seed's photon splatting on the GPU. Falls back to photon-cpu,
    /// saying why, when no adapter can run it, when the scene or settings
    /// exceed the adapter's limits, or on any GPU error.
    #[default]
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

impl RendererKind {
    /// The name front ends spell it with (`--renderer`, Python's `renderer=`).
    pub fn name(self) -> &'static str {
        match self {
            RendererKind::Gpu => "gpu",
            RendererKind::PhotonCpu => "photon-cpu",
            RendererKind::Path => "path",
            RendererKind::Vcm => "vcm",
        }
    }

    /// The kind named `name` (as [`RendererKind::name`] spells it).
    pub fn from_name(name: &str) -> Option<Self> {
        [RendererKind::Gpu, RendererKind::PhotonCpu, RendererKind::Path, RendererKind::Vcm]
            .into_iter()
            .find(|k| k.name() == name)
    }
}

/// Which of VCM's strategies `vcm` uses.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[cfg_attr(feature = "clap", derive(clap::ValueEnum))]
pub enum VcmStrategies {
    /// Connections and merging.
    #[default]
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

#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[cfg_attr(feature = "clap", derive(clap::ValueEnum))]
pub enum EstimatorChoice {
    /// Tiled on hardware GPUs (their compute units far outnumber their
    /// rasterizers), raster on software adapters (lavapipe, llvmpipe).
    #[default]
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

/// Everything that changes a render's pixels (not when it stops, nor the
/// thread count: the same image whatever the thread count). `None` fields
/// take the defaults the CLI documents.
#[derive(Clone, Debug, PartialEq)]
pub struct RenderSettings {
    pub renderer: RendererKind,
    /// Where photons are traced.
    pub trace: TraceDevice,
    /// How the GPU renderer estimates the maps.
    pub estimator: EstimatorChoice,
    /// Photon paths emitted from the lights per pass.
    pub photons: u64,
    /// Global-map radius [3% of the scene diagonal].
    pub radius: Option<f32>,
    /// Caustic-map radius [1% of the scene diagonal].
    pub caustic_radius: Option<f32>,
    /// Volume-map radius [3% of the diagonal for one pass, 0.8% for the
    /// first of progressive passes; vcm: 0.3%].
    pub volume_radius: Option<f32>,
    /// Samples per pixel [4 for photon-cpu, 64 for path; path in open-ended passes: 4 a pass].
    pub spp: Option<u32>,
    pub seed: u64,
    pub vcm_strategies: VcmStrategies,
    /// Samples per area light.
    pub area_light_samples: u32,
    /// Shadow-map side in texels (gpu).
    pub shadow_map_size: u32,
    /// Optical-depth slices through region media (gpu).
    pub volume_slices: u32,
    /// Count only photons from the side the surface faces the eye [off
    /// for one pass, on for progressive passes].
    pub normal_test: Option<bool>,
    /// The GPU's distance LOD (None: off).
    pub lod: Option<LodSettings>,
    /// The radius schedule's α in (0, 1).
    pub alpha: f32,
}

impl Default for RenderSettings {
    fn default() -> Self {
        RenderSettings {
            renderer: RendererKind::Gpu,
            trace: TraceDevice::Auto,
            estimator: EstimatorChoice::Auto,
            photons: DEFAULT_PHOTONS,
            radius: None,
            caustic_radius: None,
            volume_radius: None,
            spp: None,
            seed: 0,
            vcm_strategies: VcmStrategies::All,
            area_light_samples: 4,
            shadow_map_size: 1024,
            volume_slices: 8,
            normal_test: None,
            lod: None,
            alpha: DEFAULT_ALPHA,
        }
    }
}

/// When the passes stop. With none of `passes`, `time` and `target_error`
/// (and for the path tracer no spp) the render stops at
/// [`DEFAULT_TARGET_ERROR`] or after [`DEFAULT_TIME_LIMIT`] seconds.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Plan {
    /// At most this many passes (1: the seed's single pass).
    pub passes: Option<u32>,
    /// Stop after the first pass that ends past this.
    pub time: Option<Duration>,
    /// Stop once the estimated noise (relative to the mean) is this low,
    /// from the fourth pass on.
    pub target_error: Option<f64>,
    /// Render only this shard's share of the passes.
    pub shard: Option<Shard>,
    /// Render in passes even where one pass is asked for (the CLI's
    /// checkpoints and reference compare the mean of passes).
    pub in_passes: bool,
}

impl Plan {
    /// Whether nothing says when to stop, so the defaults do.
    pub fn by_default(&self, settings: &RenderSettings) -> bool {
        self.passes.is_none()
            && self.time.is_none()
            && self.target_error.is_none()
            && !(settings.renderer == RendererKind::Path && settings.spp.is_some())
    }

    /// Whether to render in progressive passes: more than one pass, a
    /// time limit or target error, a shard, or nothing said.
    pub fn progressive(&self, settings: &RenderSettings) -> bool {
        self.passes.is_some_and(|n| n > 1)
            || self.time.is_some()
            || self.target_error.is_some()
            || self.shard.is_some()
            || self.in_passes
            || self.by_default(settings)
    }

    /// The target error, with the default where nothing is said.
    pub fn target_error_or_default(&self, settings: &RenderSettings) -> Option<f64> {
        self.target_error.or(self.by_default(settings).then_some(DEFAULT_TARGET_ERROR))
    }

    /// The time limit, with the default where nothing is said.
    pub fn time_or_default(&self, settings: &RenderSettings) -> Option<Duration> {
        self.time.or(self.by_default(settings).then_some(Duration::from_secs_f64(DEFAULT_TIME_LIMIT)))
    }

    /// Whether the passes run until a time or noise target (no fixed count).
    pub fn open_ended(&self, settings: &RenderSettings) -> bool {
        self.time_or_default(settings).is_some() || self.target_error_or_default(settings).is_some()
    }

    /// The last pass number: the count asked for, else unbounded where
    /// open-ended, else 1.
    pub fn pass_count(&self, settings: &RenderSettings) -> u32 {
        self.passes.unwrap_or(if self.open_ended(settings) { u32::MAX } else { 1 })
    }
}

/// Radii outside [1e-5, 0.5] scene diagonals: below, the estimate's 1/r²
/// overflows or no photon is ever found; above, every photon covers every
/// pixel and a frame takes for ever.
pub const RADIUS_RANGE: (f32, f32) = (1e-5, 0.5);

/// Most photon paths a pass may emit: about 6 GB of photon maps in the
/// built-in scenes (3 stored photons of 20 bytes per path).
pub const MAX_PHOTONS: u64 = 100_000_000;

impl RenderSettings {
    /// Settings this scene cannot render with, as a message naming the
    /// setting the way the front end spells it (`spell("caustic-radius")`:
    /// "--caustic-radius" on the command line, "caustic_radius" in Python).
    pub fn check(&self, scene: &Scene, spell: impl Fn(&str) -> String) -> Result<(), String> {
        let diagonal = scene.diagonal();
        let (lo, hi) = (RADIUS_RANGE.0 * diagonal, RADIUS_RANGE.1 * diagonal);
        for (name, value) in
            [("radius", self.radius), ("caustic-radius", self.caustic_radius), ("volume-radius", self.volume_radius)]
        {
            let Some(r) = value else { continue };
            if !(r.is_finite() && r > 0.0) {
                return Err(format!("{} {r}: must be a positive, finite length", spell(name)));
            }
            if !(r >= lo && r <= hi) {
                return Err(format!(
                    "{} {r}: must be between {lo:.3e} and {hi:.3e} (1e-5 to 0.5 of this scene's diagonal {diagonal:.3})",
                    spell(name)
                ));
            }
        }
        if !(1..=MAX_PHOTONS).contains(&self.photons) {
            return Err(format!("{} {}: must be between 1 and {MAX_PHOTONS}", spell("photons"), self.photons));
        }
        if let Some(spp) = self.spp.filter(|spp| !(1..=65536).contains(spp)) {
            return Err(format!("{} {spp}: must be between 1 and 65536", spell("spp")));
        }
        if !(self.alpha > 0.0 && self.alpha < 1.0) {
            return Err(format!("{} {}: α must lie strictly between 0 and 1", spell("alpha"), self.alpha));
        }
        Ok(())
    }

    /// photon-cpu's settings (also the GPU's radii), for a render in
    /// passes (`progressive`) or one.
    pub fn photon_cpu(&self, progressive: bool) -> photon_cpu::PhotonCpuSettings {
        photon_cpu::PhotonCpuSettings {
            radius: self.radius,
            caustic_radius: self.caustic_radius,
            spp: self.spp.unwrap_or(PHOTON_CPU_SPP),
            seed: self.seed,
            area_light_samples: self.area_light_samples,
            normal_test: self.normal_test.unwrap_or(progressive),
            volume_radius: self.volume_radius,
            ..Default::default()
        }
    }

    /// The GPU renderer's settings, its radii from `cpu` (estimator: raster
    /// until an adapter chooses).
    pub fn gpu(&self, scene: &Scene, cpu: &photon_cpu::PhotonCpuSettings) -> GpuSettings {
        let (global, caustic) = cpu.estimate_params(scene);
        GpuSettings {
            area_light_samples: self.area_light_samples,
            shadow_map_size: self.shadow_map_size,
            lod: self.lod,
            volume_radius: self.volume_radius.unwrap_or_else(|| photon_cpu::default_radius(scene)),
            volume_slices: self.volume_slices,
            ..GpuSettings::new(global, caustic)
        }
    }
}

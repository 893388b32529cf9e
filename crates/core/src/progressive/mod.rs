//! Progressive photon mapping: passes of independent photon sets, each
//! estimated with a radius that shrinks by Knaus & Zwicker's schedule, and
//! the running mean of their images, which converges to the true image as
//! passes are added (docs/progressive.md). Pass 1 is the seed's single-pass
//! method. `photon-cpu` and the GPU renderer run the same passes: pass i
//! traces with seed + (i − 1) and estimates at the radii `radii(i)`.

pub mod metric;
pub mod schedule;
pub mod shard;

use crate::render::Image;
use glam::{Vec2, Vec3};
pub use metric::{ImageError, compare, compare_where, without_lights};
pub use schedule::{DEFAULT_ALPHA, RadiusSchedule};

/// The schedules of the three maps (global, caustic, volume).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Schedules {
    pub global: RadiusSchedule,
    pub caustic: RadiusSchedule,
    pub volume: RadiusSchedule,
}

impl Schedules {
    /// Every map shrinks from its own first radius with the same α.
    pub fn new([global, caustic, volume]: [f32; 3], alpha: f32) -> Self {
        Schedules {
            global: RadiusSchedule::disc(global, alpha),
            caustic: RadiusSchedule::disc(caustic, alpha),
            volume: RadiusSchedule::disc(volume, alpha),
        }
    }

    /// The radii of pass `pass` (from 1): global, caustic, volume.
    pub fn radii(&self, pass: u32) -> [f32; 3] {
        [self.global.radius(pass), self.caustic.radius(pass), self.volume.radius(pass)]
    }
}

/// The volume map's first radius in progressive passes: 0.8% of the
/// scene's diagonal, where a single pass (the seed's method) uses 3%
/// (`photon_cpu::default_radius`). At 3% the passes' error in fog was
/// mostly blur that the slowly shrinking radius (r ∝ i^−1/6) kept: at
/// 128², 20 s on 2 cores, `fog-stage` 13.3% (5 passes; the passes'
/// own noise estimate 5.3%) and `fog-stage-layered` 22.4%; at 0.8% 6.2%
/// (12 passes: a smaller ball gathers fewer photons per ray) and 7.0%.
pub fn default_volume_radius(scene: &crate::scene::Scene) -> f32 {
    0.008 * scene.diagonal()
}

/// The seed of pass `pass` (from 1): pass 1 uses the render's own seed, so
/// one pass is exactly the single-pass render.
pub fn pass_seed(seed: u64, pass: u32) -> u64 {
    seed.wrapping_add(pass.saturating_sub(1) as u64)
}

/// The sub-pixel jitter (`Camera::jitter`) of pass `pass` (from 1) for a
/// renderer that samples each pixel once (the GPU's rasterization): pass 1
/// at the centre (the single-pass image), then Roberts' R2 low-discrepancy
/// sequence, so the mean of n passes covers each pixel's square evenly, as
/// the CPU's jittered samples do, and edges and small highlights converge
/// to their pixel averages instead of to one point sample.
pub fn pass_jitter(pass: u32) -> Vec2 {
    const G: [f64; 2] = [0.754_877_666_246_692_7, 0.569_840_290_998_053_2];
    let k = pass.saturating_sub(1) as f64;
    Vec2::new(((0.5 + k * G[0]).fract() - 0.5) as f32, ((0.5 + k * G[1]).fract() - 0.5) as f32)
}

/// The running mean of the passes' images, summed in f64 (a million passes
/// of f32 sums would lose the small ones).
#[derive(Clone, Debug)]
pub struct ImageMean {
    width: u32,
    height: u32,
    sums: Vec<[f64; 3]>,
    /// The sums of the odd passes (1, 3, 5, …) alone: one of the two
    /// interleaved half-images of [`ImageMean::noise_estimate`].
    odd_sums: Vec<[f64; 3]>,
    passes: u32,
}

impl ImageMean {
    pub fn new(width: u32, height: u32) -> Self {
        let zeros = vec![[0.0; 3]; (width * height) as usize];
        ImageMean { width, height, sums: zeros.clone(), odd_sums: zeros, passes: 0 }
    }

    pub fn add(&mut self, image: &Image) {
        assert_eq!((image.width, image.height), (self.width, self.height), "a pass of another size");
        let odd = self.passes % 2 == 0;
        for ((sum, odd_sum), p) in self.sums.iter_mut().zip(&mut self.odd_sums).zip(&image.pixels) {
            for c in 0..3 {
                sum[c] += p[c] as f64;
                if odd {
                    odd_sum[c] += p[c] as f64;
                }
            }
        }
        self.passes += 1;
    }

    /// The mean's relative error as its own passes estimate it, in the
    /// project's metric (RMS error over the mean): the means A of the odd
    /// passes and B of the even ones differ by noise alone, so with k_a and
    /// k_b passes in them the mean of all n carries a squared error of
    /// about mean((A − B)²)·k_a·k_b/n² per value (a quarter when the halves
    /// are equal). It sees noise, not bias: a photon mapper's blur, which
    /// every pass shares, is not in it; nor the lights' own pixels
    /// ([`noise_from_sums`]). None before 2 passes or for a black image.
    pub fn noise_estimate(&self) -> Option<f64> {
        noise_from_sums(self.width as usize, self.passes, &self.sums, &self.odd_sums)
    }

    pub fn passes(&self) -> u32 {
        self.passes
    }

    /// The per-pixel sums of the passes so far (row-major).
    pub fn sums(&self) -> &[[f64; 3]] {
        &self.sums
    }

    /// The mean so far (black before the first pass).
    pub fn mean(&self) -> Image {
        mean_of_sums(self.width, self.height, &self.sums, self.passes)
    }
}

/// The mean image of `passes` passes whose per-pixel sums are `sums`
/// (black for none): [`ImageMean::mean`], and a merge of shards, which
/// must divide exactly as a single run does.
pub fn mean_of_sums(width: u32, height: u32, sums: &[[f64; 3]], passes: u32) -> Image {
    assert_eq!(sums.len(), (width * height) as usize, "sums of another size");
    let mut image = Image::new(width, height);
    let n = passes.max(1) as f64;
    for (p, s) in image.pixels.iter_mut().zip(sums) {
        *p = Vec3::new((s[0] / n) as f32, (s[1] / n) as f32, (s[2] / n) as f32);
    }
    image
}

/// [`ImageMean::noise_estimate`] from the sums of all `passes` passes and
/// of the odd ones, pixel by pixel (row-major, `width` wide): also what the
/// GPU's running mean keeps. The lights' own pixels are left out as the
/// metric's `without_lights` leaves them out (at least 50 times the
/// median value, grown by one pixel): a directly seen light's edges carry
/// sub-pixel noise hundreds of times the scene's, clipped to white in a
/// PNG, that would keep a render going long after the rest looks done.
pub fn noise_from_sums(width: usize, passes: u32, sums: &[[f64; 3]], odd_sums: &[[f64; 3]]) -> Option<f64> {
    if passes < 2 || sums.is_empty() {
        return None;
    }
    let n = passes as f64;
    let (k_a, k_b) = ((n / 2.0).ceil(), (n / 2.0).floor());
    let mut values: Vec<f64> = sums.iter().flatten().copied().collect();
    let middle = values.len() / 2;
    let median = *values.select_nth_unstable_by(middle, f64::total_cmp).1;
    let lit: Vec<bool> = sums.iter().map(|s| s.iter().copied().fold(0.0, f64::max) >= 50.0 * median).collect();
    let height = sums.len() / width.max(1);
    let near_light = |i: usize| {
        let (x, y) = ((i % width) as i64, (i / width) as i64);
        (-1..=1).any(|dy| {
            (-1..=1).any(|dx| {
                let (nx, ny) = (x + dx, y + dy);
                (0..width as i64).contains(&nx)
                    && (0..height as i64).contains(&ny)
                    && lit[(ny * width as i64 + nx) as usize]
            })
        })
    };
    let (mut squares, mut total, mut count) = (0.0f64, 0.0f64, 0usize);
    for (i, (sum, odd)) in sums.iter().zip(odd_sums).enumerate() {
        if median > 0.0 && near_light(i) {
            continue;
        }
        for c in 0..3 {
            let (a, b) = (odd[c] / k_a, (sum[c] - odd[c]) / k_b);
            squares += (a - b) * (a - b);
            total += sum[c];
            count += 1;
        }
    }
    let mean = total / n / count.max(1) as f64;
    (mean > 0.0).then(|| (squares / count as f64 * k_a * k_b / (n * n)).sqrt() / mean)
}

#[cfg(test)]
mod tests;

/// Pass `pass` of `photon-cpu`: a fresh set of `photons` paths traced with
/// `pass_seed`, estimated at the schedules' radii (pixels sampled with the
/// same seed). Returns the image and its non-finite samples dropped.
pub fn photon_cpu_pass(
    scene: &crate::scene::Scene,
    settings: &crate::render::photon_cpu::PhotonCpuSettings,
    photons: u64,
    schedules: &Schedules,
    pass: u32,
) -> (Image, u64) {
    let silent = crate::progress::Silent;
    let traced = crate::photon::trace_photons(scene, &pass_trace_settings(photons, settings.seed, pass), &silent);
    photon_cpu_estimate_pass(scene, settings, &traced, schedules, pass)
}

/// What pass `pass` of a run seeded with `seed` traces: `photons` paths
/// with `pass_seed`.
pub fn pass_trace_settings(photons: u64, seed: u64, pass: u32) -> crate::photon::TraceSettings {
    crate::photon::TraceSettings { photons, seed: pass_seed(seed, pass), ..Default::default() }
}

/// `photon_cpu_pass` with the pass's photons `traced` given (traced with
/// `pass_trace_settings`, on whichever device).
pub fn photon_cpu_estimate_pass(
    scene: &crate::scene::Scene,
    settings: &crate::render::photon_cpu::PhotonCpuSettings,
    traced: &crate::photon::TracedPhotons,
    schedules: &Schedules,
    pass: u32,
) -> (Image, u64) {
    use crate::render::photon_cpu::{PhotonCpuRenderer, PhotonCpuSettings};
    let seed = pass_seed(settings.seed, pass);
    let silent = crate::progress::Silent;
    let [global, caustic, volume] = schedules.radii(pass);
    let settings = PhotonCpuSettings {
        radius: Some(global),
        caustic_radius: Some(caustic),
        volume_radius: Some(volume),
        seed,
        ..settings.clone()
    };
    PhotonCpuRenderer::new(scene, traced, &settings).render(&silent)
}

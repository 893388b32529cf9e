//! All the media of a scene together (METHOD.md §5): media filling the whole
//! scene and media bounded by region meshes, whose coefficients add where
//! they overlap (the heterogeneous case, eq. 5.25–5.30). Along a ray the
//! coefficients are piecewise constant; free flights are sampled against the
//! summed optical depth across those pieces.
//!
//! Each volume photon remembers which phase function scattered it (a "phase
//! slot", at most [`MAX_PHASES`] distinct ones per scene): the photons that
//! medium i scatters have density ∝ σ_s,i, so weighting each photon by its
//! own phase function estimates Σ_i σ_s,i p_i exactly, with no mixing rule.

use super::region::{Crossing, RegionMesh};
use super::{Medium, Phase};
use crate::material::{Rgb, mean};
use glam::Vec3;

/// Distinct phase functions a scene may use (two bits in a volume photon).
pub const MAX_PHASES: usize = 4;
/// Media a scene may hold (one bit each in a mask).
pub const MAX_MEDIA: usize = 32;

#[derive(Clone, Debug)]
pub struct MediumEntry {
    pub medium: Medium,
    /// The closed mesh bounding it; none: the whole scene.
    pub region: Option<RegionMesh>,
    /// Index of its phase function in [`Media::phases`].
    pub phase_slot: u8,
}

#[derive(Clone, Debug, Default)]
pub struct Media {
    entries: Vec<MediumEntry>,
    phases: Vec<Phase>,
}

/// A stretch [t0, t1) of a ray inside the media whose bits `mask` holds.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Segment {
    pub t0: f32,
    pub t1: f32,
    pub mask: u32,
}

/// Where a sampled free flight ends.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Flight {
    /// An interaction at `distance` in the media of `mask`; the photon's
    /// power is multiplied by `weight` (all ones in grey media). `tau_bar`
    /// is the optical depth in the mean channel up to it (the depth the
    /// sampler drew), on which the flight's density depends.
    Interaction { distance: f32, weight: Rgb, mask: u32, tau_bar: f32 },
    /// No interaction before the end of the ray; power × `weight`;
    /// `tau_bar` the mean-channel optical depth of the whole ray.
    Passed { weight: Rgb, tau_bar: f32 },
}

impl Media {
    pub fn new(media: Vec<(Medium, Option<RegionMesh>)>) -> Result<Media, String> {
        if media.len() > MAX_MEDIA {
            return Err(format!("{} media given; at most {MAX_MEDIA} are supported", media.len()));
        }
        let mut phases: Vec<Phase> = Vec::new();
        let mut entries = Vec::with_capacity(media.len());
        for (medium, region) in media {
            let slot = match phases.iter().position(|p| *p == medium.phase) {
                Some(slot) => slot,
                None => {
                    if phases.len() == MAX_PHASES {
                        return Err(format!(
                            "more than {MAX_PHASES} distinct phase functions; media must share at most {MAX_PHASES}"
                        ));
                    }
                    phases.push(medium.phase);
                    phases.len() - 1
                }
            };
            entries.push(MediumEntry { medium, region, phase_slot: slot as u8 });
        }
        Ok(Media { entries, phases })
    }

    /// One medium filling the whole scene.
    pub fn homogeneous(medium: Medium) -> Media {
        Media::new(vec![(medium, None)]).expect("one medium always fits")
    }

    pub fn is_empty(&self) -> bool {
        self.entries.is_empty()
    }

    pub fn entries(&self) -> &[MediumEntry] {
        &self.entries
    }

    pub fn phases(&self) -> &[Phase] {
        &self.phases
    }

    pub fn has_regions(&self) -> bool {
        self.entries.iter().any(|e| e.region.is_some())
    }

    /// The media that fill the whole scene.
    pub fn global_mask(&self) -> u32 {
        self.entries.iter().enumerate().filter(|(_, e)| e.region.is_none()).fold(0, |m, (i, _)| m | 1 << i)
    }

    fn sum(&self, mask: u32, coefficient: impl Fn(&Medium) -> Rgb) -> Rgb {
        let mut total = Rgb::ZERO;
        let mut bits = mask;
        while bits != 0 {
            total += coefficient(&self.entries[bits.trailing_zeros() as usize].medium);
            bits &= bits - 1;
        }
        total
    }

    pub fn sigma_t(&self, mask: u32) -> Rgb {
        self.sum(mask, Medium::sigma_t)
    }

    pub fn sigma_s(&self, mask: u32) -> Rgb {
        self.sum(mask, |m| m.sigma_s)
    }

    /// σ_t of the media filling the whole scene.
    pub fn global_sigma_t(&self) -> Rgb {
        self.sigma_t(self.global_mask())
    }

    /// ∫ σ_t along `origin + t·dir`, t in [0, `length`] (the identity of
    /// `region`'s module doc for each region).
    pub fn optical_depth(&self, origin: Vec3, dir: Vec3, length: f32) -> Rgb {
        let mut tau = Rgb::ZERO;
        for entry in &self.entries {
            let inside = match &entry.region {
                None => length,
                Some(region) => region.inside_length(origin, dir, length),
            };
            if inside > 0.0 {
                tau += entry.medium.sigma_t() * inside;
            }
        }
        tau
    }

    /// e^(−τ) along the segment (eq. 5.8, eq. 5.26 across regions).
    /// Inlined: every shadow ray asks, and in a scene without media the
    /// call cost more than the answer (0.7% of a path on the Cornell box).
    #[inline]
    pub fn transmittance(&self, origin: Vec3, dir: Vec3, length: f32) -> Rgb {
        if self.is_empty() { Rgb::ONE } else { self.transmittance_through_media(origin, dir, length) }
    }

    fn transmittance_through_media(&self, origin: Vec3, dir: Vec3, length: f32) -> Rgb {
        (-self.optical_depth(origin, dir, length)).exp()
    }

    /// The media at `point`.
    pub fn mask_at(&self, point: Vec3) -> u32 {
        self.entries.iter().enumerate().fold(0, |mask, (i, e)| match &e.region {
            Some(region) if !region.contains(point) => mask,
            _ => mask | 1 << i,
        })
    }

    /// Splits `origin + t·dir`, t in [0, `t_max`], into pieces of constant
    /// media (pieces outside every medium included, with mask 0).
    pub fn segments(&self, origin: Vec3, dir: Vec3, t_max: f32, out: &mut Vec<Segment>) {
        out.clear();
        let global = self.global_mask();
        if !self.has_regions() {
            out.push(Segment { t0: 0.0, t1: t_max, mask: global });
            return;
        }
        let mut events: Vec<(Crossing, usize)> = Vec::new();
        let mut winding = [0i32; MAX_MEDIA];
        let mut scratch = Vec::new();
        for (i, entry) in self.entries.iter().enumerate() {
            if let Some(region) = &entry.region {
                scratch.clear();
                region.crossings(origin, dir, &mut scratch);
                // The net number of exits ahead is the winding at the origin.
                winding[i] = scratch.iter().map(|c| c.sign).sum();
                events.extend(scratch.iter().map(|c| (*c, i)));
            }
        }
        events.sort_by(|a, b| a.0.t.total_cmp(&b.0.t));
        let mask_of = |winding: &[i32; MAX_MEDIA]| {
            (0..self.entries.len()).filter(|&i| winding[i] > 0).fold(global, |m, i| m | 1 << i)
        };
        let mut t0 = 0.0;
        let mut mask = mask_of(&winding);
        for (crossing, i) in events {
            if crossing.t >= t_max {
                break;
            }
            if crossing.t > t0 {
                out.push(Segment { t0, t1: crossing.t, mask });
                t0 = crossing.t;
            }
            winding[i] -= crossing.sign;
            mask = mask_of(&winding);
        }
        out.push(Segment { t0, t1: t_max, mask });
    }

    /// Samples a free flight along `origin + t·dir` up to `t_max` from
    /// uniform `xi` (eq. 5.10 against the summed optical depth): the target
    /// optical depth −ln(1−ξ) is spent in the mean channel σ̄, and per-channel
    /// weights T_c/T̄ (× σ_t,c/σ̄ at an interaction) keep RGB unbiased.
    pub fn sample_flight(&self, origin: Vec3, dir: Vec3, t_max: f32, xi: f32) -> Flight {
        // Photon tracing calls this per flight: media filling the scene are
        // one piece, so skip the allocation and crossing search for them.
        let single;
        let mut segments = Vec::new();
        let pieces: &[Segment] = if self.has_regions() {
            self.segments(origin, dir, t_max, &mut segments);
            &segments
        } else {
            single = [Segment { t0: 0.0, t1: t_max, mask: self.global_mask() }];
            &single
        };
        let target = -(1.0 - xi).ln();
        let mut tau_bar = 0.0f32;
        let mut tau = Rgb::ZERO;
        for s in pieces {
            let sigma_t = self.sigma_t(s.mask);
            let sigma_bar = mean(sigma_t);
            if sigma_bar <= 0.0 {
                continue;
            }
            let length = s.t1 - s.t0;
            if tau_bar + sigma_bar * length > target {
                let d = (target - tau_bar) / sigma_bar;
                let tau_c = tau + sigma_t * d;
                let weight = (-(tau_c - Rgb::splat(target))).exp() * sigma_t / sigma_bar;
                return Flight::Interaction { distance: s.t0 + d, weight, mask: s.mask, tau_bar: target };
            }
            tau_bar += sigma_bar * length;
            tau += sigma_t * length;
        }
        Flight::Passed { weight: (-(tau - Rgb::splat(tau_bar))).exp(), tau_bar }
    }

    /// The albedo roulette at an interaction in the media of `mask`
    /// (eq. 5.12): the scattering probability Λ = mean(σ_s)/mean(σ_t), and
    /// the per-channel factor (σ_s/σ_t)/Λ a scattered photon's power takes.
    pub fn scattering(&self, mask: u32) -> (f32, Rgb) {
        let sigma_t = self.sigma_t(mask);
        let sigma_s = self.sigma_s(mask);
        let lambda = if mean(sigma_t) > 0.0 { mean(sigma_s) / mean(sigma_t) } else { 0.0 };
        if lambda <= 0.0 {
            return (0.0, Rgb::ZERO);
        }
        let albedo = Rgb::select(sigma_t.cmpgt(Rgb::ZERO), sigma_s / sigma_t, Rgb::ZERO);
        (lambda, albedo / lambda)
    }

    /// Picks the medium that scatters at a point inside the media of `mask`,
    /// with probability ∝ its mean σ_s (uniform `xi`).
    pub fn choose_scatterer(&self, mask: u32, xi: f32) -> &MediumEntry {
        let total = mean(self.sigma_s(mask));
        let mut acc = 0.0;
        let mut bits = mask;
        let mut last = mask.trailing_zeros() as usize;
        while bits != 0 {
            let i = bits.trailing_zeros() as usize;
            bits &= bits - 1;
            acc += mean(self.entries[i].medium.sigma_s) / total;
            last = i;
            if xi < acc {
                break;
            }
        }
        &self.entries[last]
    }
}

/// The optical depth along one ray, tabulated once so that many
/// transmittance lookups along it (one per volume photon) stay cheap.
pub struct MediaAlong {
    /// Per piece: where it starts, its σ_t, and τ accumulated before it.
    pieces: Vec<(f32, Rgb, Rgb)>,
}

impl MediaAlong {
    pub fn new(media: &Media, origin: Vec3, dir: Vec3, length: f32) -> MediaAlong {
        let mut segments = Vec::new();
        media.segments(origin, dir, length, &mut segments);
        let mut tau = Rgb::ZERO;
        let pieces = segments
            .iter()
            .map(|s| {
                let sigma_t = media.sigma_t(s.mask);
                let piece = (s.t0, sigma_t, tau);
                tau += sigma_t * (s.t1 - s.t0);
                piece
            })
            .collect();
        MediaAlong { pieces }
    }

    /// ∫₀ˢ σ_t; `s` at most the length given to `new`.
    pub fn optical_depth(&self, s: f32) -> Rgb {
        let i = self.pieces.partition_point(|p| p.0 <= s).saturating_sub(1);
        match self.pieces.get(i) {
            Some(&(t0, sigma_t, tau)) => tau + sigma_t * (s - t0).max(0.0),
            None => Rgb::ZERO,
        }
    }

    pub fn transmittance(&self, s: f32) -> Rgb {
        (-self.optical_depth(s)).exp()
    }
}

#[cfg(test)]
mod tests {
    use super::super::region::box_triangles;
    use super::*;
    use crate::sampling::Rng;

    fn grey(sigma_a: f32, sigma_s: f32) -> Medium {
        Medium { sigma_a: Vec3::splat(sigma_a), sigma_s: Vec3::splat(sigma_s), phase: Phase::Schlick { k: 0.0 } }
    }

    fn region(min: Vec3, max: Vec3) -> Option<RegionMesh> {
        Some(RegionMesh::new(box_triangles(min, max)).unwrap())
    }

    /// Slab x in [0,1] (σ_t = 2) overlapping slab x in [0.5, 2] (σ_t = 0.5).
    fn two_slabs() -> Media {
        let big = 50.0;
        Media::new(vec![
            (grey(0.5, 1.5), region(Vec3::new(0.0, -big, -big), Vec3::new(1.0, big, big))),
            (grey(0.1, 0.4), region(Vec3::new(0.5, -big, -big), Vec3::new(2.0, big, big))),
        ])
        .unwrap()
    }

    /// The slab test of issue #4 on the CPU: e^(−σ_t d) through one slab,
    /// the sum where two overlap, and with the eye inside a region.
    #[test]
    fn slab_transmittance_is_beer_lambert() {
        let media = two_slabs();
        let o = Vec3::new(-1.0, 0.2, 0.1);
        let t = media.transmittance(o, Vec3::X, 10.0).x;
        let want = (-(2.0f32 * 1.0 + 0.5 * 1.5)).exp();
        assert!((t - want).abs() < 1e-6, "{t} vs {want}");
        // Eye inside both slabs, looking along +x for 0.8 units: 0.5 in the
        // first (σ 2 + 0.5 overlapping), then 0.3 in the second only.
        let inside = Vec3::new(0.7, 0.0, 0.0);
        let tau = media.optical_depth(inside, Vec3::X, 0.8).x;
        assert!((tau - (0.3 * 2.5 + 0.5 * 0.5)).abs() < 1e-5, "{tau}");
        // Oblique: the path length scales by 1/cos.
        let dir = Vec3::new(1.0, 1.0, 0.0).normalize();
        let tau = media.optical_depth(Vec3::new(-0.5, 0.0, 0.0), dir, 20.0).x;
        let want = 2.0f32.sqrt() * (2.0 * 1.0 + 0.5 * 1.5);
        assert!((tau - want).abs() < 1e-4, "{tau} vs {want}");
    }

    #[test]
    fn segments_follow_the_regions() {
        let media = two_slabs();
        let mut s = Vec::new();
        media.segments(Vec3::new(-1.0, 0.0, 0.0), Vec3::X, 4.0, &mut s);
        let masks: Vec<u32> = s.iter().map(|s| s.mask).collect();
        assert_eq!(masks, vec![0, 1, 3, 2, 0]);
        assert!((s[2].t0 - 1.5).abs() < 1e-6 && (s[2].t1 - 2.0).abs() < 1e-6);
        assert_eq!(media.mask_at(Vec3::new(0.75, 3.0, 1.0)), 3);
        // The tabulated optical depth agrees with the direct sum.
        let along = MediaAlong::new(&media, Vec3::new(-1.0, 0.0, 0.0), Vec3::X, 4.0);
        for s in [0.0, 0.3, 1.2, 1.7, 2.9, 4.0] {
            let direct = media.optical_depth(Vec3::new(-1.0, 0.0, 0.0), Vec3::X, s).x;
            assert!((along.optical_depth(s).x - direct).abs() < 1e-5, "{s}: {} vs {direct}", along.optical_depth(s));
        }
    }

    #[test]
    fn free_flights_have_mean_one_over_sigma_t() {
        let media = Media::homogeneous(grey(0.3, 0.9));
        let mut rng = Rng::for_item(51, 0);
        let n = 200_000;
        let mut sum = 0.0f64;
        for _ in 0..n {
            match media.sample_flight(Vec3::ZERO, Vec3::X, f32::INFINITY, rng.next_f32()) {
                Flight::Interaction { distance, weight, mask, .. } => {
                    assert!((weight - Vec3::ONE).abs().max_element() < 1e-5 && mask == 1, "{weight} {mask}");
                    sum += distance as f64;
                }
                Flight::Passed { .. } => panic!("an infinite medium always interacts"),
            }
        }
        let mean = sum / n as f64;
        assert!((mean - 1.0 / 1.2).abs() < 0.01, "mean free path {mean}");
    }

    /// Flights through the two overlapping slabs pass with probability
    /// e^(−τ), and interactions land in each piece in proportion to
    /// ∫ σ_t T over it.
    #[test]
    fn flights_across_regions_follow_the_summed_optical_depth() {
        let media = two_slabs();
        let o = Vec3::new(-1.0, 0.0, 0.0);
        let mut rng = Rng::for_item(55, 0);
        let n = 200_000;
        let mut passed = 0;
        let mut in_overlap = 0;
        for _ in 0..n {
            match media.sample_flight(o, Vec3::X, 4.0, rng.next_f32()) {
                Flight::Passed { .. } => passed += 1,
                Flight::Interaction { mask, .. } => in_overlap += (mask == 3) as u32,
            }
        }
        let t_all = media.transmittance(o, Vec3::X, 4.0).x as f64;
        assert!((passed as f64 / n as f64 - t_all).abs() < 0.003);
        // Overlap x in [0.5,1]: enters it with T = e^(−1), leaves with e^(−2.25).
        let want = (-1.0f64).exp() - (-2.25f64).exp();
        assert!((in_overlap as f64 / n as f64 - want).abs() < 0.004, "{in_overlap} vs {want}");
    }

    /// A flight's τ̄ is the mean-channel optical depth `optical_depth` gives
    /// up to where it stopped, or over the whole ray when it passed (what
    /// vertex connection and merging's densities take from it).
    #[test]
    fn a_flights_mean_optical_depth_is_the_segments() {
        let media = two_slabs();
        let o = Vec3::new(-1.0, 0.0, 0.0);
        let mut rng = Rng::for_item(56, 0);
        let (mut stopped, mut passed) = (0, 0);
        for _ in 0..2_000 {
            let (length, tau_bar) = match media.sample_flight(o, Vec3::X, 4.0, rng.next_f32()) {
                Flight::Interaction { distance, tau_bar, .. } => {
                    stopped += 1;
                    (distance, tau_bar)
                }
                Flight::Passed { tau_bar, .. } => {
                    passed += 1;
                    (4.0, tau_bar)
                }
            };
            let want = mean(media.optical_depth(o, Vec3::X, length));
            assert!((tau_bar - want).abs() <= 1e-5 * want.max(1.0), "{tau_bar} vs {want} at {length}");
        }
        assert!(stopped > 100 && passed > 100, "{stopped} stopped, {passed} passed");
    }

    /// With RGB coefficients the weighted flights stay unbiased: the expected
    /// weight of photons passing a slab is the per-channel transmittance.
    #[test]
    fn rgb_flight_weights_are_unbiased() {
        let m = Medium {
            sigma_a: Vec3::new(0.1, 0.4, 0.9),
            sigma_s: Vec3::new(0.5, 0.5, 0.2),
            phase: Phase::Schlick { k: 0.0 },
        };
        let media = Media::new(vec![(m, region(Vec3::new(0.0, -9.0, -9.0), Vec3::new(0.8, 9.0, 9.0)))]).unwrap();
        let o = Vec3::new(-0.5, 0.0, 0.0);
        let mut rng = Rng::for_item(54, 0);
        let n = 400_000;
        let mut passed = Vec3::ZERO;
        for _ in 0..n {
            if let Flight::Passed { weight, .. } = media.sample_flight(o, Vec3::X, 2.0, rng.next_f32()) {
                passed += weight;
            }
        }
        let got = passed / n as f32;
        let want = m.transmittance(0.8);
        assert!(((got - want) / want).abs().max_element() < 0.01, "{got} vs {want}");
    }

    #[test]
    fn scatterers_are_chosen_by_sigma_s() {
        let media = two_slabs();
        let mut rng = Rng::for_item(56, 0);
        let n = 100_000;
        let first = (0..n).filter(|_| media.choose_scatterer(3, rng.next_f32()).medium.sigma_s.x == 1.5).count();
        assert!((first as f64 / n as f64 - 1.5 / 1.9).abs() < 0.005);
    }

    #[test]
    fn phases_share_slots() {
        let hg = |g| Medium { phase: Phase::HenyeyGreenstein { g }, ..grey(0.1, 0.1) };
        let media = Media::new(vec![(hg(0.5), None), (hg(0.2), None), (hg(0.5), None)]).unwrap();
        let slots: Vec<u8> = media.entries().iter().map(|e| e.phase_slot).collect();
        assert_eq!((slots, media.phases().len()), (vec![0, 1, 0], 2));
        let many = (0..5).map(|i| (hg(i as f32 * 0.1), None)).collect();
        assert!(Media::new(many).unwrap_err().contains("phase functions"));
    }
}

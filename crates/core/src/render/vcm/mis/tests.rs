//! The recursive weights against Veach's explicit balance heuristic: on
//! random paths of 2 to 5 segments (an area light, Lambertian vertices
//! with Russian roulette, a pinhole camera; with media, some vertices in a
//! medium and every segment attenuated), every strategy that makes the
//! path (the camera hitting the light, next-event estimation, every
//! connection, light tracing, a merge at every inner vertex) gets the weight
//! p^β / Σ p^β computed from the vertices' densities directly, and the
//! weights sum to one. The renderer (vcm/mod.rs) builds its subpath sums with the
//! same calls as `subpaths` below.

use super::*;
use crate::sampling::Rng;
use glam::Vec3;

/// A path x_0 (on the light) … x_k (the eye).
struct Path {
    x: Vec<Vec3>,
    /// Normals of x_0..x_{k−1}.
    n: Vec<Vec3>,
    /// σ̄ of the inner vertices that lie in a medium (isotropic phase
    /// function there), None on surfaces (index by vertex; x_0 never).
    medium: Vec<Option<f32>>,
    /// e^−τ̄ of segment x_j x_{j+1} (index j).
    passes: Vec<f32>,
    /// Russian-roulette continuation of x_1..x_{k−1} (index by vertex).
    continuation: Vec<f32>,
    area: f32,
    pick: f32,
    forward: Vec3,
    image_plane: f32,
}

impl Path {
    fn random(k: usize, media: bool, rng: &mut Rng) -> Path {
        let mut point = || Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) * 2.0 - 1.0;
        let x: Vec<Vec3> = (0..=k).map(|_| point()).collect();
        let n: Vec<Vec3> = (0..k).map(|_| point().normalize()).collect();
        let medium =
            (0..k).map(|j| (media && j > 0 && rng.next_f32() < 0.4).then(|| 0.3 + 3.0 * rng.next_f32())).collect();
        let passes = (0..k).map(|_| if media { 0.2 + 0.8 * rng.next_f32() } else { 1.0 }).collect();
        let continuation = (0..k).map(|_| 0.2 + 0.8 * rng.next_f32()).collect();
        let forward = (x[k - 1] - x[k]).normalize();
        let image_plane = 40.0 + 100.0 * rng.next_f32();
        Path { x, n, medium, passes, continuation, area: 0.3, pick: 0.7, forward, image_plane }
    }

    fn k(&self) -> usize {
        self.x.len() - 1
    }

    fn dir(&self, from: usize, to: usize) -> Vec3 {
        (self.x[to] - self.x[from]).normalize()
    }

    fn d2(&self, a: usize, b: usize) -> f32 {
        (self.x[a] - self.x[b]).length_squared()
    }

    fn in_medium(&self, at: usize) -> bool {
        self.medium.get(at).is_some_and(|m| m.is_some())
    }

    fn pass(&self, a: usize, b: usize) -> f32 {
        self.passes[a.min(b)]
    }

    /// |cos| at vertex `at` toward vertex `to` (1 in a medium).
    fn cos(&self, at: usize, to: usize) -> f32 {
        if self.in_medium(at) { 1.0 } else { self.n[at].dot(self.dir(at, to)).abs() }
    }

    /// [`SubpathMis::arrive`]'s `arrival` at `at` on a ray from `from`.
    fn arrival(&self, at: usize, from: usize) -> f32 {
        self.medium.get(at).copied().flatten().unwrap_or_else(|| self.cos(at, from)) * self.pass(at, from)
    }

    /// Its `departure` for a ray that left `from` toward `to`.
    fn departure(&self, from: usize, to: usize) -> f32 {
        self.medium.get(from).copied().flatten().unwrap_or(1.0) * self.pass(from, to)
    }

    /// Sampling density at `at` of leaving toward `to` (Lambertian, or
    /// isotropic in a medium), roulette included.
    fn pdf(&self, at: usize, to: usize) -> f32 {
        let lobe = if self.in_medium(at) { 0.25 } else { self.cos(at, to) };
        lobe / PI * self.continuation[at]
    }

    fn camera_pdf_w(&self) -> f32 {
        let cos = self.forward.dot(self.dir(self.k(), self.k() - 1));
        let to_plane = self.image_plane / cos;
        to_plane * to_plane / cos
    }

    fn camera_pdf_a(&self) -> f32 {
        let k = self.k();
        self.camera_pdf_w() * self.arrival(k - 1, k) / self.d2(k - 1, k)
    }

    /// Per unit area (volume), the light side choosing x_j and the eye side choosing x_j.
    fn densities(&self) -> (Vec<f32>, Vec<f32>) {
        let k = self.k();
        let mut forward = vec![self.pick / self.area];
        for j in 1..k {
            let pdf_w = if j == 1 { self.cos(0, 1) / PI } else { self.pdf(j - 1, j) };
            forward.push(pdf_w * self.arrival(j, j - 1) / self.d2(j - 1, j));
        }
        let mut reverse = vec![0.0; k];
        reverse[k - 1] = self.camera_pdf_a();
        for j in (0..k - 1).rev() {
            reverse[j] = self.pdf(j + 1, j) * self.arrival(j, j + 1) / self.d2(j, j + 1);
        }
        (forward, reverse)
    }

    fn eta(&self, f: &Factors, at: usize) -> f32 {
        f.eta(self.in_medium(at))
    }
}

/// The light subpath's sums at x_1..x_{k−1} and the eye's at x_0..x_{k−1}.
fn subpaths(p: &Path, f: &Factors) -> (Vec<SubpathMis>, Vec<SubpathMis>) {
    let k = p.k();
    let emission = p.pick / p.area * p.cos(0, 1) / PI;
    let mut light = vec![SubpathMis::light_start(emission, p.pick / p.area, p.cos(0, 1), false, f)];
    for j in 1..k {
        let mut s = *light.last().unwrap();
        if j > 1 {
            s.scatter(p.cos(j - 1, j), p.pdf(j - 1, j), p.pdf(j - 1, j - 2), p.eta(f, j - 1), f);
        }
        s.arrive(p.d2(j - 1, j), p.arrival(j, j - 1), p.departure(j - 1, j), true);
        light.push(s);
    }
    let mut camera = vec![SubpathMis::camera_start(p.camera_pdf_w(), f); k];
    let mut s = camera[0];
    for j in (0..k).rev() {
        if j < k - 1 {
            let from = if j + 2 == k { k } else { j + 2 };
            // The eye's vertex x_{j+1} scatters toward x_j, having come from `from`.
            s.scatter(p.cos(j + 1, j), p.pdf(j + 1, j), p.pdf(j + 1, from), p.eta(f, j + 1), f);
        }
        s.arrive(p.d2(j, j + 1), p.arrival(j, j + 1), p.departure(j + 1, j), true);
        camera[j] = s;
    }
    (light, camera)
}

/// (name, recursive weight, explicit weight) of every strategy.
fn weights(p: &Path, f: &Factors, connect: bool, merge: bool) -> Vec<(String, f64, f64)> {
    let k = p.k();
    let (fwd, rev) = p.densities();
    let (light, camera) = subpaths(p, f);
    // Count × density of every strategy, as Veach's formula has them.
    let vc = |s: usize| -> f64 {
        (0..s).map(|j| fwd[j] as f64).product::<f64>() * (s..k).map(|j| rev[j] as f64).product::<f64>()
    };
    let mut out = Vec::new();
    let mut explicit: Vec<(String, f64, f64)> = Vec::new();
    if connect {
        let direct = p.pick / p.area;
        let emission = direct * p.cos(0, 1) / PI;
        explicit.push(("hit".into(), emitter_hit(&camera[0], direct, emission) as f64, vc(0)));
        let nee = NextEvent {
            bsdf_dir_pdf_w: p.pdf(1, 0),
            bsdf_rev_pdf_w: p.pdf(1, 2),
            direct_pdf_w: direct * p.d2(0, 1) / p.cos(0, 1),
            emission_pdf_w: emission,
            vertex_arrival: p.arrival(1, 0),
            passes: p.pass(0, 1),
            cos_at_light: p.cos(0, 1),
        };
        explicit.push(("next event".into(), next_event(&camera[1], &nee, p.eta(f, 1)) as f64, vc(1)));
        for s in 2..k {
            // Light vertex x_{s−1}, eye vertex x_s.
            let (l, c) = (s - 1, s);
            let d2 = p.d2(l, c);
            let densities = Connection {
                camera_dir_pdf_a: p.pdf(c, l) * p.arrival(l, c) / d2,
                camera_rev_pdf_w: p.pdf(c, c + 1),
                light_dir_pdf_a: p.pdf(l, c) * p.arrival(c, l) / d2,
                light_rev_pdf_w: p.pdf(l, l - 1),
                camera_eta: p.eta(f, c),
                light_eta: p.eta(f, l),
            };
            explicit.push((format!("connect {s}"), connection(&camera[c], &light[l], &densities) as f64, vc(s)));
        }
        let lt = light_tracing(&light[k - 1], p.camera_pdf_a(), p.pdf(k - 1, k - 2), p.eta(f, k - 1), f) as f64;
        explicit.push(("light tracing".into(), lt, f.light_paths as f64 * vc(k)));
    }
    if merge {
        for i in 1..k {
            let eta = p.eta(f, i);
            let w = super::merge(&camera[i], &light[i], p.pdf(i, i - 1), p.pdf(i, i + 1), eta, f) as f64;
            let raw_eta = (f.normalization(p.in_medium(i)) as f64).recip();
            explicit.push((format!("merge at {i}"), w, raw_eta * fwd[i] as f64 * vc(i)));
        }
    }
    // Veach's heuristic of power β over the counts × densities.
    let power = |p: f64| p.powi(super::HEURISTIC_POWER);
    let total: f64 = explicit.iter().map(|(_, _, p)| power(*p)).sum();
    for (name, w, density) in explicit {
        out.push((name, w, power(density) / total));
    }
    out
}

fn check(connect: bool, merge: bool, media: bool) {
    let mut rng = Rng::for_item(11, connect as u64 * 4 + merge as u64 * 2 + media as u64);
    for k in 2..=5 {
        for trial in 0..200 {
            let p = Path::random(k, media, &mut rng);
            let (radius, volume_radius) = (0.01 + 0.2 * rng.next_f32(), 0.01 + 0.2 * rng.next_f32());
            let light_paths = 1000.0 + 60_000.0 * rng.next_f32();
            let f = Factors::new(radius, volume_radius, light_paths, connect, merge);
            let w = weights(&p, &f, connect, merge);
            let sum: f64 = w.iter().map(|(_, w, _)| w).sum();
            assert!((sum - 1.0).abs() < 1e-3, "k = {k}, trial {trial}: weights sum to {sum}: {w:?}");
            for (name, recursive, explicit) in &w {
                assert!(
                    (recursive - explicit).abs() < 1e-3 * explicit.max(1e-3),
                    "k = {k}, trial {trial}, {name}: recursive {recursive}, explicit {explicit}: {w:?}"
                );
            }
        }
    }
}

#[test]
fn weights_are_veachs_heuristic_and_sum_to_one() {
    check(true, true, false);
}

#[test]
fn without_merging_the_connections_sum_to_one() {
    check(true, false, false);
}

#[test]
fn without_connections_the_merges_sum_to_one() {
    check(false, true, false);
}

/// Paths with vertices in media (flight densities σ̄ e^−τ̄, a ball kernel
/// there, a disc on surfaces) and transmittance on every segment.
#[test]
fn with_medium_vertices_the_weights_are_veachs_heuristic() {
    check(true, true, true);
    check(true, false, true);
    check(false, true, true);
}

/// The bound that merging's roulette reads is one: no merge on a random
/// path (with or without media, connections on or off) weighs more.
#[test]
fn merge_bound_bounds_every_merge() {
    let mut rng = Rng::for_item(12, 0);
    for (connect, media) in [(true, false), (true, true), (false, false)] {
        for k in 2..=5 {
            for _ in 0..200 {
                let p = Path::random(k, media, &mut rng);
                let f = Factors::new(0.01 + 0.2 * rng.next_f32(), 0.01 + 0.2 * rng.next_f32(), 4096.0, connect, true);
                let (light, camera) = subpaths(&p, &f);
                for i in 1..k {
                    let eta = p.eta(&f, i);
                    let w = super::merge(&camera[i], &light[i], p.pdf(i, i - 1), p.pdf(i, i + 1), eta, &f);
                    let bound = super::merge_bound(&camera[i], eta, &f);
                    assert!(w <= bound * (1.0 + 1e-5), "k = {k}, vertex {i}: weight {w} above the bound {bound}");
                }
            }
        }
    }
}

//! `KHR_materials_sheen`: the "Charlie" sheen of the extension's
//! specification (Conty Estevez and Kulla 2017) over the glTF BRDF, as
//! [`Bsdf`]'s `sheen_color` and `sheen_roughness`:
//!
//! ```text
//! f       = f_sheen + S(θo, θi)·(f_diffuse + f_specular)
//! f_sheen = C·D(h)·V(θo, θi) / max(1, E(θo), E(θi))
//! D       = (2 + 1/α)·sin(θh)^(1/α) / 2π                 α = r²
//! V       = min(1, 1 / ((1 + Λ(θo) + Λ(θi))·4·cos θo·cos θi))
//! S       = min(1 − max(C)·Ê(θo), 1 − max(C)·Ê(θi))       Ê = min(E, 1)
//! ```
//!
//! with C the sheen colour, r its roughness (at least
//! [`MIN_SHEEN_ROUGHNESS`]), Λ the specification's fitted Charlie Λ, and
//! E(θ, r) the white sheen's directional albedo ∫ D·V·cos θi dωi, read from
//! [`SHEEN_ALBEDO`] (a table of quadratures, as the specification advises;
//! bilinear in (√cos θ, r)). V is clamped to 1 as in Khronos' sample
//! viewer.
//!
//! # Energy
//!
//! The fitted Λ makes the white lobe reflect more than arrives at grazing
//! views when it is smooth (E = 1.24 at cos θ = 0.02, r = 0.1): the lobe is
//! divided by max(1, E(θo), E(θi)), which keeps it reciprocal and its albedo
//! at most 1, and changes nothing where E ≤ 1 (every view from roughness
//! 0.2 up, and every view above 3° from the horizon at 0.1). The base is
//! dimmed by the specification's albedo scaling S (both directions, so
//! reciprocal): a white sheen over a white Lambertian base reflects at most
//! 1 (it loses what the min leaves out, as the specification's scaling
//! does).
//!
//! Under a clear coat (the specification layers the coat over the sheen)
//! the sheen is dimmed like the base's specular lobe, by √(T(θo)·T(θi)).
//!
//! # Sampling and the photon maps
//!
//! `sample` picks the sheen with probability ∝ max(C)·Ê(θo) against the
//! base's lobes and draws it uniformly over the hemisphere (the lobe peaks
//! toward the horizon, where a cosine-weighted density vanishes). Sheen is
//! always estimated from the photon maps (`f_gathered`), never followed.
//!
//! The WGSL twin is in `crates/gpu/src/wgsl/bsdf.wgsl`, pinned by
//! `crates/gpu/tests/bsdf.rs`; the table is uploaded as it is here.

use super::Bsdf;
use crate::material::Rgb;
use glam::Vec3;
use std::f32::consts::PI;

mod table;
pub use table::SHEEN_ALBEDO;

/// Sheen roughness below which the lobe is drawn at this roughness (as
/// three.js and Filament do): below it the Charlie distribution is a thin
/// ring at the horizon that no light sample or photon gather resolves.
pub const MIN_SHEEN_ROUGHNESS: f32 = 0.07;

/// Nodes of [`SHEEN_ALBEDO`] per axis: √cos θ = i/(N − 1) along a row,
/// roughness r = j/(N − 1) down the rows (evaluated at no less than
/// `MIN_SHEEN_ROUGHNESS`).
pub const SHEEN_TABLE_SIZE: usize = 32;

/// The sheen's roughness as drawn: clamped to [MIN_SHEEN_ROUGHNESS, 1].
pub fn effective_roughness(roughness: f32) -> f32 {
    roughness.clamp(MIN_SHEEN_ROUGHNESS, 1.0)
}

/// The Charlie distribution of width `alpha` at `cos_h` = n·h.
pub fn charlie_d(cos_h: f32, alpha: f32) -> f32 {
    let inv = 1.0 / alpha;
    let sin2 = (1.0 - cos_h * cos_h).max(0.0);
    (2.0 + inv) * sin2.powf(0.5 * inv) / (2.0 * PI)
}

/// The specification's fit L(x) to the Charlie distribution's Λ.
fn lambda_fit(x: f32, alpha: f32) -> f32 {
    let t = (1.0 - alpha) * (1.0 - alpha);
    let mix = |a: f32, b: f32| a + (b - a) * t;
    let a = mix(21.5473, 25.3245);
    let b = mix(3.82987, 3.32435);
    let c = mix(0.19823, 0.16801);
    let d = mix(-1.97760, -1.27393);
    let e = mix(-4.32054, -4.85967);
    a / (1.0 + b * x.powf(c)) + d * x + e
}

/// Λ(θ) of the Charlie distribution, with the fit's terminator softening.
pub fn charlie_lambda(cos: f32, alpha: f32) -> f32 {
    let c = cos.abs();
    if c < 0.5 { lambda_fit(c, alpha).exp() } else { (2.0 * lambda_fit(0.5, alpha) - lambda_fit(1.0 - c, alpha)).exp() }
}

/// V = G2/(4 cos θo cos θi), at most 1; both cosines positive.
pub fn charlie_visibility(cos_o: f32, cos_i: f32, alpha: f32) -> f32 {
    let g = 1.0 + charlie_lambda(cos_o, alpha) + charlie_lambda(cos_i, alpha);
    (1.0 / (g * 4.0 * cos_o * cos_i)).min(1.0)
}

/// The white sheen's D·V at roughness `roughness` (already effective), both
/// directions above the surface.
pub fn white_sheen(wo: Vec3, wi: Vec3, roughness: f32) -> f32 {
    let alpha = roughness * roughness;
    let h = (wo + wi).normalize();
    charlie_d(h.z, alpha) * charlie_visibility(wo.z, wi.z, alpha)
}

/// E(cos θ, r): the white sheen's directional albedo, bilinear in
/// (√cos θ, r) between the table's nodes. `roughness` is clamped as drawn.
pub fn sheen_albedo(cos: f32, roughness: f32) -> f32 {
    let last = (SHEEN_TABLE_SIZE - 1) as f32;
    let x = cos.clamp(0.0, 1.0).sqrt() * last;
    let y = effective_roughness(roughness) * last;
    let (i, j) = ((x as usize).min(SHEEN_TABLE_SIZE - 2), (y as usize).min(SHEEN_TABLE_SIZE - 2));
    let (fx, fy) = (x - i as f32, y - j as f32);
    let at = |i: usize, j: usize| SHEEN_ALBEDO[j * SHEEN_TABLE_SIZE + i];
    let row0 = at(i, j) + (at(i + 1, j) - at(i, j)) * fx;
    let row1 = at(i, j + 1) + (at(i + 1, j + 1) - at(i, j + 1)) * fx;
    row0 + (row1 - row0) * fy
}

impl Bsdf {
    /// This material under a sheen of colour `color` (≥ 0) and roughness
    /// `roughness` (clamped to [0, 1]; drawn at no less than
    /// `MIN_SHEEN_ROUGHNESS`).
    pub fn with_sheen(self, color: Rgb, roughness: f32) -> Self {
        Bsdf { sheen_color: color.max(Rgb::ZERO), sheen_roughness: roughness.clamp(0.0, 1.0), ..self }
    }

    /// A sheen is present (some channel of its colour is above 0).
    pub fn has_sheen(&self) -> bool {
        self.sheen_color.max_element() > 0.0
    }

    /// Ê(cos) = min(E, 1) at this material's sheen roughness.
    pub(super) fn sheen_albedo_at(&self, cos: f32) -> f32 {
        sheen_albedo(cos, self.sheen_roughness).min(1.0)
    }

    /// S, what the sheen leaves of the base's lobes, and the sheen lobe
    /// f_sheen between `wo` and `wi` (both above the surface), reading the
    /// albedo table once per direction: the max of E(θo) and E(θi) sets
    /// both, max(Ê(θo), Ê(θi)) = min(max(E(θo), E(θi)), 1).
    pub(super) fn sheen_parts(&self, wo: Vec3, wi: Vec3) -> (f32, Rgb) {
        let r = effective_roughness(self.sheen_roughness);
        let e = sheen_albedo(wo.z, r).max(sheen_albedo(wi.z, r));
        let m = self.sheen_color.max_element().min(1.0);
        (1.0 - m * e.min(1.0), self.sheen_color * (white_sheen(wo, wi, r) / e.max(1.0)))
    }

    /// The sheen's lobe-selection weight at `cos_o`: its albedo there.
    pub(super) fn sheen_weight(&self, cos_o: f32) -> f32 {
        if !self.has_sheen() {
            return 0.0;
        }
        crate::material::mean(self.sheen_color) * self.sheen_albedo_at(cos_o)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bsdf::ggx::tests::direction_at;
    use crate::bsdf::tests::{integrate_about, mean_weight};
    use crate::material::mean;
    use crate::sampling::Rng;
    use crate::sampling::chi2::assert_direction_distribution;
    use glam::Vec2;
    use std::cell::RefCell;
    use std::f64::consts::PI as PI64;

    /// E(cos θo, r) = ∫ D·V·cos θi dωi by the midpoint rule over the
    /// hemisphere (θi, φi), `n` steps in θ and 2n in φ (symmetric in φ).
    pub(crate) fn albedo_by_quadrature(cos_o: f32, roughness: f32, n: usize) -> f64 {
        let wo = Vec3::new((1.0 - cos_o * cos_o).max(0.0).sqrt(), 0.0, cos_o);
        let (dt, dp) = (0.5 * PI64 / n as f64, PI64 / n as f64);
        let mut sum = 0.0;
        for a in 0..n {
            let theta = (a as f64 + 0.5) * dt;
            for b in 0..n {
                let phi = (b as f64 + 0.5) * dp;
                let wi =
                    Vec3::new((theta.sin() * phi.cos()) as f32, (theta.sin() * phi.sin()) as f32, theta.cos() as f32);
                sum += white_sheen(wo, wi, roughness) as f64 * theta.cos() * theta.sin();
            }
        }
        2.0 * sum * dt * dp
    }

    /// cos θ at column `i`: (i/31)², and the limit from above at the
    /// horizon (where cos θ = 0 exactly, Λ's 0·∞ clamps V to 1 and the
    /// quadrature jumps from 0.7 to 1.2 at roughness 1).
    pub(crate) fn node_cos(i: usize) -> f32 {
        let x = i as f32 / (SHEEN_TABLE_SIZE - 1) as f32;
        (x * x).max(1e-6)
    }

    /// Prints `table.rs` (run once, in release: `cargo test --release -p
    /// hikari-core print_sheen_table -- --ignored --nocapture`).
    #[test]
    #[ignore]
    fn print_sheen_table() {
        let last = (SHEEN_TABLE_SIZE - 1) as f32;
        let mut out = String::new();
        for j in 0..SHEEN_TABLE_SIZE {
            let r = effective_roughness(j as f32 / last);
            let row: Vec<String> =
                (0..SHEEN_TABLE_SIZE).map(|i| format!("{:.6}", albedo_by_quadrature(node_cos(i), r, 1200))).collect();
            out += &format!("    // r = {:.4}\n    {},\n", j as f32 / last, row.join(", "));
        }
        println!("{out}");
    }

    #[test]
    fn the_table_holds_the_quadratures() {
        // Nodes across the table, the spiky smooth corner included.
        for (i, j) in [(0, 31), (31, 31), (10, 10), (3, 2), (0, 2), (20, 5), (7, 25)] {
            let r = effective_roughness(j as f32 / (SHEEN_TABLE_SIZE - 1) as f32);
            let quadrature = albedo_by_quadrature(node_cos(i), r, 600);
            let table = SHEEN_ALBEDO[j * SHEEN_TABLE_SIZE + i] as f64;
            assert!(
                (table - quadrature).abs() < 2e-3 + 2e-3 * quadrature,
                "node ({i}, {j}): table {table}, quadrature {quadrature}"
            );
        }
    }

    #[test]
    fn the_distribution_is_normalised() {
        // ∫ D cos θh dωh = 1 for every width.
        for alpha in [0.0049f32, 0.04, 0.25, 1.0] {
            let n = 4000;
            let dt = 0.5 * PI64 / n as f64;
            let sum: f64 = (0..n)
                .map(|a| {
                    let t = (a as f64 + 0.5) * dt;
                    charlie_d(t.cos() as f32, alpha) as f64 * t.cos() * t.sin() * 2.0 * PI64 * dt
                })
                .sum();
            assert!((sum - 1.0).abs() < 2e-3, "alpha {alpha}: {sum}");
        }
    }

    #[test]
    fn interpolation_between_nodes_is_close_to_the_quadrature() {
        // Midway between nodes, where bilinear interpolation is worst, for
        // the roughness Blender exports by default and rougher.
        for (cos, r) in [(0.3f32, 0.5f32), (0.05, 0.5), (0.7, 0.3), (0.15, 1.0), (0.5, 0.8)] {
            let q = albedo_by_quadrature(cos, r, 600);
            let t = sheen_albedo(cos, r) as f64;
            assert!((t - q).abs() < 0.01, "cos {cos} r {r}: table {t} quadrature {q}");
        }
    }

    /// Directional albedo of `bsdf` (channel mean) by quadrature.
    fn albedo(bsdf: &Bsdf, wo: Vec3) -> f64 {
        integrate_about(Vec3::Z, |wi| (mean(bsdf.f(wo, wi)) * wi.z.max(0.0)) as f64)
    }

    fn view(cos: f32) -> Vec3 {
        Vec3::new((1.0 - cos * cos).sqrt(), 0.0, cos)
    }

    #[test]
    fn white_sheen_over_white_lambert_never_creates_light() {
        for r in [0.0f32, 0.1, 0.3, 0.5, 1.0] {
            let b = Bsdf::diffuse(Rgb::ONE).with_sheen(Rgb::ONE, r);
            for cos in [0.02f32, 0.1, 0.4, 0.8, 1.0] {
                let a = albedo(&b, view(cos));
                // Never above 1, but by the table's interpolation error
                // where E changes fastest (1° from the horizon on the
                // smoothest sheen: 1.3%); and the sheen gives back most of
                // what it takes (the scaling's min loses the rest: 13% at
                // normal incidence on roughness 1).
                let most = if r < 0.1 && cos < 0.05 { 1.02 } else { 1.002 };
                assert!(a <= most && a > 0.85, "r {r} cos {cos}: albedo {a}");
            }
        }
    }

    #[test]
    fn the_lobe_alone_reflects_its_albedo() {
        // A black base: what is reflected is the sheen, C·min(E, 1) where
        // the normalisation does not act.
        let b = Bsdf::diffuse(Rgb::ZERO).with_sheen(Rgb::new(0.8, 0.5, 0.2), 0.5);
        for cos in [0.1f32, 0.5, 0.9] {
            let a = albedo(&b, view(cos));
            let e = albedo_by_quadrature(cos, 0.5, 400) * 0.5;
            assert!((a - e).abs() < 3e-3, "cos {cos}: {a} against {e}");
        }
    }

    #[test]
    fn sheen_is_reciprocal() {
        let b = Bsdf::new(Rgb::new(0.6, 0.3, 0.2), 0.2, 0.6, 1.0).with_sheen(Rgb::new(0.9, 0.7, 0.4), 0.3);
        for (o, i) in [(0.05f32, 0.8f32), (0.3, 0.9), (0.7, 0.02)] {
            let wo = view(o);
            let wi = Vec3::new(-(1.0 - i * i).sqrt() * 0.6, (1.0 - i * i).sqrt() * 0.8, i);
            let (a, c) = (b.f(wo, wi), b.f(wi, wo));
            assert!((a - c).abs().max_element() <= 1e-6 * a.max_element(), "{a} against {c}");
        }
    }

    fn sheened() -> [(Bsdf, f32); 4] {
        [
            (Bsdf::new(Rgb::new(0.3, 0.3, 0.6), 0.0, 0.8, 1.0).with_sheen(Rgb::new(1.0, 0.9, 0.8), 0.4), 30.0),
            (Bsdf::new(Rgb::new(0.2, 0.1, 0.1), 0.0, 0.5, 1.0).with_sheen(Rgb::ONE, 0.1), 80.0),
            (Bsdf::new(Rgb::new(0.9, 0.8, 0.7), 1.0, 0.3, 1.0).with_sheen(Rgb::splat(0.5), 0.7), 60.0),
            (
                Bsdf::new(Rgb::new(0.5, 0.2, 0.1), 0.0, 0.7, 1.0)
                    .with_sheen(Rgb::new(0.6, 0.8, 1.0), 0.5)
                    .with_clearcoat(1.0, 0.3),
                50.0,
            ),
        ]
    }

    #[test]
    fn samples_match_their_density() {
        for (b, deg) in sheened() {
            let wo = direction_at(deg);
            let p_valid = integrate_about(Vec3::Z, |wi| b.pdf(wo, wi) as f64) as f32;
            assert!(p_valid <= 1.0 + 1e-3 && p_valid > 0.8, "{p_valid}");
            let rng = RefCell::new(Rng::for_item(0x5EE4, deg as u64));
            let sample = |mut u: Vec2| loop {
                let u_lobe = rng.borrow_mut().next_f32();
                if let Some(s) = b.sample(wo, u_lobe, u) {
                    return s.wi;
                }
                u = rng.borrow_mut().next_2d();
            };
            assert_direction_distribution(sample, |wi| b.pdf(wo, wi) / p_valid);
        }
    }

    /// The mean sample weight is ∫ f cos dω by quadrature, and the gathered
    /// part plus the followed samples is the whole: the sheen is gathered.
    #[test]
    fn sampled_and_gathered_albedos_match_quadrature() {
        for (b, deg) in sheened() {
            let wo = direction_at(deg);
            let whole = integrate_about(Vec3::Z, |wi| (mean(b.f(wo, wi)) * wi.z.max(0.0)) as f64);
            let (m, error) = mean_weight(200_000, 0x5EE5 + deg as u64, |u_lobe, u| {
                b.sample(wo, u_lobe, u).map_or(0.0, |s| mean(s.weight) as f64)
            });
            assert!((m - whole).abs() < 4.0 * error + 2e-3, "{deg}°: sampled {m} ± {error}, quadrature {whole}");
            let gathered = integrate_about(Vec3::Z, |wi| (mean(b.f_gathered(wo, wi)) * wi.z.max(0.0)) as f64);
            let (followed, error) = mean_weight(100_000, 0x5EE6 + deg as u64, |_, u| {
                b.sample_followed(wo, u).map_or(0.0, |s| mean(s.weight) as f64)
            });
            assert!(
                (gathered + followed - whole).abs() < 4.0 * error + 2e-3,
                "{deg}°: {gathered} + {followed} against {whole}"
            );
        }
    }

    #[test]
    fn no_sheen_is_the_base() {
        let base = Bsdf::new(Rgb::new(0.6, 0.3, 0.2), 0.2, 0.6, 1.0);
        let wo = view(0.4);
        let wi = Vec3::new(0.3, -0.5, 0.81).normalize();
        assert_eq!(base.with_sheen(Rgb::ZERO, 0.5).f(wo, wi), base.f(wo, wi));
        assert_eq!(base.with_sheen(Rgb::ZERO, 0.5).pdf(wo, wi), base.pdf(wo, wi));
    }
}

use super::*;
use crate::bsdf::ggx::tests::direction_at;
use crate::bsdf::tests::integrate_about;
use crate::material::{dielectric_split, mean};
use crate::sampling::Rng;
use crate::sampling::chi2::assert_direction_distribution;
use std::cell::RefCell;

fn glass(roughness: f32) -> Dielectric {
    Dielectric { ior: 1.5, roughness, tint: Rgb::ONE, absorption: Rgb::ZERO }
}

/// `wo` at `deg` from the normal, outside (`outside`) or mirrored inside.
fn view(deg: f32, outside: bool) -> Vec3 {
    let w = direction_at(deg);
    if outside { w } else { Vec3::new(w.x, w.y, -w.z) }
}

/// The directions a rough boundary sends `wo`'s light: the mirror one and
/// Snell's refraction (where quadrature points must crowd); beyond the
/// critical angle, rough microfacets still transmit: about the far normal.
fn lobe_axes(wo: Vec3, ior: f32) -> (Vec3, Vec3) {
    let split = dielectric_split(-wo, Vec3::Z, ior);
    (split.reflected, split.refracted.unwrap_or(Vec3::new(0.0, 0.0, -wo.z.signum())))
}

/// ∫ f |cos θi| dωi (channel mean) by quadrature: the reflected and the
/// transmitted hemisphere each integrated about their lobe's axis.
fn albedo_by_quadrature(g: &Dielectric, wo: Vec3, mode: Transport) -> f64 {
    let (reflected, refracted) = lobe_axes(wo, g.ior);
    let side = |w: Vec3, reflect: bool| (w.z * wo.z > 0.0) == reflect;
    let cosine_weighted = |w: Vec3| (mean(g.f(wo, w, mode)) * w.z.abs()) as f64;
    let r = integrate_about(reflected, |w| if side(w, true) { cosine_weighted(w) } else { 0.0 });
    let t = integrate_about(refracted, |w| if side(w, false) { cosine_weighted(w) } else { 0.0 });
    r + t
}

fn albedo_by_sampling(g: &Dielectric, wo: Vec3, mode: Transport, n: usize) -> (f64, f64) {
    crate::bsdf::tests::mean_weight(n, 0xD1E1, |u_lobe, u| {
        g.sample(wo, u_lobe, u, mode).map_or(0.0, |s| mean(s.weight) as f64)
    })
}

#[test]
fn smooth_glass_splits_by_fresnel_with_tinted_transmission() {
    let g = Dielectric { ior: 1.5, roughness: 0.0, tint: Rgb::new(0.9, 0.5, 0.2), absorption: Rgb::ZERO };
    let wo = Vec3::Z;
    // Normal incidence from outside: R = ((1.5 − 1)/(1.5 + 1))² = 0.04.
    let r = g.sample(wo, 0.0, Vec2::ZERO, Transport::Importance).unwrap();
    assert!(r.is_delta && !r.transmitted && (r.pdf - 0.04).abs() < 1e-6 && r.weight == Rgb::ONE);
    assert_eq!(r.wi, Vec3::Z);
    let t = g.sample(wo, 0.5, Vec2::ZERO, Transport::Importance).unwrap();
    assert!(t.transmitted && (t.pdf - 0.96).abs() < 1e-6 && t.wi == -Vec3::Z);
    // Each crossing tints by √tint: through a solid piece, the tint.
    let per_crossing = Rgb::new(0.9f32.sqrt(), 0.5f32.sqrt(), 0.2f32.sqrt());
    assert_eq!(t.weight, per_crossing);
    // Radiance entering glass is divided by 1.5²; leaving, multiplied.
    let t = g.sample(wo, 0.5, Vec2::ZERO, Transport::Radiance).unwrap();
    assert!((t.weight - per_crossing / 2.25).abs().max_element() < 1e-6);
    let t = g.sample(-wo, 0.5, Vec2::ZERO, Transport::Radiance).unwrap();
    assert!((t.weight - per_crossing * 2.25).abs().max_element() < 1e-5);
    // The same directions as `dielectric_split`, from either side.
    for (deg, outside) in [(30.0, true), (60.0, true), (20.0, false), (40.0, false)] {
        let wo = view(deg, outside);
        let split = dielectric_split(-wo, Vec3::Z, 1.5);
        let r = g.sample(wo, 0.0, Vec2::ZERO, Transport::Importance).unwrap();
        assert!((r.wi - split.reflected).length() < 1e-6 && (r.pdf - split.reflectance).abs() < 1e-6);
        let t = g.sample(wo, 0.9999, Vec2::ZERO, Transport::Importance).unwrap();
        assert!(
            (t.wi - split.refracted.unwrap()).length() < 1e-5,
            "{deg}° {outside}: {} vs {:?}",
            t.wi,
            split.refracted
        );
    }
    // Beyond the critical angle (41.8°) inside: total internal reflection.
    let s = g.sample(view(50.0, false), 0.9999, Vec2::ZERO, Transport::Radiance).unwrap();
    assert!(!s.transmitted && s.pdf == 1.0);
}

#[test]
fn rough_samples_match_their_density() {
    for (roughness, deg, outside) in [(0.3, 30.0, true), (0.6, 70.0, true), (0.3, 20.0, false), (0.5, 60.0, false)] {
        let g = glass(roughness);
        let wo = view(deg, outside);
        // Draws that fall on the wrong side are lost; the helper wants a
        // direction per draw, so the density is divided by P(success).
        let (reflected, refracted) = lobe_axes(wo, g.ior);
        let p_valid = integrate_about(reflected, |w| if w.z * wo.z > 0.0 { g.pdf(wo, w) as f64 } else { 0.0 })
            + integrate_about(refracted, |w| if w.z * wo.z < 0.0 { g.pdf(wo, w) as f64 } else { 0.0 });
        println!(
            "roughness {roughness}, {deg}° {}: P(sample succeeds) = {p_valid:.5}",
            if outside { "out" } else { "in" }
        );
        assert!(p_valid <= 1.0 + 2e-3 && p_valid > 0.7, "{p_valid}");
        let rng = RefCell::new(Rng::for_item(0xD1E2, deg as u64));
        let sample = |mut u: Vec2| loop {
            let u_lobe = rng.borrow_mut().next_f32();
            if let Some(s) = g.sample(wo, u_lobe, u, Transport::Radiance) {
                assert!(!s.is_delta && s.pdf == g.pdf(wo, s.wi));
                assert_eq!(s.transmitted, s.wi.z * wo.z < 0.0);
                return s.wi;
            }
            u = rng.borrow_mut().next_2d();
        };
        let p_valid = p_valid as f32;
        assert_direction_distribution(sample, |w| g.pdf(wo, w) / p_valid);
    }
}

/// The mean sample weight is ∫ f |cos| dω computed by quadrature from `f`
/// alone: sampler, density and BSDF agree. In importance mode that is the
/// fraction of power kept (below 1 only by what single scattering loses).
#[test]
fn sampled_albedo_matches_quadrature() {
    for (roughness, deg, outside, mode) in [
        (0.2, 0.0, true, Transport::Importance),
        (0.4, 45.0, true, Transport::Importance),
        (0.4, 30.0, false, Transport::Importance),
        (0.7, 75.0, true, Transport::Radiance),
        (0.4, 30.0, false, Transport::Radiance),
    ] {
        let g = glass(roughness);
        let wo = view(deg, outside);
        let quadrature = albedo_by_quadrature(&g, wo, mode);
        let (sampled, error) = albedo_by_sampling(&g, wo, mode, 400_000);
        println!(
            "roughness {roughness} {deg}° out={outside} {mode:?}: quadrature {quadrature:.4}, sampled {sampled:.4} ± {error:.4}"
        );
        assert!((quadrature - sampled).abs() < 4.0 * error + 2e-3, "{quadrature} vs {sampled}");
        if mode == Transport::Importance {
            assert!(sampled <= 1.0 + 4.0 * error && sampled > 0.85, "{sampled}");
        }
    }
}

/// Radiance from wo by wi equals importance from wi by wo (Veach's adjoint
/// BSDF), for reflection and transmission pairs from both sides (to 1%:
/// near total internal reflection 1 − F is steep in f32's cosines).
#[test]
fn radiance_is_the_adjoint_of_importance() {
    let g = Dielectric { ior: 1.33, roughness: 0.45, tint: Rgb::new(0.8, 0.6, 1.0), absorption: Rgb::ZERO };
    let mut rng = Rng::for_item(0xD1E3, 0);
    let mut checked = 0;
    for _ in 0..2000 {
        let (a, b) = (crate::sampling::uniform_sphere(rng.next_2d()), crate::sampling::uniform_sphere(rng.next_2d()));
        let forward = g.f(a, b, Transport::Radiance);
        let backward = g.f(b, a, Transport::Importance);
        if forward.max_element() > 1e-4 {
            checked += 1;
            assert!(
                (forward - backward).abs().max_element() <= 1e-2 * forward.max_element(),
                "{a} {b}: {forward} vs {backward}"
            );
        } else {
            assert!(backward.max_element() < 2e-3, "{a} {b}: {forward} vs {backward}");
        }
    }
    assert!(checked > 500, "{checked}");
}

/// Just above the smooth threshold the rough boundary reflects and
/// transmits what the smooth one does.
#[test]
fn rough_glass_tends_to_smooth_glass() {
    let rough = glass(SMOOTH_ROUGHNESS * 1.2);
    for (deg, outside) in [(0.0, true), (50.0, true), (30.0, false)] {
        let wo = view(deg, outside);
        let split = dielectric_split(-wo, Vec3::Z, 1.5);
        let mut rng = Rng::for_item(0xD1E4, deg as u64);
        let (n, mut reflected, mut transmitted) = (100_000, 0.0, 0.0);
        for _ in 0..n {
            let u_lobe = rng.next_f32();
            if let Some(s) = rough.sample(wo, u_lobe, rng.next_2d(), Transport::Importance) {
                if s.transmitted { transmitted += mean(s.weight) } else { reflected += mean(s.weight) }
            }
        }
        let (r, t) = (reflected / n as f32, transmitted / n as f32);
        println!("{deg}° out={outside}: R {r:.4} (smooth {:.4}), T {t:.4}", split.reflectance);
        assert!((r - split.reflectance).abs() < 0.01 && (t - (1.0 - split.reflectance)).abs() < 0.01);
    }
}

#[test]
/// Each crossing is tinted by √tint (in and out: the tint), reflections
/// stay white.
fn tint_colours_transmission_only() {
    let tint = Rgb::new(1.0, 0.25, 0.0625);
    let g = Dielectric { ior: 1.5, roughness: 0.4, tint, absorption: Rgb::ZERO };
    let wo = view(30.0, true);
    let mut rng = Rng::for_item(0xD1E5, 0);
    let (mut seen_r, mut seen_t) = (false, false);
    for _ in 0..200 {
        let u_lobe = rng.next_f32();
        let Some(s) = g.sample(wo, u_lobe, rng.next_2d(), Transport::Importance) else { continue };
        let w = s.weight;
        if s.transmitted {
            seen_t = true;
            assert!((w.y / w.x - 0.5).abs() < 1e-5 && (w.z / w.x - 0.25).abs() < 1e-5, "{w}");
            // In and out again (a solid piece): the tint itself.
            let back = g.sample(-s.wi, u_lobe.max(0.999), rng.next_2d(), Transport::Importance);
            if let Some(out) = back.filter(|b| b.transmitted) {
                let through = w * out.weight;
                assert!((through.y / through.x - 0.25).abs() < 1e-4, "{through}");
            }
        } else {
            seen_r = true;
            assert!(w.x == w.y && w.y == w.z, "{w}");
        }
    }
    assert!(seen_r && seen_t);
}

#[test]
fn smooth_branches_are_the_samples_weighted_by_their_probability() {
    let g = Dielectric { ior: 1.4, roughness: 0.0, tint: Rgb::new(0.7, 0.8, 0.9), absorption: Rgb::ZERO };
    for (deg, outside) in [(0.0, true), (35.0, true), (80.0, true), (25.0, false), (60.0, false)] {
        let wo = view(deg, outside);
        let ((r_dir, r_weight), refracted) = g.smooth_branches(-wo, Vec3::Z, Transport::Radiance);
        let r = g.sample(wo, 0.0, Vec2::ZERO, Transport::Radiance).unwrap();
        assert!((r_dir - r.wi).length() < 1e-6 && (r_weight - Rgb::splat(r.pdf) * r.weight).abs().max_element() < 1e-6);
        let t = g.sample(wo, 0.99999, Vec2::ZERO, Transport::Radiance).unwrap();
        match refracted {
            Some((t_dir, t_weight)) => {
                assert!(t.transmitted && (t_dir - t.wi).length() < 1e-6);
                assert!((t_weight - t.pdf * t.weight).abs().max_element() < 1e-5);
            }
            None => assert!(!t.transmitted && r.pdf == 1.0, "{deg}° {outside}"),
        }
    }
}

/// Beer–Lambert inside: a ray arriving from inside (along the outward
/// normal) keeps e^(−σ·t); one arriving from outside, or clear glass,
/// keeps everything.
#[test]
fn the_inside_absorbs_only_along_paths_inside() {
    let g = Dielectric { absorption: Rgb::new(0.5, 1.0, 0.0), ..glass(0.0) };
    let up = Vec3::Z;
    let kept = g.interior_transmittance(Vec3::new(0.0, 0.6, 0.8), up, 2.0);
    assert!((kept - Rgb::new((-1.0f32).exp(), (-2.0f32).exp(), 1.0)).abs().max_element() < 1e-6, "{kept}");
    assert_eq!(g.interior_transmittance(-up, up, 2.0), Rgb::ONE);
    assert_eq!(glass(0.0).interior_transmittance(up, up, 2.0), Rgb::ONE);
}

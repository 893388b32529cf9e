//! A vertex as vertex connection and merging sees it: its material at the
//! point (or, in a medium, the phase functions there), the direction its
//! subpath arrived from, and what the strategies ask of it: f and both
//! sampling densities toward any direction (connections, merges), a sampled
//! continuation, and the Russian-roulette probability of going on, which
//! every density includes (in a medium, the albedo Λ).
//!
//! Shading uses the interpolated normal bent by its normal texture
//! (`Scene::bent`), as every renderer does. f is symmetric, so light and
//! camera subpaths evaluate it alike, except across glass: eye subpaths
//! carry radiance (1/η'² per crossing), light subpaths power, and each
//! evaluates glass in its own mode (`Transport`), the adjoint of the other.

use crate::bsdf::bump::BumpShadow;
use crate::bsdf::dielectric::{Dielectric, Transport};
use crate::bsdf::{Bsdf, ShadingFrame};
use crate::geometry::Hit;
use crate::material::{Material, Rgb, mean, reflect};
use crate::medium::{MAX_PHASES, Media, Phase};
use crate::sampling::{Rng, cosine_hemisphere};
use glam::Vec3;
use std::f32::consts::PI;

#[derive(Clone, Copy, Debug)]
enum Lobes {
    /// The glTF BRDF (its smooth mirror a delta lobe).
    Pbr(Bsdf),
    /// Lambertian `albedo` chosen with probability `p_diffuse`, else a
    /// perfect mirror of reflectance `mirror` (hikari's `diffuse` and `mirror`).
    Lambert { albedo: Rgb, mirror: Rgb, p_diffuse: f32 },
    /// Glass, in the frame of its outward geometric normal: smooth (Fresnel
    /// reflection or refraction, both deltas) or rough (both lobes
    /// densities); eye subpaths carry radiance through it, light subpaths
    /// power.
    Glass(Dielectric, Transport),
    /// A point in a medium.
    Medium(PhaseMix),
}

/// The phase functions of the media overlapping at a point: per channel,
/// f = Σᵢ σ_s,i pᵢ / Σᵢ σ_s,i (the vertex's throughput already carries
/// σ_s), sampled by choosing a medium ∝ its mean σ_s, so the density is
/// the same mixture with those probabilities. One medium: f = pdf = p.
#[derive(Clone, Copy, Debug)]
struct PhaseMix {
    phases: [Phase; MAX_PHASES],
    weights: [Rgb; MAX_PHASES],
    probabilities: [f32; MAX_PHASES],
    count: usize,
    /// σ̄ = mean(σ_t) there: the free flight's density per unit length
    /// (with the transmittance before it).
    sigma_bar: f32,
}

impl PhaseMix {
    fn new(media: &Media, mask: u32) -> Option<PhaseMix> {
        let phases_in_scene = media.phases();
        let mut mix = PhaseMix {
            phases: [Phase::Schlick { k: 0.0 }; MAX_PHASES],
            weights: [Rgb::ZERO; MAX_PHASES],
            probabilities: [0.0; MAX_PHASES],
            count: phases_in_scene.len().min(MAX_PHASES),
            sigma_bar: mean(media.sigma_t(mask)),
        };
        mix.phases[..mix.count].copy_from_slice(&phases_in_scene[..mix.count]);
        let sigma_s = media.sigma_s(mask);
        let total = mean(sigma_s);
        if total <= 0.0 {
            return None;
        }
        let mut bits = mask;
        while bits != 0 {
            let entry = &media.entries()[bits.trailing_zeros() as usize];
            bits &= bits - 1;
            let slot = entry.phase_slot as usize;
            mix.weights[slot] += Rgb::select(sigma_s.cmpgt(Rgb::ZERO), entry.medium.sigma_s / sigma_s, Rgb::ZERO);
            mix.probabilities[slot] += mean(entry.medium.sigma_s) / total;
        }
        Some(mix)
    }

    /// f (per channel) and density of scattering by angle acos(`mu`).
    fn eval(&self, mu: f32) -> (Rgb, f32) {
        let (mut f, mut pdf) = (Rgb::ZERO, 0.0);
        for slot in 0..self.count {
            let p = self.phases[slot].eval(mu);
            f += self.weights[slot] * p;
            pdf += self.probabilities[slot] * p;
        }
        (f, pdf)
    }

    fn choose(&self, u: f32) -> Phase {
        let mut acc = 0.0;
        for slot in 0..self.count {
            acc += self.probabilities[slot];
            if u < acc {
                return self.phases[slot];
            }
        }
        self.phases[self.count.saturating_sub(1)]
    }
}

#[derive(Clone, Copy, Debug)]
pub struct Scatter {
    lobes: Lobes,
    frame: ShadingFrame,
    /// The shading and geometric normals, turned toward `wo`.
    normal: Vec3,
    geometric: Vec3,
    /// The geometric normal as the primitive defines it (glass's outside).
    outward: Vec3,
    /// Unit, toward where the subpath came from.
    wo: Vec3,
    wo_local: Vec3,
    continuation: f32,
    /// At a point a normal texture bends, the diffuse lobes' bump
    /// shadowing, of the side the light comes from: `wi` on an eye
    /// subpath, `wo` on a light subpath (`carries`).
    bump: Option<BumpShadow>,
    carries: Transport,
}

/// f toward a direction and the two sampling densities (per steradian,
/// without the continuation).
#[derive(Clone, Copy, Debug)]
pub struct Evaluation {
    pub f: Rgb,
    /// |n · wi|.
    pub cos: f32,
    /// Of sampling wi given wo.
    pub pdf_dir: f32,
    /// Of sampling wo given wi.
    pub pdf_rev: f32,
}

#[derive(Clone, Copy, Debug)]
pub struct Sampled {
    pub wi: Vec3,
    /// f·|cos|/pdf.
    pub weight: Rgb,
    /// Densities as in [`Evaluation`]; for a delta lobe its choice's probability.
    pub pdf_dir: f32,
    pub pdf_rev: f32,
    pub cos: f32,
    pub delta: bool,
}

impl Scatter {
    /// The vertex at `hit`, reached along `dir`; None where nothing
    /// scatters (the black bodies of area lights, black materials).
    /// `unbent` is the smooth normal a normal texture bent `hit`'s shading
    /// normal from (equal to it where none did). `mode` says what the
    /// subpath carries: radiance (from the eye) or power (from a light),
    /// which differ across glass and in the bump shadowing's side.
    pub fn at(material: Material, hit: &Hit, unbent: Vec3, dir: Vec3, mode: Transport) -> Option<Scatter> {
        let facing = if dir.dot(hit.geometric_normal) < 0.0 { 1.0 } else { -1.0 };
        let (lobes, continuation) = match material {
            Material::Emitter => return None,
            Material::Pbr(bsdf) => (Lobes::Pbr(bsdf), bsdf.albedo_estimate().max_element()),
            Material::Glass(glass) => (Lobes::Glass(glass, mode), 1.0),
            Material::Diffuse { .. } | Material::Mirror { .. } => {
                let (albedo, mirror) = (material.diffuse_albedo(), material.mirror_reflectance());
                let (p_d, p_s) = (mean(albedo), mean(mirror));
                if p_d + p_s <= 0.0 {
                    return None;
                }
                (Lobes::Lambert { albedo, mirror, p_diffuse: p_d / (p_d + p_s) }, (albedo + mirror).max_element())
            }
        };
        if continuation <= 0.0 {
            return None;
        }
        let normal = hit.shading_normal * facing;
        let frame = ShadingFrame::new(normal);
        let wo = -dir;
        let bent = unbent != hit.shading_normal && !matches!(lobes, Lobes::Glass(..));
        Some(Scatter {
            lobes,
            frame,
            normal,
            geometric: hit.geometric_normal * facing,
            outward: hit.geometric_normal,
            wo,
            wo_local: frame.to_local(wo),
            continuation: continuation.min(1.0),
            bump: if bent { BumpShadow::new(unbent * facing, normal) } else { None },
            carries: mode,
        })
    }

    /// [`Scatter::at`] for a vertex of `scene`: `material`'s clear coat on
    /// its own normal where a `clearcoatNormalTexture` bends it
    /// ([`crate::scene::Scene::coat_tilted`], in the frame `at` shades in).
    pub fn in_scene(
        scene: &crate::scene::Scene,
        material: Material,
        hit: &Hit,
        unbent: Vec3,
        dir: Vec3,
        mode: Transport,
    ) -> Option<Scatter> {
        let material = match material {
            Material::Pbr(bsdf) if bsdf.has_coat() => {
                let facing = if dir.dot(hit.geometric_normal) < 0.0 { 1.0 } else { -1.0 };
                let frame = ShadingFrame::new(hit.shading_normal * facing);
                scene.coat_tilted(&bsdf, hit, unbent, dir, &frame).map_or(material, Material::Pbr)
            }
            other => other,
        };
        Scatter::at(material, hit, unbent, dir, mode)
    }

    /// The vertex in the media of `mask`, reached along `dir`; None where
    /// nothing there scatters.
    pub fn medium(media: &Media, mask: u32, dir: Vec3) -> Option<Scatter> {
        let mix = PhaseMix::new(media, mask)?;
        let (lambda, _) = media.scattering(mask);
        let frame = ShadingFrame::new(dir);
        Some(Scatter {
            lobes: Lobes::Medium(mix),
            frame,
            normal: dir,
            geometric: dir,
            outward: dir,
            wo: -dir,
            wo_local: frame.to_local(-dir),
            continuation: lambda.min(1.0),
            bump: None,
            carries: Transport::Radiance,
        })
    }

    /// Whether the vertex lies in a medium (merges there use the ball kernel).
    pub fn in_medium(&self) -> bool {
        matches!(self.lobes, Lobes::Medium(_))
    }

    /// What turns a density per unit area on a surface into one per unit
    /// volume in a medium: σ̄ there (the free flight's density, with the
    /// transmittance before it); 1 on a surface, whose cosine
    /// [`Evaluation::cos`] carries instead.
    pub fn flight_density(&self) -> f32 {
        match self.lobes {
            Lobes::Medium(mix) => mix.sigma_bar,
            _ => 1.0,
        }
    }

    /// Every lobe is a delta: no connection or merge can use this vertex.
    pub fn is_delta(&self) -> bool {
        match self.lobes {
            Lobes::Pbr(bsdf) => !bsdf.has_non_delta_lobe(),
            Lobes::Lambert { p_diffuse, .. } => p_diffuse == 0.0,
            Lobes::Glass(glass, _) => glass.is_smooth(),
            Lobes::Medium(_) => false,
        }
    }

    /// |n · wo|: the cosine the subpath arrived with (1 in a medium).
    pub fn cos_in(&self) -> f32 {
        if self.in_medium() { 1.0 } else { self.wo_local.z.abs() }
    }

    /// The probability that a subpath goes on from here.
    pub fn continuation(&self) -> f32 {
        self.continuation
    }

    /// Toward where the subpath came from.
    pub fn wo(&self) -> Vec3 {
        self.wo
    }

    /// The bump shadowing's weight of the diffuse lobes for a subpath
    /// going on along the world direction `wi` (1 where nothing bends).
    fn bump_weight(&self, wi: Vec3) -> f32 {
        self.bump.map_or(1.0, |b| b.term(if self.carries == Transport::Radiance { wi } else { self.wo }))
    }

    /// What a light vertex merged here, arriving from `wi`, weighs beyond f:
    /// on a reflecting surface whose shading normal is not its geometric
    /// one, `estimate::shading_normal_factor` (the density of light vertices
    /// is flux over the true surface, while f's connections and bounces
    /// weigh cos θs: without it, merging and connecting estimated different
    /// light, and MIS mixed them); 1 elsewhere (glass is evaluated in its
    /// geometric frame, media have no normal).
    pub fn merge_weight(&self, wi: Vec3) -> f32 {
        match self.lobes {
            Lobes::Medium(_) | Lobes::Glass(..) => 1.0,
            _ if self.normal == self.geometric => 1.0,
            _ => crate::estimate::shading_normal_factor(wi, self.normal, self.geometric),
        }
    }

    /// f and densities toward world direction `wi` (non-delta lobes);
    /// None where they carry nothing.
    pub fn evaluate(&self, wi: Vec3) -> Option<Evaluation> {
        if let Lobes::Medium(mix) = self.lobes {
            // μ between the directions of travel before (−wo) and after (wi).
            let (f, pdf) = mix.eval(-self.wo.dot(wi));
            return (f.max_element() > 0.0 && pdf > 0.0).then_some(Evaluation {
                f,
                cos: 1.0,
                pdf_dir: pdf,
                pdf_rev: pdf,
            });
        }
        if let Lobes::Glass(glass, mode) = self.lobes {
            let outward = ShadingFrame::new(self.outward);
            let (wo, wi) = (outward.to_local(self.wo), outward.to_local(wi));
            let f = glass.f(wo, wi, mode);
            let (pdf_dir, pdf_rev) = (glass.pdf(wo, wi), glass.pdf(wi, wo));
            return (f.max_element() > 0.0 && pdf_dir > 0.0).then_some(Evaluation {
                f,
                cos: wi.z.abs(),
                pdf_dir,
                pdf_rev,
            });
        }
        // Reflection only, on the side the subpath arrived from.
        if wi.dot(self.geometric) <= 0.0 {
            return None;
        }
        let wi_local = self.frame.to_local(wi);
        if wi_local.z <= 0.0 || self.wo_local.z <= 0.0 {
            return None;
        }
        let (f, pdf_dir, pdf_rev) = match self.lobes {
            Lobes::Pbr(bsdf) => (
                bsdf.f_bumped(self.wo_local, wi_local, self.bump_weight(wi)),
                bsdf.pdf(self.wo_local, wi_local),
                bsdf.pdf(wi_local, self.wo_local),
            ),
            Lobes::Lambert { albedo, p_diffuse, .. } => {
                (albedo / PI * self.bump_weight(wi), p_diffuse * wi_local.z / PI, p_diffuse * self.wo_local.z / PI)
            }
            Lobes::Glass(..) | Lobes::Medium(_) => return None,
        };
        (f.max_element() > 0.0 && pdf_dir > 0.0).then_some(Evaluation { f, cos: wi_local.z, pdf_dir, pdf_rev })
    }

    /// A continuation direction (before Russian roulette).
    pub fn sample(&self, rng: &mut Rng) -> Option<Sampled> {
        let (u_lobe, u) = (rng.next_f32(), rng.next_2d());
        let sampled = match self.lobes {
            Lobes::Pbr(bsdf) => {
                let s = bsdf.sample(self.wo_local, u_lobe, u)?;
                let s = bsdf.reweigh(self.wo_local, s, self.bump_weight(self.frame.to_world(s.wi)));
                let pdf_rev = if s.is_delta { s.pdf } else { bsdf.pdf(s.wi, self.wo_local) };
                Sampled {
                    wi: self.frame.to_world(s.wi),
                    weight: s.weight,
                    pdf_dir: s.pdf,
                    pdf_rev,
                    cos: s.wi.z,
                    delta: s.is_delta,
                }
            }
            Lobes::Lambert { albedo, mirror, p_diffuse } => {
                if u_lobe < p_diffuse {
                    let local = cosine_hemisphere(u);
                    let wi = self.frame.to_world(local);
                    Sampled {
                        wi,
                        weight: albedo / p_diffuse * self.bump_weight(wi),
                        pdf_dir: p_diffuse * local.z / PI,
                        pdf_rev: p_diffuse * self.wo_local.z / PI,
                        cos: local.z,
                        delta: false,
                    }
                } else {
                    let p = 1.0 - p_diffuse;
                    let wi = reflect(-self.wo, self.normal);
                    Sampled { wi, weight: mirror / p, pdf_dir: p, pdf_rev: p, cos: wi.dot(self.normal), delta: true }
                }
            }
            Lobes::Glass(glass, mode) => {
                let s = glass.sample_world(-self.wo, self.outward, u_lobe, u, mode)?;
                // A delta choice's probability is the same either way.
                let pdf_rev = if s.is_delta {
                    s.pdf.max(f32::MIN_POSITIVE)
                } else {
                    let outward = ShadingFrame::new(self.outward);
                    glass.pdf(outward.to_local(s.wi), outward.to_local(self.wo))
                };
                Sampled {
                    wi: s.wi,
                    weight: s.weight,
                    pdf_dir: s.pdf.max(f32::MIN_POSITIVE),
                    pdf_rev,
                    cos: s.wi.dot(self.normal).abs(),
                    delta: s.is_delta,
                }
            }
            Lobes::Medium(mix) => {
                let wi = mix.choose(u_lobe).sample(-self.wo, u);
                let (f, pdf) = mix.eval(-self.wo.dot(wi));
                Sampled {
                    wi,
                    weight: f / pdf.max(f32::MIN_POSITIVE),
                    pdf_dir: pdf,
                    pdf_rev: pdf,
                    cos: 1.0,
                    delta: false,
                }
            }
        };
        if sampled.pdf_dir.is_nan() || sampled.pdf_dir <= 0.0 || sampled.weight.max_element() <= 0.0 {
            return None;
        }
        // A reflection must leave on the side it arrived from (a shading
        // normal can point a sample through the surface); glass may cross it.
        let crosses = sampled.wi.dot(self.geometric) <= 0.0;
        if crosses && !matches!(self.lobes, Lobes::Glass { .. } | Lobes::Medium(_)) {
            return None;
        }
        Some(sampled)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec2;

    fn hit(shading_normal: Vec3) -> Hit {
        Hit {
            t: 1.0,
            point: Vec3::ZERO,
            geometric_normal: Vec3::Z,
            shading_normal,
            surface: 0,
            prim: 0,
            barycentrics: Vec2::ZERO,
        }
    }

    /// A light vertex merged on a bent diffuse surface weighs
    /// `shading_normal_factor` (as photon-cpu's gathers); on a flat one, on
    /// glass and in a medium, 1.
    #[test]
    fn merges_weigh_the_shading_normal_where_it_bends() {
        let diffuse = Material::Diffuse { albedo: Rgb::splat(0.5), specular: Rgb::ZERO };
        let bent = Vec3::new(0.5f32.sin(), 0.0, 0.5f32.cos());
        let down = Vec3::new(0.0, 0.3, -1.0).normalize();
        let wi = Vec3::new(0.6, 0.0, 0.8);
        let at = |n: Vec3, m: Material| Scatter::at(m, &hit(n), n, down, Transport::Radiance).unwrap();
        let weight = at(bent, diffuse).merge_weight(wi);
        assert!((weight - crate::estimate::shading_normal_factor(wi, bent, Vec3::Z)).abs() < 1e-6);
        assert!((weight - wi.dot(bent) / 0.8).abs() < 1e-5, "{weight}");
        assert_eq!(at(Vec3::Z, diffuse).merge_weight(wi), 1.0);
        assert_eq!(at(bent, Material::Glass(Dielectric::clear(1.5))).merge_weight(wi), 1.0);
    }

    /// At a normal-mapped point the diffuse lobes take the bump shadowing
    /// of the light's side: the direction an eye subpath goes on along,
    /// the one a light subpath came from; the densities stay; nothing
    /// changes where no normal texture bent the normal.
    #[test]
    fn the_bump_shadowing_weighs_the_lights_side() {
        let unbent = Vec3::Z;
        let bent = Vec3::new(0.6f32.sin(), 0.0, 0.6f32.cos());
        let down = Vec3::new(-0.9, 0.2, -0.35).normalize();
        let wi = Vec3::new(0.9, 0.1, 0.25).normalize();
        let bump = BumpShadow::new(unbent, bent).unwrap();
        let diffuse = Material::Diffuse { albedo: Rgb::splat(0.5), specular: Rgb::ZERO };
        let pbr = Material::Pbr(Bsdf::new(Rgb::new(0.7, 0.5, 0.3), 0.0, 0.6, 1.0));
        for m in [diffuse, pbr] {
            let plain = Scatter::at(m, &hit(bent), bent, down, Transport::Radiance).unwrap().evaluate(wi).unwrap();
            for (mode, side) in [(Transport::Radiance, wi), (Transport::Importance, -down)] {
                let s = Scatter::at(m, &hit(bent), unbent, down, mode).unwrap();
                let e = s.evaluate(wi).unwrap();
                let k = bump.term(side);
                assert!(k < 0.99, "{k}");
                let want = match m {
                    Material::Pbr(b) => {
                        let frame = ShadingFrame::new(bent);
                        b.f_bumped(frame.to_local(-down), frame.to_local(wi), k)
                    }
                    _ => plain.f * k,
                };
                assert!(e.f.abs_diff_eq(want, 1e-6), "{mode:?}: {} against {want}", e.f);
                assert_eq!((e.pdf_dir, e.pdf_rev), (plain.pdf_dir, plain.pdf_rev));
            }
        }
    }
}

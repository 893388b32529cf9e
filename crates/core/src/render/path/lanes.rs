//! The path step for a packet's lanes side by side, in structure-of-arrays
//! form, where a lane's vertex is the common case: a plain diffuse surface
//! in a scene without media or textures, lit by point and spot lights
//! (a spot is a point light whose intensity falls off by direction). Other
//! vertices take the scalar step (`advance`).
//!
//! Why: against Mitsuba on the Cornell box (perf, one thread), hikari's
//! traversals take what Embree's do per frame, and its step and sampler
//! 1.8× what Mitsuba's vectorised wavefront code takes. One lane after
//! another, each vertex is a long chain of dependent operations (the
//! light's direction and falloff; the bounce's square roots, azimuth
//! polynomials and frame), and a chain overlapped little more than the
//! next lane's: perf found 45% of the step's time waiting at their ends.
//! Here the two chains run for the eight lanes at once in AVX2
//! (`point_light`, `sampling::cosine8`), and so do the normals' facing
//! and the throughput, density and roulette (`facing_normals`,
//! `scatter`: -2.8% wall); the shadow rays toward a light go through the
//! BVH as one packet (`Accel::occluded_packet`: shadow rays from a
//! packet's vertices converge on the light, so they share most of their
//! nodes; one thread, -11% of the Cornell box's wall time). The sampler's
//! numbers and the moves in and out of the paths stay lane by lane.
//!
//! Same numbers: the vector code is the scalar maths operation for
//! operation (Rust never fuses or reorders float operations, and vector
//! instructions round as scalar ones do), each lane draws its numbers in
//! the scalar step's order, so every lane gets the bits the scalar step
//! would give it: `point_light_lanes_give_the_scalar_bits`,
//! `facing_and_scatter_lanes_give_the_scalar_bits`, `cosine8`'s test,
//! and whole images against paths traced one at a time
//! (`paths_in_packets_match_paths_one_at_a_time`,
//! `the_lane_step_gives_the_scalar_steps_image`).

use super::{PathState, Previous};
use crate::geometry::packet::{LANES, RayLanes};
use crate::geometry::{Hit, Ray};
use crate::light::Light;
use crate::material::{Material, Rgb, mean};
use crate::sampling::Sampler;
use crate::sampling::cosine8::{Lanes3, cosine_directions};
use crate::scene::Scene;
use glam::Vec3;
use std::f32::consts::PI;

fn get(a: &Lanes3, i: usize) -> Vec3 {
    Vec3::new(a[0][i], a[1][i], a[2][i])
}

fn put(a: &mut Lanes3, i: usize, v: Vec3) {
    (a[0][i], a[1][i], a[2][i]) = (v.x, v.y, v.z);
}

/// A scene the lane step serves (no media, no textures, only point and
/// spot lights), with its lights and the surfaces it takes.
pub(super) struct LaneStep {
    /// Each light with its position and intensity, in the scene's order.
    lights: Vec<(Light, Vec3, Rgb)>,
    /// Each surface's albedo where the lane step takes its vertices: a
    /// diffuse material without a mirror part, not black, not emissive.
    albedo: Vec<Option<Rgb>>,
}

impl LaneStep {
    /// The lane step for `scene`, or None where it does not serve it.
    pub fn for_scene(scene: &Scene) -> Option<LaneStep> {
        if !scene.media.is_empty() || scene.texturing.is_some() {
            return None;
        }
        let lights = scene.lights.iter().map(|light| match *light {
            Light::Point { position, intensity } | Light::Spot { position, intensity, .. } => {
                Some((light.clone(), position, intensity))
            }
            _ => None,
        });
        let lights = lights.collect::<Option<_>>()?;
        let albedo = scene.surfaces.iter().map(|surface| match scene.materials[surface.material as usize] {
            _ if surface.emitter.is_some() => None,
            Material::Diffuse { albedo, specular } if specular == Rgb::ZERO && mean(albedo) > 0.0 => Some(albedo),
            _ => None,
        });
        Some(LaneStep { lights, albedo: albedo.collect() })
    }

    /// The albedo at `hit` where the lane step takes the vertex.
    pub fn albedo_at(&self, hit: &Hit) -> Option<Rgb> {
        self.albedo[hit.surface as usize]
    }
}

/// The vertices of the lanes taken, and after [`DiffuseLanes::step`] what
/// they lead to.
#[derive(Default)]
pub(super) struct DiffuseLanes {
    taken: [bool; LANES],
    // The path and its vertex.
    dir: Lanes3,
    point: Lanes3,
    geometric_normal: Lanes3,
    shading_normal: Lanes3,
    albedo: Lanes3,
    beta: Lanes3,
    l: Lanes3,
    bounce: [u32; LANES],
    // The numbers the vertex draws: the bounce's, and the roulette's
    // where it plays (from the fifth vertex).
    u: [[f32; LANES]; 2],
    roulette: [bool; LANES],
    xi: [f32; LANES],
    // What the step leaves.
    next_dir: Lanes3,
    pdf: [f32; LANES],
    goes_on: [bool; LANES],
}

impl DiffuseLanes {
    /// Takes lane `l`'s path at `hit` (whose material has `albedo`) and
    /// draws the numbers its vertex needs, in the scalar step's order.
    pub fn take(&mut self, l: usize, path: &PathState, hit: &Hit, albedo: Rgb, sampler: &mut impl Sampler) {
        self.taken[l] = true;
        put(&mut self.dir, l, path.ray.dir);
        put(&mut self.point, l, hit.point);
        put(&mut self.geometric_normal, l, hit.geometric_normal);
        put(&mut self.shading_normal, l, hit.shading_normal);
        put(&mut self.albedo, l, albedo);
        put(&mut self.beta, l, path.beta);
        put(&mut self.l, l, path.l);
        self.bounce[l] = path.bounce;
        let u = sampler.next_2d();
        (self.u[0][l], self.u[1][l]) = (u.x, u.y);
        self.roulette[l] = path.bounce >= 4;
        self.xi[l] = if self.roulette[l] { sampler.next_f32() } else { 0.0 };
    }

    /// Takes no lane (what the lanes held stays, unread, until taken).
    pub fn clear(&mut self) {
        self.taken = [false; LANES];
    }

    pub fn any(&self) -> bool {
        self.taken.contains(&true)
    }

    pub fn taken(&self, l: usize) -> bool {
        self.taken[l]
    }

    /// The taken lanes' vertices: light from each point or spot light, the
    /// cosine-distributed bounce, the roulette. Lanes not taken compute
    /// on whatever they hold and are never read.
    pub fn step(&mut self, scene: &Scene, step: &LaneStep, max_depth: u32) {
        let [ng, ns] = facing_normals(&self.dir, &self.geometric_normal, &self.shading_normal);
        // Next-event estimation (`next_event` for point and spot lights: density
        // 1, MIS weight 1, transmittance 1).
        let mut sum = Lanes3::default();
        for (light, position, intensity) in &step.lights {
            // A spot's falloff toward each vertex, lane by lane (its arc
            // cosine has no vector twin); a point light has none.
            let falloff = matches!(light, Light::Spot { .. }).then(|| {
                std::array::from_fn(|i| if self.taken[i] { light.falloff_toward(get(&self.point, i)) } else { 0.0 })
            });
            let in_cone: [bool; LANES] = match &falloff {
                Some(f) => std::array::from_fn(|i| !(f[i] <= 0.0)),
                None => self.taken,
            };
            let delta = DeltaLight { position: *position, intensity: *intensity, falloff: falloff.as_ref() };
            let PointLight { mut lit, wi, t_max, light } = point_light(&delta, &self.point, &ns, &self.albedo);
            for (lit, in_cone) in lit.iter_mut().zip(in_cone) {
                *lit &= in_cone;
            }
            let active = lit.iter().rev().fold(0, |bits, &lit| bits << 1 | u32::from(lit));
            let shadow_rays = RayLanes { origin: self.point, dir: wi, t_max, active };
            let blocked = scene.accel.occluded_packet(&shadow_rays);
            for (i, lit) in lit.iter_mut().enumerate() {
                *lit &= blocked & (1 << i) == 0;
            }
            for i in 0..LANES {
                let s = get(&sum, i);
                put(&mut sum, i, if lit[i] { s + get(&light, i) } else { s });
            }
        }
        let dirs = cosine_directions(&self.u, &ns);
        scatter(self, &sum, &dirs, &ns, &ng);
        for (goes_on, bounce) in self.goes_on.iter_mut().zip(&self.bounce) {
            *goes_on &= bounce + 1 < max_depth;
        }
    }

    /// Writes lane `l`'s step into its path: false where the path ends.
    pub fn finish(&self, l: usize, path: &mut PathState) -> bool {
        path.l = get(&self.l, l);
        path.beta = get(&self.beta, l);
        let point = get(&self.point, l);
        path.previous = Previous::Diffuse { point, pdf: self.pdf[l] };
        path.ray = Ray::new(point, get(&self.next_dir, l));
        path.bounce += 1;
        self.goes_on[l]
    }
}

/// The geometric and shading normals turned toward the side each lane's
/// ray `dir` came from (`advance`'s `facing`): in AVX2 where the CPU has
/// it, to the bit (a test checks it).
fn facing_normals(dir: &Lanes3, geometric: &Lanes3, shading: &Lanes3) -> [Lanes3; 2] {
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx2") {
        // SAFETY: AVX2 checked above.
        return unsafe { avx2::facing_normals(dir, geometric, shading) };
    }
    facing_normals_by_lane(dir, geometric, shading)
}

fn facing_normals_by_lane(dir: &Lanes3, geometric: &Lanes3, shading: &Lanes3) -> [Lanes3; 2] {
    let (mut ng, mut ns) = (Lanes3::default(), Lanes3::default());
    for i in 0..LANES {
        let facing = if get(dir, i).dot(get(geometric, i)) < 0.0 { 1.0 } else { -1.0 };
        put(&mut ng, i, get(geometric, i) * facing);
        put(&mut ns, i, get(shading, i) * facing);
    }
    [ng, ns]
}

/// The rest of the lanes' vertices once their direct light `sum` is
/// known: the light added, the diffuse bounce along `dirs` (its
/// throughput and density), the roulette, and whether the path goes on
/// as far as the vertex can tell (the depth limit aside). In AVX2 where
/// the CPU has it, to the bit (a test checks it).
fn scatter(v: &mut DiffuseLanes, sum: &Lanes3, dirs: &Lanes3, ns: &Lanes3, ng: &Lanes3) {
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx2") {
        // SAFETY: AVX2 checked above.
        return unsafe { avx2::scatter(v, sum, dirs, ns, ng) };
    }
    scatter_by_lane(v, sum, dirs, ns, ng)
}

fn scatter_by_lane(v: &mut DiffuseLanes, sum: &Lanes3, dirs: &Lanes3, ns: &Lanes3, ng: &Lanes3) {
    for i in 0..LANES {
        let (albedo, mut beta) = (get(&v.albedo, i), get(&v.beta, i));
        let l = get(&v.l, i) + beta * get(sum, i);
        put(&mut v.l, i, l);
        // The diffuse lobe, chosen with probability p_d / (p_d + 0) = 1
        // exactly (x / x is 1 in IEEE arithmetic for x finite, not 0),
        // so dividing by it and multiplying by it change no bit.
        beta *= albedo;
        let (n, dir) = (get(ns, i), get(dirs, i));
        v.pdf[i] = dir.dot(n).max(0.0) / PI;
        // `survives_roulette`.
        let survive = beta.max_element().min(0.95);
        let dies = v.roulette[i] && v.xi[i] >= survive;
        put(&mut v.beta, i, if v.roulette[i] { beta / survive } else { beta });
        put(&mut v.next_dir, i, dir);
        // Not `> 0.0`: the scalar step goes on where the cosine is NaN.
        v.goes_on[i] = !dies && !(dir.dot(get(ng, i)) <= 0.0);
    }
}

/// A point light, or a spot as the point light it is toward each of eight
/// vertices: its intensity scaled lane by lane by the spot's `falloff`.
#[derive(Clone, Copy)]
struct DeltaLight<'a> {
    position: Vec3,
    intensity: Rgb,
    falloff: Option<&'a [f32; LANES]>,
}

/// A point light's sample at eight vertices: where it can light them (at
/// a distance, in front of the shading normal), the direction and length
/// of the shadow ray, and the light it brings if unshadowed.
struct PointLight {
    lit: [bool; LANES],
    wi: Lanes3,
    t_max: [f32; LANES],
    light: Lanes3,
}

/// `next_event`'s sample of a point light (`Light::sample_incident`:
/// density 1, MIS weight 1, transmittance 1 without media) at eight
/// vertices `point` with shading normals `ns` and diffuse `albedo`: in
/// AVX2 where the CPU has it, to the bit (a test checks it).
fn point_light(light: &DeltaLight, point: &Lanes3, ns: &Lanes3, albedo: &Lanes3) -> PointLight {
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx2") {
        // SAFETY: AVX2 checked above.
        return unsafe { avx2::point_light(light, point, ns, albedo) };
    }
    point_light_by_lane(light, point, ns, albedo)
}

fn point_light_by_lane(light: &DeltaLight, point: &Lanes3, ns: &Lanes3, albedo: &Lanes3) -> PointLight {
    let DeltaLight { position, intensity, falloff } = *light;
    let mut out =
        PointLight { lit: [false; LANES], wi: Lanes3::default(), t_max: [0.0; LANES], light: Lanes3::default() };
    for i in 0..LANES {
        // `Light::sample_incident` of a spot: a point light of the
        // intensity it sends this way.
        let light = Light::Point { position, intensity: falloff.map_or(intensity, |f| intensity * f[i]) };
        let Some(s) = light.sample_incident(get(point, i), glam::Vec2::ZERO) else { continue };
        let cos = s.wi.dot(get(ns, i));
        out.lit[i] = !(cos <= 0.0 || s.pdf <= 0.0);
        put(&mut out.wi, i, s.wi);
        out.t_max[i] = s.distance * (1.0 - 1e-4);
        put(&mut out.light, i, get(albedo, i) / PI * s.radiance * Rgb::ONE * (cos * 1.0 / s.pdf));
    }
    out
}

#[cfg(target_arch = "x86_64")]
mod avx2 {
    use super::{DeltaLight, DiffuseLanes, LANES, Lanes3, PointLight};
    use std::arch::x86_64::*;
    use std::f32::consts::PI;

    /// Eight booleans as lane masks.
    #[target_feature(enable = "avx2")]
    fn mask(b: &[bool; LANES]) -> __m256 {
        let bits: [f32; LANES] = std::array::from_fn(|i| f32::from_bits(if b[i] { u32::MAX } else { 0 }));
        // SAFETY: 8 floats.
        unsafe { _mm256_loadu_ps(bits.as_ptr()) }
    }

    #[target_feature(enable = "avx2")]
    fn load3(a: &Lanes3) -> [__m256; 3] {
        // SAFETY: rows of 8 floats.
        std::array::from_fn(|k| unsafe { _mm256_loadu_ps(a[k].as_ptr()) })
    }

    #[target_feature(enable = "avx2")]
    fn store3(a: &mut Lanes3, v: [__m256; 3]) {
        for (row, v) in a.iter_mut().zip(v) {
            // SAFETY: rows of 8 floats.
            unsafe { _mm256_storeu_ps(row.as_mut_ptr(), v) };
        }
    }

    /// glam's `dot`: (x·x' + y·y') + z·z'.
    #[target_feature(enable = "avx2")]
    fn dot(a: [__m256; 3], b: [__m256; 3]) -> __m256 {
        _mm256_add_ps(_mm256_add_ps(_mm256_mul_ps(a[0], b[0]), _mm256_mul_ps(a[1], b[1])), _mm256_mul_ps(a[2], b[2]))
    }

    /// `facing_normals_by_lane`, operation for operation.
    #[target_feature(enable = "avx2")]
    pub fn facing_normals(dir: &Lanes3, geometric: &Lanes3, shading: &Lanes3) -> [Lanes3; 2] {
        let (gn, sn) = (load3(geometric), load3(shading));
        let front = _mm256_cmp_ps::<_CMP_LT_OQ>(dot(load3(dir), gn), _mm256_setzero_ps());
        let facing = _mm256_blendv_ps(_mm256_set1_ps(-1.0), _mm256_set1_ps(1.0), front);
        let (mut ng, mut ns) = (Lanes3::default(), Lanes3::default());
        store3(&mut ng, gn.map(|c| _mm256_mul_ps(c, facing)));
        store3(&mut ns, sn.map(|c| _mm256_mul_ps(c, facing)));
        [ng, ns]
    }

    /// `scatter_by_lane`, operation for operation (f32::max and min as
    /// maxps and minps: the same wherever no operand is NaN, and a
    /// density of ±0 either way where the cosine is).
    #[target_feature(enable = "avx2")]
    pub fn scatter(v: &mut DiffuseLanes, sum: &Lanes3, dirs: &Lanes3, ns: &Lanes3, ng: &Lanes3) {
        let (add, mul, div) = (_mm256_add_ps, _mm256_mul_ps, _mm256_div_ps);
        let (beta, sum, l, albedo) = (load3(&v.beta), load3(sum), load3(&v.l), load3(&v.albedo));
        store3(&mut v.l, std::array::from_fn(|k| add(l[k], mul(beta[k], sum[k]))));
        let beta: [__m256; 3] = std::array::from_fn(|k| mul(beta[k], albedo[k]));
        let dir = load3(dirs);
        let pdf = div(_mm256_max_ps(dot(dir, load3(ns)), _mm256_setzero_ps()), _mm256_set1_ps(PI));
        let survive = _mm256_min_ps(_mm256_max_ps(_mm256_max_ps(beta[0], beta[1]), beta[2]), _mm256_set1_ps(0.95));
        let roulette = mask(&v.roulette);
        // SAFETY: 8 floats.
        let xi = unsafe { _mm256_loadu_ps(v.xi.as_ptr()) };
        let dies = _mm256_and_ps(roulette, _mm256_cmp_ps::<_CMP_GE_OQ>(xi, survive));
        store3(&mut v.beta, beta.map(|c| _mm256_blendv_ps(c, div(c, survive), roulette)));
        v.next_dir = *dirs;
        // SAFETY: 8 floats.
        unsafe { _mm256_storeu_ps(v.pdf.as_mut_ptr(), pdf) };
        let away = _mm256_cmp_ps::<_CMP_LE_OQ>(dot(dir, load3(ng)), _mm256_setzero_ps());
        let ends = _mm256_movemask_ps(_mm256_or_ps(dies, away));
        v.goes_on = std::array::from_fn(|i| ends & (1 << i) == 0);
    }

    /// `point_light_by_lane`, operation for operation.
    #[target_feature(enable = "avx2")]
    pub fn point_light(light: &DeltaLight, point: &Lanes3, ns: &Lanes3, albedo: &Lanes3) -> PointLight {
        let DeltaLight { position, intensity, falloff } = *light;
        let (mul, add, sub, div, s) = (_mm256_mul_ps, _mm256_add_ps, _mm256_sub_ps, _mm256_div_ps, _mm256_set1_ps);
        // SAFETY (loads and stores): rows of 8 floats.
        let ld = |row: &[f32; LANES]| unsafe { _mm256_loadu_ps(row.as_ptr()) };
        let to =
            [sub(s(position.x), ld(&point[0])), sub(s(position.y), ld(&point[1])), sub(s(position.z), ld(&point[2]))];
        let d2 = add(add(mul(to[0], to[0]), mul(to[1], to[1])), mul(to[2], to[2]));
        let distance = _mm256_sqrt_ps(d2);
        let wi = [div(to[0], distance), div(to[1], distance), div(to[2], distance)];
        let cos = add(add(mul(wi[0], ld(&ns[0])), mul(wi[1], ld(&ns[1]))), mul(wi[2], ld(&ns[2])));
        // d2 ≠ 0 (else no sample) and not cos ≤ 0.
        let zero = _mm256_setzero_ps();
        let lit = _mm256_andnot_ps(_mm256_cmp_ps::<_CMP_LE_OQ>(cos, zero), _mm256_cmp_ps::<_CMP_NEQ_UQ>(d2, zero));
        let bits = _mm256_movemask_ps(lit);
        let mut out = PointLight {
            lit: std::array::from_fn(|i| bits & (1 << i) != 0),
            wi: Lanes3::default(),
            t_max: [0.0; LANES],
            light: Lanes3::default(),
        };
        unsafe {
            _mm256_storeu_ps(out.t_max.as_mut_ptr(), mul(distance, s(1.0 - 1e-4)));
            for k in 0..3 {
                _mm256_storeu_ps(out.wi[k].as_mut_ptr(), wi[k]);
                let toward = falloff.map_or(s(intensity[k]), |f| mul(s(intensity[k]), ld(f)));
                let radiance = div(toward, d2);
                let light = mul(mul(div(ld(&albedo[k]), s(PI)), radiance), cos);
                _mm256_storeu_ps(out.light[k].as_mut_ptr(), light);
            }
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampling::Rng;

    /// A point light's sample at eight vertices at once has the bits of
    /// the scalar one's wherever it lights the vertex (elsewhere its
    /// numbers are never read): random vertices and normals, the light
    /// at a vertex, behind it and on its plane.
    #[test]
    fn point_light_lanes_give_the_scalar_bits() {
        let mut rng = Rng::for_item(11, 0);
        let mut random = || rng.next_f32() * 4.0 - 2.0;
        let position = Vec3::new(0.25, 0.9, -0.5);
        let intensity = Rgb::new(2.5, 1.0, 0.125);
        let mut checked = 0;
        for round in 0..500 {
            let mut point: Lanes3 = std::array::from_fn(|_| std::array::from_fn(|_| random()));
            let mut ns: Lanes3 = Lanes3::default();
            for i in 0..LANES {
                let n = Vec3::new(random(), random(), random()).normalize_or(Vec3::Y);
                put(&mut ns, i, n);
            }
            if round == 0 {
                put(&mut point, 0, position); // at the light
                put(&mut point, 1, position - Vec3::Y); // right below, facing it
                put(&mut ns, 1, Vec3::Y);
                put(&mut ns, 2, (position - get(&point, 2)).cross(Vec3::X).normalize()); // edge-on
            }
            let albedo: Lanes3 = std::array::from_fn(|_| std::array::from_fn(|_| random().abs()));
            // Every other round as a spot's, with a falloff in each lane.
            let falloff: [f32; LANES] = std::array::from_fn(|i| (i + 1) as f32 / 8.0 - 0.1 * (round % 3) as f32);
            let falloff = (round % 2 == 1).then_some(&falloff);
            let light = DeltaLight { position, intensity, falloff };
            let got = point_light(&light, &point, &ns, &albedo);
            let want = point_light_by_lane(&light, &point, &ns, &albedo);
            assert_eq!(got.lit, want.lit, "round {round}");
            let same = |a: f32, b: f32| a.to_bits() == b.to_bits();
            for i in (0..LANES).filter(|&i| want.lit[i]) {
                checked += 1;
                assert!(same(got.t_max[i], want.t_max[i]), "round {round} lane {i}");
                for k in 0..3 {
                    assert!(same(got.wi[k][i], want.wi[k][i]), "round {round} lane {i}");
                    assert!(same(got.light[k][i], want.light[k][i]), "round {round} lane {i}");
                }
            }
        }
        assert!(checked > 1000, "{checked}");
    }

    /// The normals' facing and the rest of the vertex (`scatter`) in
    /// eight lanes at once have the scalar loop's bits: random paths,
    /// directions and normals (some facing away, some at grazing angles),
    /// throughputs that survive the roulette and that do not; a density
    /// of zero may differ in its sign alone.
    #[test]
    fn facing_and_scatter_lanes_give_the_scalar_bits() {
        let mut rng = Rng::for_item(12, 0);
        let mut random = || rng.next_f32() * 2.0 - 1.0;
        let (mut ended, mut roulette_played) = (0, 0);
        for round in 0..500 {
            let mut lanes3 = || -> Lanes3 { std::array::from_fn(|_| std::array::from_fn(|_| random())) };
            let (mut dir, mut geometric, shading, sum, mut dirs) = (lanes3(), lanes3(), lanes3(), lanes3(), lanes3());
            if round == 0 {
                // A ray along its surface: the cosine is exactly 0.
                (put(&mut dir, 3, Vec3::X), put(&mut geometric, 3, Vec3::Y));
            }
            let [ng, ns] = facing_normals(&dir, &geometric, &shading);
            assert_eq!(
                [ng, ns].map(bits),
                facing_normals_by_lane(&dir, &geometric, &shading).map(bits),
                "round {round}"
            );
            let mut v = DiffuseLanes {
                albedo: lanes3().map(|row| row.map(f32::abs)),
                beta: lanes3().map(|row| row.map(|b| b.abs() * 2.0)),
                l: lanes3(),
                roulette: std::array::from_fn(|i| (round + i) % 3 != 0),
                xi: std::array::from_fn(|_| random().abs()),
                ..DiffuseLanes::default()
            };
            if round == 0 {
                put(&mut v.beta, 0, Vec3::ZERO); // survives with probability 0
                put(&mut dirs, 1, get(&ns, 1).cross(Vec3::X)); // a grazing bounce
                // Survives with probability 0.95 and draws exactly that.
                (put(&mut v.beta, 2, Vec3::splat(1.0)), put(&mut v.albedo, 2, Vec3::splat(1.0)));
                (v.roulette[2], v.xi[2]) = (true, 0.95);
            }
            let mut by_lane = DiffuseLanes { ..v };
            scatter(&mut v, &sum, &dirs, &ns, &ng);
            scatter_by_lane(&mut by_lane, &sum, &dirs, &ns, &ng);
            assert_eq!([v.l, v.beta, v.next_dir].map(bits), [by_lane.l, by_lane.beta, by_lane.next_dir].map(bits));
            assert_eq!(v.pdf, by_lane.pdf, "round {round}");
            assert_eq!(v.goes_on, by_lane.goes_on, "round {round}");
            ended += v.goes_on.iter().filter(|&&g| !g).count();
            roulette_played += v.roulette.iter().filter(|&&r| r).count();
        }
        assert!(ended > 500 && roulette_played > 2000, "{ended} ended, {roulette_played} played");
    }

    fn bits(a: Lanes3) -> [[u32; LANES]; 3] {
        a.map(|row| row.map(f32::to_bits))
    }
}

//! The multiple-importance weights of vertex connection and merging, in the
//! recursive form of Georgiev et al.'s technical report ("Implementing
//! vertex connection and merging", 2012; SmallVCM follows it): each subpath
//! carries three running sums (dVCM, dVC, dVM) from which the weight of
//! every strategy that completes a path at its end vertex follows in O(1).
//! The weights use Veach's power heuristic with β = 2 (`mis`), which on
//! the Cornell box (256², 20 s) left 8.9% error where the balance
//! heuristic left 10.2%.
//!
//! Every function here is a pure function of the subpaths' sums and the
//! densities at the vertices a strategy joins, so the test below can check
//! them against Veach's explicit formula on paths given vertex by vertex.

use std::f32::consts::PI;

/// β of the power heuristic: each strategy weighs (count × density)^β.
pub const HEURISTIC_POWER: i32 = 2;

/// A density ratio to the heuristic's power.
pub fn mis(x: f32) -> f32 {
    x.powi(HEURISTIC_POWER)
}

/// Which strategies an iteration uses: connections (next-event estimation,
/// bidirectional connections, light tracing), merging (photon density
/// estimation), or both; their per-iteration constants.
///
/// Merging has a kernel per kind of vertex: a disc of radius r on surfaces
/// (η = π r² N_L), a ball of radius r_v in media (η = 4/3 π r_v³ N_L). So η
/// is a property of the vertex where a merge happens, and the sums below
/// carry it per vertex; with one kind of vertex they are Georgiev et al.'s
/// exactly (dVM there is this dVM over η).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Factors {
    /// 1 when connections are on, else 0.
    connect: f32,
    merge: bool,
    /// η on surfaces and in media (not to the heuristic's power).
    surface_eta: f32,
    volume_eta: f32,
    /// N_L: light subpaths per iteration (one per pixel).
    pub light_paths: f32,
}

impl Factors {
    pub fn new(radius: f32, volume_radius: f32, light_paths: f32, connect: bool, merge: bool) -> Self {
        let (radius, volume_radius) = (radius.max(1e-7), volume_radius.max(1e-7));
        Factors {
            connect: if connect { 1.0 } else { 0.0 },
            merge,
            surface_eta: PI * radius * radius * light_paths,
            volume_eta: 4.0 / 3.0 * PI * volume_radius.powi(3) * light_paths,
            light_paths,
        }
    }

    /// η of a merge at a vertex in a medium (`medium`) or on a surface, to
    /// the heuristic's power; 0 when merging is off.
    pub fn eta(&self, medium: bool) -> f32 {
        if self.merge { mis(self.raw_eta(medium)) } else { 0.0 }
    }

    fn raw_eta(&self, medium: bool) -> f32 {
        if medium { self.volume_eta } else { self.surface_eta }
    }

    /// 1/η: a merge's density-estimation kernel and path count.
    pub fn normalization(&self, medium: bool) -> f32 {
        1.0 / self.raw_eta(medium)
    }
}

/// A subpath's running sums (tech. rep. eqs. 31–36), dVM multiplied by
/// the η of the subpath's current vertex (so that it stays a sum of
/// density ratios where η changes from vertex to vertex).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SubpathMis {
    pub d_vcm: f32,
    pub d_vc: f32,
    pub d_vm: f32,
}

impl SubpathMis {
    /// A light subpath leaving its light: `emission_pdf_w` is the density
    /// of its start (position × direction, light choice included),
    /// `direct_pdf` that of next-event estimation choosing the same light
    /// point (area measure for finite lights, solid angle for distant ones;
    /// 1 for a delta position; for lights whose direct sampling depends on
    /// the receiver, pass 1 and call [`SubpathMis::direct_pdf_known`] at the
    /// first hit), `cos_light` the cosine at the light (1 for distant
    /// lights). Delta lights cannot be hit, so dVC starts at 0.
    pub fn light_start(emission_pdf_w: f32, direct_pdf: f32, cos_light: f32, delta: bool, f: &Factors) -> Self {
        let d_vc = if delta { 0.0 } else { mis(cos_light / emission_pdf_w) };
        SubpathMis { d_vcm: mis(direct_pdf / emission_pdf_w), d_vc, d_vm: d_vc * f.connect }
    }

    /// Multiplies in the direct-sampling density that `light_start` was
    /// given as 1 (a sphere light's cone depends on the receiver).
    pub fn direct_pdf_known(&mut self, direct_pdf: f32) {
        self.d_vcm *= mis(direct_pdf);
    }

    /// A camera subpath leaving the eye with the solid-angle density
    /// `camera_pdf_w` of its first direction (per unit pixel area).
    pub fn camera_start(camera_pdf_w: f32, f: &Factors) -> Self {
        SubpathMis { d_vcm: mis(f.light_paths / camera_pdf_w), d_vc: 0.0, d_vm: 0.0 }
    }

    /// The subpath's ray arrived `distance` away. `arrival` turns the
    /// density per steradian of its direction into one per unit area (or
    /// volume) there, apart from 1/d²: on a surface the cosine there times
    /// the probability that the free flight passed every medium on the way
    /// (e^−τ̄, 1 without media), in a medium the flight's density σ̄ e^−τ̄.
    /// `departure` does the same for the reverse direction at the vertex it
    /// left, apart from the cosine its scattering already counted: e^−τ̄
    /// from a surface, σ̄ e^−τ̄ from a medium vertex. `finite`: false for
    /// the first segment of a distant light's subpath (its densities are per
    /// solid angle, not per area).
    pub fn arrive(&mut self, distance_squared: f32, arrival: f32, departure: f32, finite: bool) {
        if finite {
            self.d_vcm *= mis(distance_squared);
        }
        let arrival = mis(arrival.abs());
        let ratio = mis(departure) / arrival;
        self.d_vcm /= arrival;
        self.d_vc *= ratio;
        self.d_vm *= ratio;
    }

    /// The subpath scattered by a delta lobe (the forward and reverse
    /// densities are the same choice and cancel), leaving with cosine `cos_out`.
    pub fn scatter_delta(&mut self, cos_out: f32) {
        self.d_vcm = 0.0;
        self.d_vc *= mis(cos_out);
        self.d_vm *= mis(cos_out);
    }

    /// The subpath scattered by a non-delta lobe: `pdf_dir` the density of
    /// the direction taken, `pdf_rev` that of the reverse (both per
    /// steradian, continuation included), leaving with cosine `cos_out` (1
    /// in a medium); `eta` that of a merge at this vertex ([`Factors::eta`]).
    pub fn scatter(&mut self, cos_out: f32, pdf_dir: f32, pdf_rev: f32, eta: f32, f: &Factors) {
        let g = mis(cos_out / pdf_dir);
        let d_vc = g * (self.d_vc * mis(pdf_rev) + self.d_vcm + eta);
        let d_vm = g * (self.d_vm * mis(pdf_rev) + self.d_vcm * f.connect + eta);
        *self = SubpathMis { d_vcm: mis(1.0 / pdf_dir), d_vc, d_vm };
    }
}

/// Weight of a camera subpath that hits an emitter (or escapes to the sky):
/// `direct_pdf` the density of next-event estimation choosing that point
/// (area; solid angle for the sky), `emission_pdf_w` that of a light
/// subpath starting there toward the camera vertex, both with the light's
/// choice. A camera ray that hits it first gets 1 (no other strategy
/// draws it).
pub fn emitter_hit(camera: &SubpathMis, direct_pdf: f32, emission_pdf_w: f32) -> f32 {
    let w_camera = mis(direct_pdf) * camera.d_vcm + mis(emission_pdf_w) * camera.d_vc;
    1.0 / (1.0 + w_camera)
}

/// Densities of next-event estimation at a camera vertex.
#[derive(Clone, Copy, Debug)]
pub struct NextEvent {
    /// Of the BSDF sampling toward the light (continuation included; 0 for
    /// a delta light, which BSDF sampling never finds).
    pub bsdf_dir_pdf_w: f32,
    /// Of the BSDF sampling the camera subpath's incoming direction from
    /// the light's (continuation included).
    pub bsdf_rev_pdf_w: f32,
    /// Of the light's choice × its direct sampling, per steradian at the
    /// vertex (point lights: the squared distance).
    pub direct_pdf_w: f32,
    /// Of a light subpath starting at the light point toward the vertex
    /// (light choice included).
    pub emission_pdf_w: f32,
    /// As [`SubpathMis::arrive`]'s `arrival` for a ray from the light to
    /// the vertex: the cosine there (σ̄ in a medium) times e^−τ̄.
    pub vertex_arrival: f32,
    /// e^−τ̄ between the vertex and the light: the probability that a ray
    /// the vertex samples toward the light reaches it (1 without media).
    pub passes: f32,
    /// Cosine at the light point (1 for point and distant lights).
    pub cos_at_light: f32,
}

/// `eta`: of a merge at the vertex ([`Factors::eta`]).
pub fn next_event(camera: &SubpathMis, d: &NextEvent, eta: f32) -> f32 {
    let w_light = mis(d.bsdf_dir_pdf_w * d.passes / d.direct_pdf_w);
    let w_camera = mis(d.emission_pdf_w * d.vertex_arrival / (d.direct_pdf_w * d.cos_at_light))
        * (eta + camera.d_vcm + camera.d_vc * mis(d.bsdf_rev_pdf_w));
    1.0 / (w_light + 1.0 + w_camera)
}

/// Weight of connecting a light vertex to the eye (light tracing):
/// `camera_pdf_a` the density, per unit area (volume) at the vertex, of
/// the camera choosing it; `bsdf_rev_pdf_w` that of the light vertex's
/// BSDF sampling its incoming direction from the eye's (continuation
/// included); `eta` of a merge at the vertex.
pub fn light_tracing(light: &SubpathMis, camera_pdf_a: f32, bsdf_rev_pdf_w: f32, eta: f32, f: &Factors) -> f32 {
    let w_light = mis(camera_pdf_a / f.light_paths) * (eta + light.d_vcm + light.d_vc * mis(bsdf_rev_pdf_w));
    1.0 / (w_light + 1.0)
}

/// Densities at the two ends of a connection between a camera vertex and
/// a light vertex (continuations included; "per unit area" is per unit
/// volume at a medium vertex, and includes the free flight's density).
#[derive(Clone, Copy, Debug)]
pub struct Connection {
    /// The camera vertex's BSDF choosing the light vertex, per unit area there.
    pub camera_dir_pdf_a: f32,
    /// The camera vertex's BSDF choosing its own incoming direction from the connection's.
    pub camera_rev_pdf_w: f32,
    /// The light vertex's BSDF choosing the camera vertex, per unit area there.
    pub light_dir_pdf_a: f32,
    /// The light vertex's BSDF choosing its incoming direction from the connection's.
    pub light_rev_pdf_w: f32,
    /// [`Factors::eta`] at the camera vertex and at the light vertex.
    pub camera_eta: f32,
    pub light_eta: f32,
}

pub fn connection(camera: &SubpathMis, light: &SubpathMis, d: &Connection) -> f32 {
    let w_light = mis(d.camera_dir_pdf_a) * (d.light_eta + light.d_vcm + light.d_vc * mis(d.light_rev_pdf_w));
    let w_camera = mis(d.light_dir_pdf_a) * (d.camera_eta + camera.d_vcm + camera.d_vc * mis(d.camera_rev_pdf_w));
    1.0 / (w_light + 1.0 + w_camera)
}

/// An upper bound on the weight of any merge at a camera vertex with sums
/// `camera` (eta: [`Factors::eta`] there, not 0): [`merge`]'s weight
/// without the terms that depend on the light vertex and the directions.
pub fn merge_bound(camera: &SubpathMis, eta: f32, f: &Factors) -> f32 {
    1.0 / (1.0 + camera.d_vcm * f.connect / eta)
}

/// Weight of merging a camera vertex with a light vertex at (nearly) the
/// same point: `camera_dir_pdf_w` the camera vertex's BSDF choosing the
/// light vertex's incoming direction (its continuation), `camera_rev_pdf_w`
/// it choosing its own incoming direction from there (the light vertex's
/// continuation, which would govern it); `eta` of the merge
/// ([`Factors::eta`], not 0).
pub fn merge(
    camera: &SubpathMis,
    light: &SubpathMis,
    camera_dir_pdf_w: f32,
    camera_rev_pdf_w: f32,
    eta: f32,
    f: &Factors,
) -> f32 {
    let w_light = (light.d_vcm * f.connect + light.d_vm * mis(camera_dir_pdf_w)) / eta;
    let w_camera = (camera.d_vcm * f.connect + camera.d_vm * mis(camera_rev_pdf_w)) / eta;
    1.0 / (w_light + 1.0 + w_camera)
}

#[cfg(test)]
mod tests;

//! `vcm`: vertex connection and merging (Georgiev, Křivánek, Davidovič &
//! Slusallek 2012; Hachisuka, Pantaleoni & Jensen's "unified path
//! sampling"), progressive like the photon mappers: each pass traces one
//! light subpath per pixel, connects each of its vertices to the eye (light
//! tracing), then traces one camera subpath per pixel that samples lights
//! (next-event estimation), connects to every vertex of its pixel's light
//! subpath (bidirectional path tracing) and merges with the light vertices
//! of all subpaths within the pass's radius (photon density estimation,
//! the radius shrinking as the photon maps' does), every contribution
//! weighted by multiple importance sampling over all of these strategies
//! ([`mis`]). SmallVCM, the authors' reference implementation, was read,
//! not copied.
//!
//! [`Strategies`] turns parts off: without merging it is bidirectional
//! path tracing (unbiased: it converges to `path`), without connections
//! progressive photon mapping of every bounce, and `LightTracing` the
//! light-tracing strategy alone (plus the lights the eye sees directly).
//!
//! In participating media both subpaths sample free flights ([`flight`]):
//! a flight that ends in a medium makes a volume vertex, scattering by the
//! phase functions there; connections and next-event estimation carry the
//! transmittance between their ends; volume vertices merge with the light
//! subpaths' volume vertices within a ball (surface vertices with surface
//! vertices within a disc), and the weights count the flights' densities
//! (σ̄ e^−τ̄ to stop at a point, e^−τ̄ to pass). Surfaces shade with
//! their normal textures' bent normals (`Scene::bent`), as every renderer.

pub mod emitters;
mod flight;
mod grid;
pub mod mis;
mod scatter;

use self::emitters::Emitters;
use self::flight::Event;
use self::grid::HashGrid;
use self::mis::{Factors, SubpathMis};
use self::scatter::Scatter;
use super::Image;
use crate::bsdf::dielectric::Transport;
use crate::geometry::Ray;
use crate::light::Light;
use crate::material::{Material, Rgb};
use crate::progressive::RadiusSchedule;
use crate::sampling::Rng;
use crate::scene::Scene;
use glam::{Vec2, Vec3};
use rayon::prelude::*;

/// Which of VCM's strategies a render uses.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Strategies {
    /// All of them: connections and merging.
    All,
    /// Connections only: bidirectional path tracing (unbiased).
    Connections,
    /// Merging only: progressive photon mapping at every camera vertex.
    Merging,
    /// Light subpaths connected to the eye, unweighted, plus the lights
    /// camera rays hit first.
    LightTracing,
}

impl Strategies {
    fn connect(self) -> bool {
        matches!(self, Strategies::All | Strategies::Connections)
    }

    fn merge(self) -> bool {
        matches!(self, Strategies::All | Strategies::Merging)
    }
}

#[derive(Clone, Debug)]
pub struct VcmSettings {
    pub seed: u64,
    pub strategies: Strategies,
    /// Longest path, in segments from the eye to the light.
    pub max_path_length: u32,
    /// The first pass's merging radius on surfaces (default [`default_radius`]).
    pub radius: Option<f32>,
    /// The first pass's merging radius in media (default [`default_volume_radius`]).
    pub volume_radius: Option<f32>,
    /// The radius schedule's α (as the photon maps').
    pub alpha: f32,
}

impl Default for VcmSettings {
    fn default() -> Self {
        VcmSettings {
            seed: 0,
            strategies: Strategies::All,
            max_path_length: 32,
            radius: None,
            volume_radius: None,
            alpha: crate::progressive::DEFAULT_ALPHA,
        }
    }
}

/// The first pass's merging radius: 0.1% of the scene's diagonal. MIS
/// weighs a merge against a connection by η = π r² × light subpaths, which
/// counts every light vertex in the disc as an independent sample; a larger
/// radius gives merging weight its noise does not earn. At 256², 20 s:
/// 0.5% left 8.0% error on the Cornell box (bidirectional alone 5.2%), 0.1%
/// 5.9%; through glass 7.9% and 6.2%. Merging carries what connections
/// cannot (caustics seen through glass or in a mirror).
pub fn default_radius(scene: &Scene) -> f32 {
    0.001 * scene.diagonal()
}

/// The first pass's merging radius in media: 0.3% of the scene's
/// diagonal. In thin fog merges carry little weight, and a larger ball
/// reaches through the surfaces that bound a medium: at 1% the layered fog
/// stage (128², 20 s) read 0.7% too dark and 10.7% error, at 0.3% 0.07% and
/// 9.6% (0.1%: the same).
pub fn default_volume_radius(scene: &Scene) -> f32 {
    0.003 * scene.diagonal()
}

/// Below this bound on their MIS weight ([`mis::merge_bound`]), a camera
/// vertex's merges are made by Russian roulette, with probability bound /
/// this, and count 1/probability: unbiased, and the merges that carry an
/// image alone (after a mirror or glass the bound is 1) are all made. On
/// the Cornell box (256²) 80% of camera vertices could only merge with
/// weights below 0.1, and merges gave 0.4% of the image for a quarter of
/// a pass's time. Error at 20 s (256², 128² in fog) without the roulette /
/// with this at 0.25 / 0.5: Cornell box 4.38% / 4.07% / 3.97%, glass ball
/// 4.66% / 4.76% / 4.74%, fog-stage 4.17% / 3.88% / 3.90%.
const MERGE_ROULETTE_WEIGHT: f32 = 0.5;

/// A stored light-subpath vertex, as connections read it.
struct LightVertex {
    position: Vec3,
    throughput: Rgb,
    /// Segments from the light.
    length: u32,
    scatter: Scatter,
    mis: SubpathMis,
}

/// What a merge reads of a light vertex: a fifth of a [`LightVertex`],
/// stored in its grid's order so that a query reads them in sequence.
#[derive(Clone, Copy)]
struct MergeRecord {
    /// The throughput, without σ_s in a medium (the camera vertex's
    /// throughput carries the σ_s of the merged point).
    throughput: Rgb,
    /// Toward where the light subpath came from.
    wo: Vec3,
    /// The light vertex's Russian-roulette probability.
    continuation: f32,
    length: u32,
    mis: SubpathMis,
}

/// One pass's shared state.
struct Pass<'a> {
    scene: &'a Scene,
    emitters: Emitters<'a>,
    factors: Factors,
    strategies: Strategies,
    max_length: u32,
    image_plane: f32,
}

/// Light subpaths a chunk holds: chunks are traced in parallel and read
/// in order, so the image does not depend on the thread count.
const CHUNK: usize = 256;

/// What a chunk of light subpaths leaves: its vertices for connections
/// (subpath by subpath) and where each subpath ends, its vertices for
/// merging (on surfaces, in media), and its light-tracing splats.
#[derive(Default)]
struct LightChunk {
    vertices: Vec<LightVertex>,
    ends: Vec<u32>,
    surface: Vec<(Vec3, MergeRecord)>,
    volume: Vec<(Vec3, MergeRecord)>,
    splats: Vec<(u32, Rgb)>,
}

impl LightChunk {
    fn clear(&mut self) {
        self.vertices.clear();
        self.ends.clear();
        self.surface.clear();
        self.volume.clear();
        self.splats.clear();
    }
}

/// The buffers of VCM passes, kept from pass to pass: a pass at 256²
/// writes ~10⁵ light vertices (tens of MB). Fresh pages for them each
/// pass, and joining the chunks into one array, took a Cornell-box pass
/// (256², 2 cores) to 120 ms where it now takes 86 ms.
#[derive(Default)]
pub struct Workspace {
    chunks: Vec<LightChunk>,
    surface: MergeGrid,
    volume: MergeGrid,
}

/// Pass `pass` (from 1): one light subpath and one camera subpath per
/// pixel. Returns the pass's image and the number of non-finite
/// contributions dropped. (A progressive render keeps one [`Workspace`]
/// for all its passes: [`render_pass_in`].)
pub fn render_pass(scene: &Scene, settings: &VcmSettings, pass: u32) -> Result<(Image, u64), String> {
    render_pass_in(&mut Workspace::default(), scene, settings, pass)
}

/// [`render_pass`] in `workspace`'s buffers.
pub fn render_pass_in(
    workspace: &mut Workspace,
    scene: &Scene,
    settings: &VcmSettings,
    pass: u32,
) -> Result<(Image, u64), String> {
    let camera = &scene.camera;
    let (width, height) = (camera.width, camera.height);
    let pixels = (width * height) as usize;
    let radius =
        RadiusSchedule::disc(settings.radius.unwrap_or_else(|| default_radius(scene)), settings.alpha).radius(pass);
    let volume_radius =
        RadiusSchedule::ball(settings.volume_radius.unwrap_or_else(|| default_volume_radius(scene)), settings.alpha)
            .radius(pass);
    let strategies = settings.strategies;
    // One light subpath per pixel: more a pass (2, 4, 8 per pixel) left
    // more error after 20 s on the Cornell box (13%, 20%, 27% against 8%):
    // the passes slow as much, and the camera subpaths carry most paths.
    let light_paths = pixels;
    let p = Pass {
        scene,
        emitters: Emitters::new(scene),
        factors: Factors::new(radius, volume_radius, light_paths as f32, strategies.connect(), strategies.merge()),
        strategies,
        max_length: settings.max_path_length.max(1),
        image_plane: camera.image_plane_distance(),
    };
    let seed = crate::progressive::pass_seed(settings.seed, pass);

    // Light subpaths, in chunks.
    let Workspace { chunks, surface, volume } = workspace;
    chunks.resize_with(light_paths.div_ceil(CHUNK), LightChunk::default);
    chunks.par_iter_mut().enumerate().for_each(|(c, chunk)| {
        chunk.clear();
        for i in c * CHUNK..((c + 1) * CHUNK).min(light_paths) {
            let mut rng = Rng::for_item(seed ^ 0x11c4_7a7b_0000_0001, i as u64);
            p.trace_light(&mut rng, chunk);
            chunk.ends.push(chunk.vertices.len() as u32);
        }
    });
    let merge = strategies.merge();
    let media = !scene.media.is_empty();
    let (surface_grid, volume_grid) = rayon::join(
        || merge.then(|| surface.rebuild(chunks.iter().map(|c| &c.surface[..]), radius)),
        || (merge && media).then(|| volume.rebuild(chunks.iter().map(|c| &c.volume[..]), volume_radius)),
    );
    let light = Subpaths { chunks, surface: surface_grid.map(|_| &*surface), volume: volume_grid.map(|_| &*volume) };

    // Camera subpaths, pixel by pixel.
    let mut image = Image::new(width, height);
    let nonfinite: u64 = image
        .pixels
        .par_chunks_mut(width as usize)
        .enumerate()
        .map(|(y, row)| {
            let mut bad = 0;
            for (x, out) in row.iter_mut().enumerate() {
                let index = y * width as usize + x;
                let mut rng = Rng::for_item(seed ^ 0xca3e_7a00_0000_0002, index as u64);
                let value = p.trace_camera(Vec2::new(x as f32, y as f32), index, &light, &mut rng);
                if value.is_finite() {
                    *out = value;
                } else {
                    bad += 1;
                }
            }
            bad
        })
        .sum();
    let mut dropped = nonfinite;
    for &(pixel, value) in chunks.iter().flat_map(|c| &c.splats) {
        if value.is_finite() {
            image.pixels[pixel as usize] += value;
        } else {
            dropped += 1;
        }
    }
    Ok((image, dropped))
}

/// The pass's light subpaths as camera subpaths read them.
struct Subpaths<'a> {
    chunks: &'a [LightChunk],
    /// The surface vertices and the volume vertices, for merging.
    surface: Option<&'a MergeGrid>,
    volume: Option<&'a MergeGrid>,
}

impl Subpaths<'_> {
    /// The vertices of light subpath `index` (the pixel's own).
    fn of_pixel(&self, index: usize) -> &[LightVertex] {
        let (chunk, local) = (&self.chunks[index / CHUNK], index % CHUNK);
        let start = if local == 0 { 0 } else { chunk.ends[local - 1] as usize };
        &chunk.vertices[start..chunk.ends[local] as usize]
    }
}

/// The light vertices of one kind (surface or volume) in a hash grid.
#[derive(Default)]
struct MergeGrid {
    /// Scratch: the vertices' positions and records in chunk order.
    positions: Vec<Vec3>,
    unordered: Vec<MergeRecord>,
    /// The vertices' records in the grid's slot order.
    records: Vec<MergeRecord>,
    grid: HashGrid,
}

impl MergeGrid {
    fn rebuild<'a>(&mut self, chunks: impl Iterator<Item = &'a [(Vec3, MergeRecord)]>, radius: f32) {
        self.positions.clear();
        self.unordered.clear();
        for &(position, record) in chunks.flatten() {
            self.positions.push(position);
            self.unordered.push(record);
        }
        self.grid.rebuild(&self.positions, radius);
        self.records.clear();
        let unordered = &self.unordered;
        self.records.par_extend(self.grid.order().par_iter().map(|&i| unordered[i as usize]));
    }

    fn query(&self, p: Vec3, mut visit: impl FnMut(&MergeRecord)) {
        self.grid.query(p, |slot| visit(&self.records[slot]));
    }
}

impl Pass<'_> {
    /// Whether the segment from `x` to `y` is blocked.
    fn occluded(&self, x: Vec3, dir: Vec3, distance: f32) -> bool {
        let mut ray = Ray::new(x, dir);
        ray.t_max = distance * (1.0 - 1e-4);
        self.scene.accel.occluded(&ray)
    }

    fn trace_light(&self, rng: &mut Rng, out: &mut LightChunk) {
        let Some(e) = self.emitters.emit(rng) else { return };
        let f = &self.factors;
        let mut state = SubpathMis::light_start(e.emission_pdf_w, e.direct_pdf, e.cos_light, e.delta, f);
        let sphere = matches!(self.scene.lights[e.light], Light::Sphere { .. });
        let mut throughput = e.throughput;
        let mut ray = Ray::new(e.origin, e.dir);
        let mut length = 1;
        // σ̄ at the vertex the ray left (1: a light or a surface).
        let mut departure_density = 1.0;
        loop {
            let step = flight::step(self.scene, &ray, rng);
            // Where glass is mixed in, merges stored on one material's draws
            // stand for the other's draws that store none (`store_weight`).
            let mut store_weight = 1.0;
            let (point, scatter) = match step.event {
                Event::Escaped => break,
                Event::Surface { hit, unbent } => {
                    let scatter_of =
                        |m: &Material| Scatter::in_scene(self.scene, *m, &hit, unbent, ray.dir, Transport::Importance);
                    if self.strategies.merge() && self.scene.mixes_at(&hit) {
                        let drawn = self.scene.drawn_material_at(&hit);
                        store_weight = drawn.store_weight(|m| scatter_of(m).is_some_and(|s| !s.is_delta()));
                        (hit.point, scatter_of(&drawn.material))
                    } else {
                        (hit.point, scatter_of(&self.scene.material_at(&hit)))
                    }
                }
                Event::Medium { point, mask } => (point, Scatter::medium(&self.scene.media, mask, ray.dir)),
            };
            if length == 1 && sphere {
                state.direct_pdf_known(self.emitters.sphere_direct_pdf_a(e.light, point, e.origin, e.normal));
            }
            let Some(scatter) = scatter else { break };
            throughput *= step.weight;
            let arrival = scatter.cos_in() * scatter.flight_density() * step.passes;
            let distance2 = step.distance * step.distance;
            state.arrive(distance2, arrival, departure_density * step.passes, length > 1 || e.finite);
            if !scatter.is_delta() {
                let to_eye = self.strategies.connect() || self.strategies == Strategies::LightTracing;
                if let Some(splat) = to_eye.then(|| self.connect_to_eye(point, &scatter, throughput, &state)).flatten()
                {
                    out.splats.push(splat);
                }
                if self.strategies.connect() {
                    out.vertices.push(LightVertex { position: point, throughput, length, scatter, mis: state });
                }
                if self.strategies.merge() {
                    let (kind, throughput) = match step.event {
                        Event::Medium { mask, .. } => {
                            let sigma_s = self.scene.media.sigma_s(mask);
                            (&mut out.volume, Rgb::select(sigma_s.cmpgt(Rgb::ZERO), throughput / sigma_s, Rgb::ZERO))
                        }
                        _ => (&mut out.surface, throughput * store_weight),
                    };
                    let record = MergeRecord {
                        throughput,
                        wo: scatter.wo(),
                        continuation: scatter.continuation(),
                        length,
                        mis: state,
                    };
                    kind.push((point, record));
                }
            }
            if length + 2 > self.max_length {
                break;
            }
            let Some((next, _)) = self.continue_subpath(&scatter, &mut state, &mut throughput, rng) else { break };
            departure_density = scatter.flight_density();
            ray = Ray::new(point, next);
            length += 1;
        }
    }

    /// Samples the next direction with Russian roulette and updates the
    /// subpath's sums and throughput: the direction and whether a delta
    /// lobe chose it; None where the subpath ends.
    fn continue_subpath(
        &self,
        scatter: &Scatter,
        state: &mut SubpathMis,
        throughput: &mut Rgb,
        rng: &mut Rng,
    ) -> Option<(Vec3, bool)> {
        let s = scatter.sample(rng)?;
        let continuation = scatter.continuation();
        if rng.next_f32() >= continuation {
            return None;
        }
        if s.delta {
            state.scatter_delta(s.cos);
        } else {
            let eta = self.factors.eta(scatter.in_medium());
            state.scatter(s.cos, s.pdf_dir * continuation, s.pdf_rev * continuation, eta, &self.factors);
        }
        *throughput *= s.weight / continuation;
        Some((s.wi, s.delta))
    }

    /// Light tracing: the light vertex at `x` seen by the eye, as a splat
    /// on the pixel it projects to.
    fn connect_to_eye(&self, x: Vec3, scatter: &Scatter, throughput: Rgb, state: &SubpathMis) -> Option<(u32, Rgb)> {
        let camera = &self.scene.camera;
        let raster = camera.raster(x)?;
        let to_eye = camera.position - x;
        let distance2 = to_eye.length_squared();
        let distance = distance2.sqrt();
        let dir = to_eye / distance;
        let eval = scatter.evaluate(dir)?;
        let cos_at_camera = camera.forward().dot(-dir);
        let (transmittance, passes) = flight::between(&self.scene.media, x, dir, distance);
        // The camera's importance times the geometry term (one unit of
        // image-plane area per pixel sample), and the density, per unit
        // area (volume) at x, of the camera's ray choosing x: the same
        // with the free flight's density for the cosine's transmittance.
        let to_plane = self.image_plane / cos_at_camera;
        let importance = to_plane * to_plane / cos_at_camera * eval.cos / distance2;
        let camera_pdf_a = importance * scatter.flight_density() * passes;
        let weight = if self.strategies == Strategies::LightTracing {
            1.0
        } else {
            let eta = self.factors.eta(scatter.in_medium());
            mis::light_tracing(state, camera_pdf_a, eval.pdf_rev * scatter.continuation(), eta, &self.factors)
        };
        let value = throughput * eval.f * transmittance * (weight * importance / self.factors.light_paths);
        if value.max_element() <= 0.0 || self.occluded(x, dir, distance) {
            return None;
        }
        let pixel = raster.y as u32 * camera.width + raster.x as u32;
        Some((pixel, value))
    }

    /// Radiance through pixel `pixel` (its top-left corner) from one camera subpath.
    fn trace_camera(&self, pixel: Vec2, index: usize, light: &Subpaths, rng: &mut Rng) -> Rgb {
        let camera = &self.scene.camera;
        let f = &self.factors;
        let mut ray = camera.ray(pixel + rng.next_2d());
        let cos_at_camera = ray.dir.dot(camera.forward());
        let to_plane = self.image_plane / cos_at_camera;
        let mut state = SubpathMis::camera_start(to_plane * to_plane / cos_at_camera, f);
        let mut throughput = Rgb::ONE;
        let mut color = Rgb::ZERO;
        let mut length = 1;
        let mut specular_path = true;
        let mut from = camera.position;
        let mut departure_density = 1.0;
        loop {
            let step = flight::step(self.scene, &ray, rng);
            throughput *= step.weight;
            let departure = departure_density * step.passes;
            let (x, scatter) = match step.event {
                Event::Escaped => {
                    state.arrive(1.0, step.passes, departure, false);
                    for found in self.emitters.escaped(ray.dir) {
                        let weight =
                            self.emitter_weight(&state, length, specular_path, found.direct_pdf, found.emission_pdf_w);
                        color += throughput * found.radiance * weight;
                    }
                    break;
                }
                Event::Surface { hit, unbent } => {
                    let cos = ray.dir.dot(hit.shading_normal);
                    state.arrive(step.distance * step.distance, cos * step.passes, departure, true);
                    if let Some(found) = self.emitters.at_surface(&hit, from, ray.dir) {
                        let weight =
                            self.emitter_weight(&state, length, specular_path, found.direct_pdf, found.emission_pdf_w);
                        color += throughput * found.radiance * weight;
                    }
                    let material = *self.scene.material_at(&hit);
                    (hit.point, Scatter::in_scene(self.scene, material, &hit, unbent, ray.dir, Transport::Radiance))
                }
                Event::Medium { point, mask } => {
                    let scatter = Scatter::medium(&self.scene.media, mask, ray.dir);
                    let density = scatter.as_ref().map_or(1.0, |s| s.flight_density());
                    state.arrive(step.distance * step.distance, density * step.passes, departure, true);
                    (point, scatter)
                }
            };
            if self.strategies == Strategies::LightTracing || length >= self.max_length {
                break;
            }
            let Some(scatter) = scatter else { break };
            if !scatter.is_delta() {
                if self.strategies.connect() {
                    color += throughput * self.next_event(x, &scatter, &state, rng);
                    for vertex in light.of_pixel(index) {
                        if vertex.length + 1 + length > self.max_length {
                            break;
                        }
                        color += throughput * vertex.throughput * self.connect(x, &scatter, &state, vertex);
                    }
                }
                let medium = scatter.in_medium();
                if let Some(grid) = if medium { light.volume } else { light.surface } {
                    // Merges here weigh at most `bound`; where that is
                    // small the search is made only with a probability
                    // (its results divided by it).
                    let bound = mis::merge_bound(&state, f.eta(medium), f);
                    let probability = (bound / MERGE_ROULETTE_WEIGHT).min(1.0);
                    if probability >= 1.0 || rng.next_f32() < probability {
                        let mut sum = Rgb::ZERO;
                        grid.query(x, |vertex| sum += self.merge(&scatter, &state, length, vertex));
                        color += throughput * sum * (f.normalization(medium) / probability);
                    }
                }
            }
            let Some((next, delta)) = self.continue_subpath(&scatter, &mut state, &mut throughput, rng) else { break };
            specular_path &= delta;
            departure_density = scatter.flight_density();
            from = x;
            ray = Ray::new(x, next);
            length += 1;
        }
        color
    }

    /// The weight of emitted light a camera subpath of `length` segments finds.
    fn emitter_weight(&self, state: &SubpathMis, length: u32, specular_path: bool, direct: f32, emission: f32) -> f32 {
        if length == 1 {
            1.0
        } else if !self.strategies.connect() {
            // Merging alone finds everything but purely specular paths.
            if specular_path { 1.0 } else { 0.0 }
        } else {
            mis::emitter_hit(state, direct, emission)
        }
    }

    /// Next-event estimation at camera vertex `x`.
    fn next_event(&self, x: Vec3, scatter: &Scatter, state: &SubpathMis, rng: &mut Rng) -> Rgb {
        let Some(light) = self.emitters.illuminate(x, rng) else { return Rgb::ZERO };
        let Some(eval) = scatter.evaluate(light.wi) else { return Rgb::ZERO };
        let continuation = scatter.continuation();
        let (transmittance, passes) = flight::between(&self.scene.media, x, light.wi, light.distance);
        let densities = mis::NextEvent {
            bsdf_dir_pdf_w: if light.delta { 0.0 } else { eval.pdf_dir * continuation },
            bsdf_rev_pdf_w: eval.pdf_rev * continuation,
            direct_pdf_w: light.direct_pdf_w,
            emission_pdf_w: light.emission_pdf_w,
            vertex_arrival: eval.cos * scatter.flight_density() * passes,
            passes,
            cos_at_light: light.cos_at_light,
        };
        let weight = mis::next_event(state, &densities, self.factors.eta(scatter.in_medium()));
        let value = light.radiance * eval.f * transmittance * (weight * eval.cos / light.direct_pdf_w);
        if value.max_element() <= 0.0 || self.occluded(x, light.wi, light.distance) {
            return Rgb::ZERO;
        }
        value
    }

    /// Connects camera vertex `x` to a light vertex (without the throughputs).
    fn connect(&self, x: Vec3, scatter: &Scatter, state: &SubpathMis, vertex: &LightVertex) -> Rgb {
        let to_light = vertex.position - x;
        let distance2 = to_light.length_squared();
        let distance = distance2.sqrt();
        let dir = to_light / distance;
        let Some(camera_eval) = scatter.evaluate(dir) else { return Rgb::ZERO };
        let Some(light_eval) = vertex.scatter.evaluate(-dir) else { return Rgb::ZERO };
        let (camera_continuation, light_continuation) = (scatter.continuation(), vertex.scatter.continuation());
        let (transmittance, passes) = flight::between(&self.scene.media, x, dir, distance);
        let at_light = light_eval.cos * vertex.scatter.flight_density() * passes;
        let at_camera = camera_eval.cos * scatter.flight_density() * passes;
        let densities = mis::Connection {
            camera_dir_pdf_a: camera_eval.pdf_dir * camera_continuation * at_light / distance2,
            camera_rev_pdf_w: camera_eval.pdf_rev * camera_continuation,
            light_dir_pdf_a: light_eval.pdf_dir * light_continuation * at_camera / distance2,
            light_rev_pdf_w: light_eval.pdf_rev * light_continuation,
            camera_eta: self.factors.eta(scatter.in_medium()),
            light_eta: self.factors.eta(vertex.scatter.in_medium()),
        };
        let weight = mis::connection(state, &vertex.mis, &densities);
        let value =
            camera_eval.f * light_eval.f * transmittance * (weight * camera_eval.cos * light_eval.cos / distance2);
        if value.max_element() <= 0.0 || self.occluded(x, dir, distance) {
            return Rgb::ZERO;
        }
        value
    }

    /// A light vertex merged at a camera vertex of `length` segments
    /// (without the camera throughput and the kernel's normalization).
    fn merge(&self, scatter: &Scatter, state: &SubpathMis, length: u32, vertex: &MergeRecord) -> Rgb {
        if vertex.length + length > self.max_length {
            return Rgb::ZERO;
        }
        let Some(eval) = scatter.evaluate(vertex.wo) else { return Rgb::ZERO };
        let weight = mis::merge(
            state,
            &vertex.mis,
            eval.pdf_dir * scatter.continuation(),
            eval.pdf_rev * vertex.continuation,
            self.factors.eta(scatter.in_medium()),
            &self.factors,
        );
        eval.f * vertex.throughput * (weight * scatter.merge_weight(vertex.wo))
    }
}

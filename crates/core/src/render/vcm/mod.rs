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
//! Not yet handled: participating media (the renderer refuses scenes with
//! fog, saying so) and normal textures (shading uses interpolated normals,
//! as the photon mappers do).

pub mod emitters;
mod grid;
pub mod mis;
mod scatter;

use self::emitters::Emitters;
use self::grid::HashGrid;
use self::mis::{Factors, SubpathMis};
use self::scatter::Scatter;
use super::Image;
use crate::geometry::Ray;
use crate::light::Light;
use crate::material::Rgb;
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
    /// The first pass's merging radius (default [`default_radius`]).
    pub radius: Option<f32>,
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

/// A stored light-subpath vertex.
struct LightVertex {
    position: Vec3,
    throughput: Rgb,
    /// Segments from the light.
    length: u32,
    scatter: Scatter,
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

/// What a chunk of light subpaths leaves: its vertices (subpath by
/// subpath), where each subpath's end, and its light-tracing splats.
#[derive(Default)]
struct LightChunk {
    vertices: Vec<LightVertex>,
    ends: Vec<u32>,
    splats: Vec<(u32, Rgb)>,
}

/// Why a scene cannot be rendered with VCM yet.
pub fn unsupported(scene: &Scene) -> Option<String> {
    (!scene.media.is_empty()).then(|| {
        "the vcm renderer does not handle participating media yet (use --renderer path or photon-cpu)".to_string()
    })
}

/// Pass `pass` (from 1): one light subpath and one camera subpath per
/// pixel. Returns the pass's image and the number of non-finite
/// contributions dropped.
pub fn render_pass(scene: &Scene, settings: &VcmSettings, pass: u32) -> Result<(Image, u64), String> {
    if let Some(why) = unsupported(scene) {
        return Err(why);
    }
    let camera = &scene.camera;
    let (width, height) = (camera.width, camera.height);
    let pixels = (width * height) as usize;
    let radius =
        RadiusSchedule::disc(settings.radius.unwrap_or_else(|| default_radius(scene)), settings.alpha).radius(pass);
    let strategies = settings.strategies;
    // One light subpath per pixel: more a pass (2, 4, 8 per pixel) left
    // more error after 20 s on the Cornell box (13%, 20%, 27% against 8%):
    // the passes slow as much, and the camera subpaths carry most paths.
    let light_paths = pixels;
    let p = Pass {
        scene,
        emitters: Emitters::new(scene),
        factors: Factors::new(radius, light_paths as f32, strategies.connect(), strategies.merge()),
        strategies,
        max_length: settings.max_path_length.max(1),
        image_plane: camera.image_plane_distance(),
    };
    let seed = crate::progressive::pass_seed(settings.seed, pass);

    // Light subpaths, in chunks whose results are joined in order: the
    // same image whatever the thread count.
    const CHUNK: usize = 256;
    let chunks: Vec<LightChunk> = (0..light_paths.div_ceil(CHUNK))
        .into_par_iter()
        .map(|c| {
            let mut chunk = LightChunk::default();
            for i in c * CHUNK..((c + 1) * CHUNK).min(light_paths) {
                let mut rng = Rng::for_item(seed ^ 0x11c4_7a7b_0000_0001, i as u64);
                p.trace_light(&mut rng, &mut chunk);
                chunk.ends.push(chunk.vertices.len() as u32);
            }
            chunk
        })
        .collect();
    let mut vertices = Vec::new();
    let mut ends = Vec::with_capacity(light_paths);
    let mut splats = Vec::new();
    for chunk in chunks {
        let base = vertices.len() as u32;
        ends.extend(chunk.ends.iter().map(|e| e + base));
        vertices.extend(chunk.vertices);
        splats.extend(chunk.splats);
    }
    let positions: Vec<Vec3> = vertices.iter().map(|v| v.position).collect();
    let grid = strategies.merge().then(|| HashGrid::new(&positions, radius));
    let light = Subpaths { vertices: &vertices, positions: &positions, ends: &ends, grid: grid.as_ref() };

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
    for (pixel, value) in splats {
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
    vertices: &'a [LightVertex],
    positions: &'a [Vec3],
    ends: &'a [u32],
    grid: Option<&'a HashGrid>,
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
        while let Some(hit) = self.scene.accel.intersect(&ray) {
            if length == 1 && sphere {
                state.direct_pdf_known(self.emitters.sphere_direct_pdf_a(e.light, hit.point, e.origin, e.normal));
            }
            let Some(scatter) = Scatter::at(self.scene.material_at(&hit), &hit, ray.dir) else { break };
            state.arrive(hit.t * hit.t, scatter.cos_in(), length > 1 || e.finite);
            if !scatter.is_delta() {
                let to_eye = self.strategies.connect() || self.strategies == Strategies::LightTracing;
                if let Some(splat) =
                    to_eye.then(|| self.connect_to_eye(hit.point, &scatter, throughput, &state)).flatten()
                {
                    out.splats.push(splat);
                }
                if self.strategies != Strategies::LightTracing {
                    out.vertices.push(LightVertex { position: hit.point, throughput, length, scatter, mis: state });
                }
            }
            if length + 2 > self.max_length {
                break;
            }
            let Some((next, _)) = self.continue_subpath(&scatter, &mut state, &mut throughput, rng) else { break };
            ray = Ray::new(hit.point, next);
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
            state.scatter(s.cos, s.pdf_dir * continuation, s.pdf_rev * continuation, &self.factors);
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
        // Per unit area at x, the density of the camera's ray choosing x
        // (one unit of image-plane area per pixel sample).
        let to_plane = self.image_plane / cos_at_camera;
        let camera_pdf_a = to_plane * to_plane / cos_at_camera * eval.cos / distance2;
        let weight = if self.strategies == Strategies::LightTracing {
            1.0
        } else {
            mis::light_tracing(state, camera_pdf_a, eval.pdf_rev * scatter.continuation(), &self.factors)
        };
        let value = throughput * eval.f * (weight * camera_pdf_a / self.factors.light_paths);
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
        loop {
            let Some(hit) = self.scene.accel.intersect(&ray) else {
                for found in self.emitters.escaped(ray.dir) {
                    let weight =
                        self.emitter_weight(&state, length, specular_path, found.direct_pdf, found.emission_pdf_w);
                    color += throughput * found.radiance * weight;
                }
                break;
            };
            state.arrive(hit.t * hit.t, ray.dir.dot(hit.shading_normal), true);
            if let Some(found) = self.emitters.at_surface(&hit, from, ray.dir) {
                let weight = self.emitter_weight(&state, length, specular_path, found.direct_pdf, found.emission_pdf_w);
                color += throughput * found.radiance * weight;
            }
            if self.strategies == Strategies::LightTracing || length >= self.max_length {
                break;
            }
            let Some(scatter) = Scatter::at(self.scene.material_at(&hit), &hit, ray.dir) else { break };
            let x = hit.point;
            if !scatter.is_delta() {
                if self.strategies.connect() {
                    color += throughput * self.next_event(x, &scatter, &state, rng);
                    let start = if index == 0 { 0 } else { light.ends[index - 1] as usize };
                    for vertex in &light.vertices[start..light.ends[index] as usize] {
                        if vertex.length + 1 + length > self.max_length {
                            break;
                        }
                        color += throughput * vertex.throughput * self.connect(x, &scatter, &state, vertex);
                    }
                }
                if let Some(grid) = light.grid {
                    let mut sum = Rgb::ZERO;
                    grid.query(light.positions, x, |i| {
                        sum += self.merge(&scatter, &state, length, &light.vertices[i]);
                    });
                    color += throughput * sum * f.vm_normalization;
                }
            }
            let Some((next, delta)) = self.continue_subpath(&scatter, &mut state, &mut throughput, rng) else { break };
            specular_path &= delta;
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
        let densities = mis::NextEvent {
            bsdf_dir_pdf_w: if light.delta { 0.0 } else { eval.pdf_dir * continuation },
            bsdf_rev_pdf_w: eval.pdf_rev * continuation,
            direct_pdf_w: light.direct_pdf_w,
            emission_pdf_w: light.emission_pdf_w,
            cos_at_vertex: eval.cos,
            cos_at_light: light.cos_at_light,
        };
        let weight = mis::next_event(state, &densities, &self.factors);
        let value = light.radiance * eval.f * (weight * eval.cos / light.direct_pdf_w);
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
        let densities = mis::Connection {
            camera_dir_pdf_a: camera_eval.pdf_dir * camera_continuation * light_eval.cos / distance2,
            camera_rev_pdf_w: camera_eval.pdf_rev * camera_continuation,
            light_dir_pdf_a: light_eval.pdf_dir * light_continuation * camera_eval.cos / distance2,
            light_rev_pdf_w: light_eval.pdf_rev * light_continuation,
        };
        let weight = mis::connection(state, &vertex.mis, &densities, &self.factors);
        let value = camera_eval.f * light_eval.f * (weight * camera_eval.cos * light_eval.cos / distance2);
        if value.max_element() <= 0.0 || self.occluded(x, dir, distance) {
            return Rgb::ZERO;
        }
        value
    }

    /// A light vertex merged at a camera vertex of `length` segments
    /// (without the camera throughput and the kernel's normalization).
    fn merge(&self, scatter: &Scatter, state: &SubpathMis, length: u32, vertex: &LightVertex) -> Rgb {
        if vertex.length + length > self.max_length {
            return Rgb::ZERO;
        }
        let Some(eval) = scatter.evaluate(vertex.scatter.wo()) else { return Rgb::ZERO };
        let weight = mis::merge(
            state,
            &vertex.mis,
            eval.pdf_dir * scatter.continuation(),
            eval.pdf_rev * vertex.scatter.continuation(),
            &self.factors,
        );
        eval.f * vertex.throughput * weight
    }
}

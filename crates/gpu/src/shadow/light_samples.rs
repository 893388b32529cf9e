//! Lights as the GPU shades them. Point, spot, sphere, quad and sun keep
//! their exact unshadowed irradiance formula and get one or more
//! shadow-mapped samples whose visible fraction scales it: one for point
//! and spot lights (a perspective view) and the sun (an orthographic view
//! along its direction), `area_samples` fixed points on a sphere or quad (a
//! soft shadow as an average of hard ones). Where no such formula fits, each
//! sample is evaluated on its own: the sky's directions
//! ([`sky_directions`] of them, each an orthographic view) and points on an
//! emissive mesh (each a cube of views), see light_eval.wgsl.

use crate::scene_upload::GpuVertex;
use bytemuck::{Pod, Zeroable};
use glam::{Mat4, Vec2, Vec3, Vec4};
use hikari_core::camera::{clip_from_view, view_from_world};
use hikari_core::light::{Disc, EmissiveMesh, Light};
use hikari_core::sampling::{orthonormal_basis, uniform_sphere};
use hikari_core::scene::Scene;
use std::ops::Range;

/// One light. Mirrors `Light` in light_eval.wgsl.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct GpuLight {
    /// Point/spot position, sphere centre, quad corner, or the centre of a
    /// distant light's disc.
    pub position: [f32; 3],
    pub kind: u32,
    /// Intensity (W/sr) for point and spot lights, irradiance (W/m²) for
    /// the sun, radiance for the others.
    pub emission: [f32; 3],
    /// Index of its first sample point in the samples array.
    pub first_sample: u32,
    /// Spot axis, quad edge_u, or the unit direction toward the sun.
    pub axis: [f32; 3],
    pub sample_count: u32,
    /// Quad edge_v.
    pub edge_v: [f32; 3],
    /// Spot cutoff (radians), sphere radius, or a distant light's disc radius.
    pub cutoff: f32,
    pub falloff_start: f32,
    /// Emissive mesh: each sample's share of its area, A / N.
    pub sample_area: f32,
    /// Emissive mesh: 1 if it emits from both faces.
    pub two_sided: u32,
    /// Sky: 1 when it is an image, its directions drawn from it, each with
    /// its `GpuLightSample::weight`.
    pub mapped: u32,
    /// Emissive mesh: where its triangles start in the samples array (after
    /// its shadow-mapped points, [`GpuLights::add_triangles`]) and how many.
    pub first_triangle: u32,
    pub triangle_count: u32,
    pub _pad: [u32; 2],
}

/// One shadow-mapped sample. Mirrors `LightSample` in light_eval.wgsl.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct GpuLightSample {
    /// The sample point (point, spot, sphere, quad, mesh; offset off a
    /// quad's or mesh's surface); for distant lights the point the
    /// orthographic view starts from.
    pub position: [f32; 3],
    pub first_view: u32,
    /// The unit direction toward the light of a distant sample (sun, sky);
    /// the unit front normal at a mesh sample; zero otherwise.
    pub direction: [f32; 3],
    /// 6 for a cube of views, 1 for a single (spot or orthographic) view.
    pub view_count: u32,
    /// A sky image's direction: L(ω)/(K·p(ω)), its share of the
    /// irradiance integral (the light's radiance factor aside); zero
    /// otherwise.
    pub weight: [f32; 3],
    pub _pad: u32,
}

pub mod kind {
    pub const POINT: u32 = 0;
    pub const SPOT: u32 = 1;
    pub const SPHERE: u32 = 2;
    pub const QUAD: u32 = 3;
    pub const DIRECTIONAL: u32 = 4;
    pub const ENVIRONMENT: u32 = 5;
    pub const MESH: u32 = 6;
}

/// A spot light narrower than this gets one 2D shadow view; wider, a cube.
const MAX_SINGLE_VIEW_CUTOFF_DEGREES: f32 = 60.0;

/// Directions a sky is shadow-mapped from: four times an area light's
/// samples (16 at the default 4), as the sky spans the whole sphere where
/// an area light spans a small solid angle. Half of them lie above any
/// surface's horizon.
pub fn sky_directions(area_samples: u32) -> u32 {
    4 * area_samples.max(1)
}

/// One rendered shadow view: a layer of the shadow-map array.
#[derive(Clone, Copy, Debug)]
pub struct ShadowView {
    pub clip_from_world: Mat4,
    /// The light sample of a perspective view; a point of the plane an
    /// orthographic view starts from.
    pub light_position: Vec3,
    /// Orthographic views (distant lights): the unit direction light
    /// travels and the view's width.
    pub orthographic: Option<(Vec3, f32)>,
    /// The scene light the view belongs to: an emissive mesh does not
    /// shadow its own views.
    pub light: u32,
}

/// Cube faces in the order the shader selects them: +X, −X, +Y, −Y, +Z, −Z.
const CUBE_FACES: [(Vec3, Vec3); 6] = [
    (Vec3::X, Vec3::NEG_Y),
    (Vec3::NEG_X, Vec3::NEG_Y),
    (Vec3::Y, Vec3::Z),
    (Vec3::NEG_Y, Vec3::NEG_Z),
    (Vec3::Z, Vec3::NEG_Y),
    (Vec3::NEG_Z, Vec3::NEG_Y),
];

/// Stratified points in [0,1)² for a given count (golden-ratio lattice).
fn lattice(i: u32, n: u32) -> Vec2 {
    Vec2::new((i as f32 + 0.5) / n as f32, (i as f32 * 0.618_034 + 0.5).fract())
}

/// The toroidal shift (Cranley–Patterson rotation) of the lattice in
/// progressive pass `pass`: none in pass 1 (and 0), then the R2 sequence's
/// points, which fill [0,1)² evenly pass after pass. A uniformly shifted
/// lattice is still stratified, and each of its points is uniform over
/// the square, so the mean over passes of the shadow-mapped samples
/// converges to the light's integral instead of a fixed set of hard
/// shadows.
pub fn pass_shift(pass: u32) -> Vec2 {
    // R2: the plastic number's powers (Roberts 2018).
    const R2: Vec2 = Vec2::new(0.754_877_7, 0.569_840_3);
    let k = pass.saturating_sub(1) as f64;
    Vec2::new((k * R2.x as f64).fract() as f32, (k * R2.y as f64).fract() as f32)
}

/// Point `i` of `n` of the lattice shifted by `shift`.
fn shifted(i: u32, n: u32, shift: Vec2) -> Vec2 {
    let p = lattice(i, n) + shift;
    // fract, kept below 1 in f32 (1 − ε + a shift can round up to 1).
    Vec2::new(p.x.fract().min(0.999_999_94), p.y.fract().min(0.999_999_94))
}

/// What the lights' samples are drawn from: the scene's lights and the
/// distances that size their views, kept by the renderer so that each
/// progressive pass can draw its own samples (`GpuLights::sampled`).
#[derive(Clone)]
pub struct LightSource {
    lights: Vec<Light>,
    diagonal: f32,
    far: f32,
}

impl LightSource {
    pub fn of(scene: &Scene) -> Self {
        let far = 4.0 * scene.diagonal() + (scene.camera.position - scene.accel.bounds().0).length();
        LightSource { lights: scene.lights.clone(), diagonal: scene.diagonal(), far }
    }

    /// Do the samples change from pass to pass (a light of several shadow-
    /// mapped samples: an area light with `area_samples` > 1, a sky, an
    /// emissive mesh)? Points, spots and suns keep their one sample.
    pub fn varies_per_pass(&self, area_samples: u32) -> bool {
        self.lights.iter().any(|l| match l {
            Light::Sphere { .. } | Light::Quad { .. } => area_samples > 1,
            Light::Environment { .. } | Light::Mesh(_) => true,
            Light::Point { .. } | Light::Spot { .. } | Light::Directional { .. } => false,
        })
    }
}

/// The emissive meshes' triangles as shadow-map occluders (positions only),
/// each mesh a contiguous range: every shadow view draws them but the
/// ranges of its own light (the scene's vertex buffer leaves all light
/// bodies out of the shadow maps, `SceneBuffers::occluder_count`).
#[derive(Clone, Debug, Default)]
pub struct MeshOccluders {
    pub vertices: Vec<GpuVertex>,
    /// (light index, its vertex range), in light order.
    pub ranges: Vec<(u32, Range<u32>)>,
}

/// The surface id of an emissive mesh's own triangles drawn as occluders
/// (opaque: no cut-out test).
pub const NO_SURFACE: u32 = 0x7fff_ffff;

impl MeshOccluders {
    /// The vertex ranges a view of light `light` draws: all but its own.
    pub fn drawn_by(&self, light: u32) -> impl Iterator<Item = Range<u32>> + '_ {
        let total = self.vertices.len() as u32;
        let own = self.ranges.iter().find(|(l, _)| *l == light).map_or(total..total, |(_, r)| r.clone());
        [0..own.start, own.end..total].into_iter().filter(|r| !r.is_empty())
    }
}

pub struct GpuLights {
    pub lights: Vec<GpuLight>,
    pub samples: Vec<GpuLightSample>,
    pub views: Vec<ShadowView>,
    pub occluders: MeshOccluders,
    /// Radiance of rays that leave the scene: the sky's (zero without one).
    pub sky_radiance: Vec3,
}

impl GpuLights {
    /// The samples of the first progressive pass.
    pub fn new(scene: &Scene, area_samples: u32) -> Self {
        Self::sampled(&LightSource::of(scene), area_samples, 1)
    }

    /// The samples of progressive pass `pass`: the same count and views
    /// as every other pass's, at points shifted by `pass_shift(pass)`.
    pub fn sampled(source: &LightSource, area_samples: u32, pass: u32) -> Self {
        let (far, diagonal, shift) = (source.far, source.diagonal, pass_shift(pass));
        let mut out = GpuLights {
            lights: Vec::new(),
            samples: Vec::new(),
            views: Vec::new(),
            occluders: MeshOccluders::default(),
            sky_radiance: Vec3::ZERO,
        };
        let n = area_samples.max(1);
        for (index, light) in source.lights.iter().enumerate() {
            let index = index as u32;
            let first_sample = out.samples.len() as u32;
            let mut record = GpuLight { first_sample, ..GpuLight::zeroed() };
            match *light {
                Light::Point { position, intensity } => {
                    record = GpuLight {
                        position: position.to_array(),
                        kind: kind::POINT,
                        emission: intensity.to_array(),
                        ..record
                    };
                    out.add_sample(index, position, None, far);
                }
                Light::Spot { position, axis, intensity, cutoff, falloff_start } => {
                    record = GpuLight {
                        position: position.to_array(),
                        kind: kind::SPOT,
                        emission: intensity.to_array(),
                        axis: axis.to_array(),
                        cutoff,
                        falloff_start,
                        ..record
                    };
                    out.add_sample(index, position, Some((axis, cutoff)), far);
                }
                Light::Sphere { center, radius, radiance } => {
                    record = GpuLight {
                        position: center.to_array(),
                        kind: kind::SPHERE,
                        emission: radiance.to_array(),
                        cutoff: radius,
                        ..record
                    };
                    for i in 0..n {
                        // Spread over the ball (area-light bodies cast no shadow maps).
                        let p = center + uniform_sphere(shifted(i, n, shift)) * radius * if n == 1 { 0.0 } else { 0.9 };
                        out.add_sample(index, p, None, far);
                    }
                }
                Light::Quad { corner, edge_u, edge_v, radiance } => {
                    record = GpuLight {
                        position: corner.to_array(),
                        kind: kind::QUAD,
                        emission: radiance.to_array(),
                        axis: edge_u.to_array(),
                        edge_v: edge_v.to_array(),
                        ..record
                    };
                    let offset = edge_u.cross(edge_v).normalize() * diagonal * 1e-4;
                    for i in 0..n {
                        let u = shifted(i, n, shift);
                        out.add_sample(index, corner + edge_u * u.x + edge_v * u.y + offset, None, far);
                    }
                }
                Light::Directional { direction, irradiance, disc } => {
                    record = GpuLight {
                        position: disc.center.to_array(),
                        kind: kind::DIRECTIONAL,
                        emission: irradiance.to_array(),
                        axis: (-direction).to_array(),
                        cutoff: disc.radius,
                        ..record
                    };
                    out.add_distant_sample(index, direction, disc);
                }
                Light::Environment { radiance, disc, ref map } => {
                    record = GpuLight {
                        position: disc.center.to_array(),
                        kind: kind::ENVIRONMENT,
                        emission: radiance.to_array(),
                        cutoff: disc.radius,
                        mapped: map.is_some() as u32,
                        ..record
                    };
                    out.sky_radiance += radiance;
                    let k = sky_directions(n);
                    for i in 0..k {
                        // Light arriving from ω travels along −ω. An image's
                        // directions are drawn from it (a sun in the map
                        // gets its share of them), each weighted L/(K·p).
                        match map.as_ref().and_then(|m| m.sample(shifted(i, k, shift))) {
                            Some(s) => {
                                out.add_distant_sample(index, -s.dir, disc);
                                let weight = s.radiance / (k as f32 * s.pdf);
                                out.samples.last_mut().expect("just added").weight = weight.to_array();
                            }
                            None => out.add_distant_sample(index, -uniform_sphere(shifted(i, k, shift)), disc),
                        }
                    }
                }
                Light::Mesh(ref mesh) => {
                    record = GpuLight {
                        kind: kind::MESH,
                        emission: mesh.radiance.to_array(),
                        sample_area: mesh.area() / n as f32,
                        two_sided: mesh.two_sided as u32,
                        ..record
                    };
                    let offset = diagonal * 1e-4;
                    for i in 0..n {
                        let (p, normal) = mesh_point(mesh, shifted(i, n, shift));
                        out.add_sample(index, p + normal * offset, None, far);
                        out.samples.last_mut().expect("just added").direction = normal.to_array();
                    }
                    out.occluders.add(index, mesh);
                    record.sample_count = out.samples.len() as u32 - first_sample;
                    record.first_triangle = out.samples.len() as u32;
                    record.triangle_count = mesh.triangles().len() as u32;
                    out.add_triangles(mesh);
                    out.lights.push(record);
                    continue;
                }
            }
            record.sample_count = out.samples.len() as u32 - first_sample;
            out.lights.push(record);
        }
        out
    }

    /// A point sample at `position`: a perspective view for a narrow spot
    /// (`spot`: axis and cutoff), else a cube of six.
    fn add_sample(&mut self, light: u32, position: Vec3, spot: Option<(Vec3, f32)>, far: f32) {
        let first_view = self.views.len() as u32;
        let near = far * 1e-4;
        let mut view = |forward: Vec3, up: Vec3, fov: f32| {
            let clip_from_world = clip_from_view(fov, 1.0, near, far) * view_from_world(position, forward, up);
            self.views.push(ShadowView { clip_from_world, light_position: position, orthographic: None, light });
        };
        let view_count = match spot {
            Some((axis, cutoff)) if cutoff.to_degrees() <= MAX_SINGLE_VIEW_CUTOFF_DEGREES => {
                view(axis, orthonormal_basis(axis).0, 2.0 * cutoff * 1.02);
                1
            }
            _ => {
                for (forward, up) in CUBE_FACES {
                    view(forward, up, std::f32::consts::FRAC_PI_2);
                }
                6
            }
        };
        self.samples.push(GpuLightSample {
            position: position.to_array(),
            first_view,
            direction: [0.0; 3],
            view_count,
            weight: [0.0; 3],
            _pad: 0,
        });
    }

    /// The triangles of an emissive mesh, for the glossy points' light
    /// samples (`mesh_glossy` in light_eval.wgsl), appended to the samples
    /// array: the passes that shade have no storage binding to spare on
    /// every adapter (12 per stage, the specular pass's all taken). Each is
    /// one record: `position` its first vertex, `direction` and `weight`
    /// its two edges from it (front normal e1 × e2), `first_view` the bits
    /// of the area up to and including it (f32), `view_count` 0.
    fn add_triangles(&mut self, mesh: &EmissiveMesh) {
        for ([v0, v1, v2], cumulative) in mesh.triangles().iter().zip(mesh.cumulative_areas()) {
            self.samples.push(GpuLightSample {
                position: v0.to_array(),
                first_view: cumulative.to_bits(),
                direction: (*v1 - *v0).to_array(),
                view_count: 0,
                weight: (*v2 - *v0).to_array(),
                _pad: 0,
            });
        }
    }

    /// A sample of light travelling along unit `direction` from the plane
    /// of `disc` (where its photons start): one orthographic view of the
    /// disc, which covers the scene's bounding sphere, looking along it.
    fn add_distant_sample(&mut self, light: u32, direction: Vec3, disc: Disc) {
        let start = disc.center - direction * disc.radius;
        let width = 2.0 * disc.radius;
        // The disc fills the view; depth 0 at the disc, 1 past the far side of the sphere.
        let projection = Mat4::from_cols(
            Vec4::new(1.0 / disc.radius, 0.0, 0.0, 0.0),
            Vec4::new(0.0, 1.0 / disc.radius, 0.0, 0.0),
            Vec4::new(0.0, 0.0, -1.0 / (width * 1.01), 0.0),
            Vec4::W,
        );
        let clip_from_world = projection * view_from_world(start, direction, orthonormal_basis(direction).0);
        let first_view = self.views.len() as u32;
        self.views.push(ShadowView {
            clip_from_world,
            light_position: start,
            orthographic: Some((direction, width)),
            light,
        });
        self.samples.push(GpuLightSample {
            position: start.to_array(),
            first_view,
            direction: (-direction).to_array(),
            view_count: 1,
            weight: [0.0; 3],
            _pad: 0,
        });
    }
}

impl MeshOccluders {
    fn add(&mut self, light: u32, mesh: &EmissiveMesh) {
        let start = self.vertices.len() as u32;
        for triangle in mesh.triangles() {
            for v in triangle {
                self.vertices.push(GpuVertex { position: v.to_array(), surface: NO_SURFACE, ..GpuVertex::zeroed() });
            }
        }
        self.ranges.push((light, start..self.vertices.len() as u32));
    }
}

/// The point of `mesh` that `u` maps to, area-uniformly, and its unit
/// front normal: a triangle by its cumulative area, `u.x` reused inside it,
/// then Heitz's low-distortion square-to-triangle map (2019), which keeps a
/// stratified set stratified inside the triangle (the square-root map that
/// photon emission uses bunches it: a 16-point lattice on the Cornell box's
/// light, as two triangles, lit the back wall 3.5% dark, against 0.6% here).
pub fn mesh_point(mesh: &EmissiveMesh, u: Vec2) -> (Vec3, Vec3) {
    let cumulative = mesh.cumulative_areas();
    let target = u.x * mesh.area();
    let i = cumulative.partition_point(|&c| c <= target).min(cumulative.len() - 1);
    let start = if i == 0 { 0.0 } else { cumulative[i - 1] };
    let width = cumulative[i] - start;
    let ux = if width > 0.0 { ((target - start) / width).clamp(0.0, 1.0) } else { 0.5 };
    let [v0, v1, v2] = mesh.triangles()[i];
    let (b0, b1) = if u.y > ux { (ux / 2.0, u.y - ux / 2.0) } else { (ux - u.y / 2.0, u.y / 2.0) };
    (v0 * b0 + v1 * b1 + v2 * (1.0 - b0 - b1), (v1 - v0).cross(v2 - v0).normalize_or_zero())
}

#[cfg(test)]
mod tests {
    use super::*;
    use hikari_core::test_scenes::{cornell_quad_light, quad_lights_as_meshes, sky_floor, sunlit_floor};

    /// A sun is one orthographic view along its direction; a sky
    /// `sky_directions` of them, stratified over the sphere (their mean
    /// direction near zero); each mesh sample a cube, on the mesh, facing
    /// its front.
    #[test]
    fn suns_skies_and_meshes_get_their_views() {
        let sun = GpuLights::new(&sunlit_floor(30.0, 1.0, 0.5, false), 4);
        assert_eq!((sun.lights.len(), sun.samples.len(), sun.views.len()), (1, 1, 1));
        let (direction, width) = sun.views[0].orthographic.expect("orthographic");
        let Light::Directional { direction: d, disc, .. } = sunlit_floor(30.0, 1.0, 0.5, false).lights[0] else {
            unreachable!()
        };
        assert_eq!(direction, d);
        assert_eq!(width, 2.0 * disc.radius);
        assert_eq!(sun.lights[0].axis, (-d).to_array());
        // The disc's centre projects to the middle of the view, at half depth.
        let clip = sun.views[0].clip_from_world * disc.center.extend(1.0);
        assert!(clip.x.abs() < 1e-5 && clip.y.abs() < 1e-5 && (clip.z - 0.5 / 1.01).abs() < 1e-5, "{clip}");

        let scene = sky_floor(1.0, "name = \"floor\"\ntype = \"diffuse\"\nalbedo = [0.5, 0.5, 0.5]");
        let sky = GpuLights::new(&scene, 4);
        assert_eq!(sky.samples.len() as u32, sky_directions(4));
        assert_eq!(sky.sky_radiance, Vec3::ONE);
        let mean = sky.samples.iter().map(|s| Vec3::from(s.direction)).sum::<Vec3>() / sky.samples.len() as f32;
        assert!(mean.length() < 0.05, "mean direction {mean}");
        // The direct pass's loop bound counts every direction (and its region crossings).
        // Per light 1 + 4, per direction 1 + 3, and per BRDF sample of a
        // glossy point a search of the directions and the regions.
        let area = crate::direct::AREA_SAMPLES as u64;
        assert_eq!(crate::direct::loop_iterations(&sky, 3), 1 + 4 + 16 * (1 + 3) + area * (1 + 16 + 3));
        // Stratified in z: exactly half above the z = 0 plane, and about half above the floor.
        let above = |axis: usize| sky.samples.iter().filter(|s| s.direction[axis] > 0.0).count();
        assert_eq!(above(2), sky.samples.len() / 2);
        assert!(above(1).abs_diff(sky.samples.len() / 2) <= 2, "{} of {} above the floor", above(1), sky.samples.len());

        let scene = quad_lights_as_meshes(&cornell_quad_light(8));
        let mesh = GpuLights::new(&scene, 16);
        // 16 shadow-mapped points, then the two triangles.
        assert_eq!(mesh.samples.len(), 16 + 2);
        assert_eq!(mesh.views.len(), 16 * 6);
        let light = mesh.lights[0];
        assert!((light.sample_area - 0.25 / 16.0).abs() < 1e-7);
        assert_eq!((light.sample_count, light.first_triangle, light.triangle_count), (16, 16, 2));
        let Light::Mesh(ref emissive) = scene.lights[0] else { unreachable!() };
        for (record, (&[v0, v1, v2], &cumulative)) in
            mesh.samples[16..].iter().zip(emissive.triangles().iter().zip(emissive.cumulative_areas()))
        {
            assert_eq!(record.position, v0.to_array());
            assert_eq!(record.direction, (v1 - v0).to_array());
            assert_eq!(record.weight, (v2 - v0).to_array());
            assert_eq!(f32::from_bits(record.first_view), cumulative);
        }
        assert!((f32::from_bits(mesh.samples[17].first_view) - 0.25).abs() < 1e-6);
        // Per light 1 + 4, per point 1; a glossy point adds per sample a
        // search (2 steps) and a test of both triangles, and its points again.
        let area = crate::direct::AREA_SAMPLES as u64;
        assert_eq!(crate::direct::loop_iterations(&mesh, 0), 1 + 4 + 16 + area * (1 + 2 + 2) + 16);
        for s in &mesh.samples[..16] {
            let p = Vec3::from(s.position);
            assert!((p.y - 0.999).abs() < 1e-3 && p.x.abs() <= 0.25 && p.z.abs() <= 0.25, "{p}");
            // The quad faces down (edge_u × edge_v = x × z = −y).
            assert_eq!(s.direction, [0.0, -1.0, 0.0]);
        }
        // Stratified: every quarter of the light holds a quarter of the samples.
        let quarter = mesh.samples[..16].iter().filter(|s| s.position[0] < 0.0 && s.position[2] < 0.0).count();
        assert!((3..=5).contains(&quarter), "{quarter} of 16 in one quarter");
        // The mesh shadows other lights' views, not its own.
        assert_eq!(mesh.occluders.vertices.len(), 6);
        assert_eq!(mesh.occluders.drawn_by(0).count(), 0);
        assert_eq!(mesh.occluders.drawn_by(1).collect::<Vec<_>>(), [0..6]);
    }

    /// Each progressive pass draws the sky's and an area light's samples
    /// anew: as many as pass 1's (the same views, rewritten in place), pass
    /// 1 the unshifted lattice, and over many passes the directions cover
    /// the sphere evenly (a fixed set would not move at all).
    #[test]
    fn each_pass_draws_its_own_samples() {
        let sky = sky_floor(1.0, "name = \"floor\"\ntype = \"diffuse\"\nalbedo = [0.5, 0.5, 0.5]");
        let source = LightSource::of(&sky);
        assert!(source.varies_per_pass(4));
        let first = GpuLights::sampled(&source, 4, 1);
        assert_eq!(first.samples.len(), GpuLights::new(&sky, 4).samples.len());
        assert!(first.samples.iter().zip(&GpuLights::new(&sky, 4).samples).all(|(a, b)| a.direction == b.direction));
        let passes = 256;
        let mut directions = Vec::new();
        for pass in 1..=passes {
            let lights = GpuLights::sampled(&source, 4, pass);
            assert_eq!((lights.samples.len(), lights.views.len()), (first.samples.len(), first.views.len()));
            if pass > 1 {
                assert!(lights.samples[0].direction != first.samples[0].direction, "pass {pass}");
            }
            directions.extend(lights.samples.iter().map(|s| Vec3::from(s.direction)));
        }
        let mean = directions.iter().sum::<Vec3>() / directions.len() as f32;
        assert!(mean.length() < 0.01, "mean direction {mean}");
        // Every octant of the sphere gets its eighth of the directions.
        for octant in 0..8 {
            let sign = |bit: u32| if octant & bit == 0 { 1.0 } else { -1.0 };
            let inside =
                directions.iter().filter(|d| d.x * sign(1) > 0.0 && d.y * sign(2) > 0.0 && d.z * sign(4) > 0.0).count();
            let share = inside as f32 / directions.len() as f32;
            assert!((share - 0.125).abs() < 0.01, "octant {octant}: {share}");
        }
        // Point, spot and sun lights keep their one sample.
        assert!(!LightSource::of(&sunlit_floor(30.0, 1.0, 0.5, false)).varies_per_pass(4));
        // An area light's points move over the light, staying on it.
        let quad = cornell_quad_light(8);
        let source = LightSource::of(&quad);
        assert!(source.varies_per_pass(4) && !source.varies_per_pass(1));
        let (a, b) = (GpuLights::sampled(&source, 4, 1), GpuLights::sampled(&source, 4, 7));
        for (a, b) in a.samples.iter().zip(&b.samples) {
            assert!(a.position != b.position);
            assert!((b.position[1] - a.position[1]).abs() < 1e-6 && b.position[0].abs() <= 0.25, "{:?}", b.position);
        }
    }

    #[test]
    fn mesh_points_follow_the_area() {
        let triangles = vec![
            [Vec3::ZERO, Vec3::X, Vec3::Y],
            [Vec3::new(2.0, 0.0, 0.0), Vec3::new(2.2, 0.0, 0.0), Vec3::new(2.0, 0.2, 0.0)],
        ];
        let mesh = EmissiveMesh::new(triangles, Vec3::ONE, false).unwrap();
        let n = 520;
        let small = (0..n).filter(|&i| mesh_point(&mesh, lattice(i, n)).0.x >= 2.0).count();
        // Areas 0.5 and 0.02: 20 of 520.
        assert!((19..=21).contains(&small), "{small}");
        assert_eq!(mesh_point(&mesh, Vec2::new(0.3, 0.3)).1, Vec3::Z);
    }
}

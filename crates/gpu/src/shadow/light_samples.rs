//! Lights as the GPU shades them. Each light keeps its exact unshadowed
//! irradiance formula (point, spot, sphere, quad) and gets one or more
//! shadow-mapped sample points: one for point and spot lights, `area_samples`
//! fixed points on an area light, whose visible fraction scales the light's
//! irradiance (a soft shadow as an average of hard ones).

use bytemuck::{Pod, Zeroable};
use glam::{Mat4, Vec2, Vec3};
use hikari_core::camera::{clip_from_view, view_from_world};
use hikari_core::light::Light;
use hikari_core::sampling::{orthonormal_basis, uniform_sphere};
use hikari_core::scene::Scene;

/// One light. Mirrors `Light` in direct.wgsl.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct GpuLight {
    /// Point/spot position, sphere centre or quad corner.
    pub position: [f32; 3],
    pub kind: u32,
    /// Intensity (W/sr) for point and spot lights, radiance for area lights.
    pub emission: [f32; 3],
    /// Index of its first sample point in the samples array.
    pub first_sample: u32,
    /// Spot axis, or quad edge_u.
    pub axis: [f32; 3],
    pub sample_count: u32,
    /// Quad edge_v.
    pub edge_v: [f32; 3],
    /// Spot cutoff (radians) or sphere radius.
    pub cutoff: f32,
    pub falloff_start: f32,
    pub _pad0: u32,
    pub _pad1: u32,
    pub _pad2: u32,
}

/// One shadow-mapped point. Mirrors `LightSample` in direct.wgsl.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct GpuLightSample {
    pub position: [f32; 3],
    pub first_view: u32,
    /// 6 for a cube of views, 1 for a single (spot) view.
    pub view_count: u32,
    pub _pad0: u32,
    pub _pad1: u32,
    pub _pad2: u32,
}

pub mod kind {
    pub const POINT: u32 = 0;
    pub const SPOT: u32 = 1;
    pub const SPHERE: u32 = 2;
    pub const QUAD: u32 = 3;
}

/// A spot light narrower than this gets one 2D shadow view; wider, a cube.
const MAX_SINGLE_VIEW_CUTOFF_DEGREES: f32 = 60.0;

/// One rendered shadow view: a layer of the shadow-map array.
#[derive(Clone, Copy, Debug)]
pub struct ShadowView {
    pub clip_from_world: Mat4,
    pub light_position: Vec3,
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

/// Stratified points in [0,1)², fixed for a given count (golden-ratio lattice).
fn lattice(i: u32, n: u32) -> Vec2 {
    Vec2::new((i as f32 + 0.5) / n as f32, (i as f32 * 0.618_034 + 0.5).fract())
}

pub struct GpuLights {
    pub lights: Vec<GpuLight>,
    pub samples: Vec<GpuLightSample>,
    pub views: Vec<ShadowView>,
}

impl GpuLights {
    pub fn new(scene: &Scene, area_samples: u32) -> Self {
        let far = 4.0 * scene.diagonal() + (scene.camera.position - scene.accel.bounds().0).length();
        let mut out = GpuLights { lights: Vec::new(), samples: Vec::new(), views: Vec::new() };
        let n = area_samples.max(1);
        for light in &scene.lights {
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
                    out.add_sample(position, None, far);
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
                    out.add_sample(position, Some((axis, cutoff)), far);
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
                        let p = center + uniform_sphere(lattice(i, n)) * radius * if n == 1 { 0.0 } else { 0.9 };
                        out.add_sample(p, None, far);
                    }
                }
                // Refused before any pass is built (`renderer::unsupported_lights`);
                // skipped here so that sizing a frame never panics.
                Light::Directional { .. } | Light::Environment { .. } | Light::Mesh(_) => continue,
                Light::Quad { corner, edge_u, edge_v, radiance } => {
                    record = GpuLight {
                        position: corner.to_array(),
                        kind: kind::QUAD,
                        emission: radiance.to_array(),
                        axis: edge_u.to_array(),
                        edge_v: edge_v.to_array(),
                        ..record
                    };
                    let offset = edge_u.cross(edge_v).normalize() * scene.diagonal() * 1e-4;
                    for i in 0..n {
                        let u = lattice(i, n);
                        out.add_sample(corner + edge_u * u.x + edge_v * u.y + offset, None, far);
                    }
                }
            }
            record.sample_count = out.samples.len() as u32 - first_sample;
            out.lights.push(record);
        }
        out
    }

    fn add_sample(&mut self, position: Vec3, spot: Option<(Vec3, f32)>, far: f32) {
        let first_view = self.views.len() as u32;
        let near = far * 1e-4;
        let mut view = |forward: Vec3, up: Vec3, fov: f32| {
            let clip_from_world = clip_from_view(fov, 1.0, near, far) * view_from_world(position, forward, up);
            self.views.push(ShadowView { clip_from_world, light_position: position });
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
            view_count,
            ..Zeroable::zeroed()
        });
    }
}

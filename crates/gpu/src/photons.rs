//! The photon streams the passes share: stored photons uploaded once per
//! map (`PhotonBuffer`, read by the LOD pass), and the LOD pass's output,
//! one `LodPhoton` per surviving photon, which the splats, the volume splat
//! and the points view draw as per-instance vertex attributes. Kept apart
//! from both so that neither the LOD pass nor the splat imports the other.

use bytemuck::{Pod, Zeroable};
use hikari_core::photon::Photon;
use wgpu::util::DeviceExt;

/// A splat instance: the stored photon and its power scale. Mirrors
/// `LodPhoton` in lod.wgsl.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct LodPhoton {
    pub position_x: f32,
    pub position_y: f32,
    pub position_z: f32,
    pub power_rgb9e5: u32,
    pub direction_and_class: u32,
    pub scale: f32,
}

/// `LodPhoton` (the stored photon and its LOD scale) as per-instance
/// attributes, offsets written by hand (a test checks them against the struct).
pub const PHOTON_ATTRIBUTES: [wgpu::VertexAttribute; 4] = [
    wgpu::VertexAttribute { format: wgpu::VertexFormat::Float32x3, offset: 0, shader_location: 0 },
    wgpu::VertexAttribute { format: wgpu::VertexFormat::Uint32, offset: 12, shader_location: 1 },
    wgpu::VertexAttribute { format: wgpu::VertexFormat::Uint32, offset: 16, shader_location: 2 },
    wgpu::VertexAttribute { format: wgpu::VertexFormat::Float32, offset: 20, shader_location: 3 },
];

/// The per-instance photon stream of the splats.
pub fn photon_instances() -> wgpu::VertexBufferLayout<'static> {
    wgpu::VertexBufferLayout {
        array_stride: std::mem::size_of::<LodPhoton>() as u64,
        step_mode: wgpu::VertexStepMode::Instance,
        attributes: &PHOTON_ATTRIBUTES,
    }
}

/// A photon set's stored photons, uploaded once: the LOD pass's input.
pub struct PhotonBuffer {
    pub buffer: wgpu::Buffer,
    pub count: u32,
}

impl PhotonBuffer {
    pub fn upload(device: &wgpu::Device, photons: &[Photon], label: &str) -> Self {
        // wgpu refuses empty buffers: keep one zeroed photon, draw none.
        let zero =
            [Photon::new(glam::Vec3::ZERO, glam::Vec3::ZERO, glam::Vec3::Y, hikari_core::photon::PathClass::Indirect)];
        let data = if photons.is_empty() { &zero[..] } else { photons };
        PhotonBuffer {
            buffer: device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some(label),
                contents: bytemuck::cast_slice(data),
                usage: wgpu::BufferUsages::VERTEX | wgpu::BufferUsages::STORAGE,
            }),
            count: photons.len() as u32,
        }
    }
}

//! The present pass: the resolved frame to a window's surface texture (or
//! any colour target), tone-mapped as `hikari_core::output::tone_map` does
//! for PNG files, so the window shows what `--screenshot` writes.

use bytemuck::{Pod, Zeroable};
use wgpu::util::DeviceExt;

/// present.wgsl after the shared fullscreen triangle.
pub fn shader_source() -> String {
    format!("{}\n{}", crate::FULLSCREEN_WGSL, include_str!("present.wgsl"))
}

/// Mirrors `PresentParams` in present.wgsl.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct PresentParams {
    pub scale: f32,
    pub encode_srgb: u32,
    pub mode: u32,
    pub _pad1: u32,
}

/// What the window shows.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum PresentMode {
    /// Linear radiance, tone-mapped as PNG output.
    #[default]
    Radiance,
    /// A G-buffer's normals, xyz · 0.5 + 0.5.
    Normals,
    /// A G-buffer's albedo.
    Albedo,
    /// Photons as points coloured by power (`points::PointsPass`), as stored.
    Photons,
    /// Photons as points coloured by LOD detail level, as stored.
    DetailLevels,
}

pub struct PresentPass {
    pipeline: wgpu::RenderPipeline,
    layout: wgpu::BindGroupLayout,
    /// The target is an sRGB format (its stores encode).
    srgb_target: bool,
}

impl PresentPass {
    /// A pass drawing into targets of `format`.
    pub fn new(device: &wgpu::Device, format: wgpu::TextureFormat) -> Self {
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("present.wgsl"),
            source: wgpu::ShaderSource::Wgsl(shader_source().into()),
        });
        use crate::binding::{entry, texture, uniform};
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("present"),
            entries: &[
                entry(0, wgpu::ShaderStages::FRAGMENT, uniform()),
                entry(1, wgpu::ShaderStages::FRAGMENT, texture(wgpu::TextureViewDimension::D2)),
            ],
        });
        let pipeline_layout = crate::binding::pipeline_layout(device, "present", &layout);
        let pipeline = crate::binding::fullscreen_pipeline(device, "present", &pipeline_layout, &module, format);
        PresentPass { pipeline, layout, srgb_target: format.is_srgb() }
    }

    /// Draws `frame` (linear radiance, tone-mapped with `exposure` stops;
    /// or a G-buffer texture, per `mode`) into `target`.
    #[allow(clippy::too_many_arguments)]
    pub fn record(
        &self,
        device: &wgpu::Device,
        encoder: &mut wgpu::CommandEncoder,
        frame: &wgpu::Texture,
        target: &wgpu::TextureView,
        exposure: f32,
        mode: PresentMode,
    ) {
        let params = PresentParams {
            scale: 2f32.powf(exposure),
            encode_srgb: (!self.srgb_target) as u32,
            mode: mode as u32,
            _pad1: 0,
        };
        let uniforms = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("present params"),
            contents: bytemuck::bytes_of(&params),
            usage: wgpu::BufferUsages::UNIFORM,
        });
        let frame_view = frame.create_view(&Default::default());
        let bind_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("present"),
            layout: &self.layout,
            entries: &[
                wgpu::BindGroupEntry { binding: 0, resource: uniforms.as_entire_binding() },
                wgpu::BindGroupEntry { binding: 1, resource: wgpu::BindingResource::TextureView(&frame_view) },
            ],
        });
        let mut pass = crate::binding::color_pass(encoder, "present", target, true);
        pass.set_pipeline(&self.pipeline);
        pass.set_bind_group(0, &bind_group, &[]);
        pass.draw(0..3, 0..1);
    }
}

//! The present pass: the resolved frame to a window's surface texture (or
//! any colour target), tone-mapped as `hikari_core::output::tone_map` does
//! for PNG files, so the window shows what `--screenshot` writes.

use bytemuck::{Pod, Zeroable};

/// present.wgsl after the shared fullscreen triangle.
pub fn shader_source() -> String {
    use crate::wgsl::{FULLSCREEN, Module, compose};
    static PRESENT: Module = Module { name: "present.wgsl", source: include_str!("present.wgsl"), requires: &[] };
    compose(&[&FULLSCREEN, &PRESENT])
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
    params: wgpu::Buffer,
    /// Bind groups of the textures shown lately (the mean, G-buffer views,
    /// points), made once each; the oldest goes when a fifth comes.
    bound: Vec<(wgpu::Texture, wgpu::BindGroup)>,
}

/// How many shown textures keep their bind groups.
const BOUND_TEXTURES: usize = 4;

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
        let params = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("present params"),
            size: std::mem::size_of::<PresentParams>() as u64,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        PresentPass { pipeline, layout, srgb_target: format.is_srgb(), params, bound: Vec::new() }
    }

    /// Draws `frame` (linear radiance, tone-mapped with `exposure` stops;
    /// or a G-buffer texture, per `mode`) into `target`.
    #[allow(clippy::too_many_arguments)]
    pub fn record(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
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
        queue.write_buffer(&self.params, 0, bytemuck::bytes_of(&params));
        let index = match self.bound.iter().position(|(t, _)| t == frame) {
            Some(i) => i,
            None => {
                if self.bound.len() == BOUND_TEXTURES {
                    self.bound.remove(0);
                }
                let frame_view = frame.create_view(&Default::default());
                let bind_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
                    label: Some("present"),
                    layout: &self.layout,
                    entries: &[
                        wgpu::BindGroupEntry { binding: 0, resource: self.params.as_entire_binding() },
                        wgpu::BindGroupEntry { binding: 1, resource: wgpu::BindingResource::TextureView(&frame_view) },
                    ],
                });
                self.bound.push((frame.clone(), bind_group));
                self.bound.len() - 1
            }
        };
        let mut pass = crate::binding::color_pass(encoder, "present", target, true);
        pass.set_pipeline(&self.pipeline);
        pass.set_bind_group(0, &self.bound[index].1, &[]);
        pass.draw(0..3, 0..1);
    }
}

//! The volume splat pass (METHOD.md §5, eq. 5.21–5.24): every surviving
//! volume photon as one instanced quad, each fragment adding the light it
//! scatters toward the eye along the pixel's view ray, attenuated by the
//! media between (exactly for media filling the scene, from the
//! optical-depth slices for regions).

use crate::gbuffer::GBuffer;
use crate::lod::LodOutput;
use crate::media::GpuMedia;
use bytemuck::{Pod, Zeroable};
use wgpu::util::DeviceExt;

/// Mirrors `VolumeParams` in volume.wgsl.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct VolumeParams {
    pub clip_from_world: [[f32; 4]; 4],
    pub radius: f32,
    pub power_unit: f32,
    pub _pad0: u32,
    pub _pad1: u32,
}

pub fn shader_source() -> String {
    use crate::wgsl::{ESTIMATE, Module, UNCOUNTED_LOOPS, compose};
    static VOLUME: Module = Module { name: "volume.wgsl", source: include_str!("volume.wgsl"), requires: &[] };
    compose(&[
        &UNCOUNTED_LOOPS,
        &ESTIMATE,
        &crate::splat::FOOTPRINT,
        &crate::media::MEDIA,
        &crate::media::REGION_ARRAY,
        &crate::media::VIEW_DEPTH,
        &crate::wgsl::VOLUME_CHORD,
        &VOLUME,
    ])
}

pub struct VolumePass {
    pipeline: wgpu::RenderPipeline,
    bind_group: wgpu::BindGroup,
    uniforms: wgpu::Buffer,
}

impl VolumePass {
    pub fn new(
        device: &wgpu::Device,
        format: wgpu::TextureFormat,
        params: &VolumeParams,
        media: &GpuMedia,
        gbuffer: &GBuffer,
    ) -> Self {
        use crate::binding::{entry, storage, texture, uniform};
        use wgpu::TextureViewDimension::{D2, D2Array};
        let stages = wgpu::ShaderStages::VERTEX_FRAGMENT;
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("volume splat"),
            entries: &[
                entry(0, stages, uniform()),
                entry(1, stages, uniform()),
                entry(2, stages, storage(true)),
                entry(3, stages, texture(D2Array)),
                entry(4, stages, texture(D2)),
            ],
        });
        let uniforms = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("volume params"),
            contents: bytemuck::bytes_of(params),
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
        });
        let slices =
            media.slices.create_view(&wgpu::TextureViewDescriptor { dimension: Some(D2Array), ..Default::default() });
        let position = gbuffer.position.create_view(&Default::default());
        let bind_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("volume splat"),
            layout: &layout,
            entries: &[
                wgpu::BindGroupEntry { binding: 0, resource: uniforms.as_entire_binding() },
                wgpu::BindGroupEntry { binding: 1, resource: media.params_buffer.as_entire_binding() },
                wgpu::BindGroupEntry { binding: 2, resource: media.regions.as_entire_binding() },
                wgpu::BindGroupEntry { binding: 3, resource: wgpu::BindingResource::TextureView(&slices) },
                wgpu::BindGroupEntry { binding: 4, resource: wgpu::BindingResource::TextureView(&position) },
            ],
        });
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("volume.wgsl"),
            source: wgpu::ShaderSource::Wgsl(shader_source().into()),
        });
        let pipeline_layout = crate::binding::pipeline_layout(device, "volume splat", &layout);
        let instances = [Some(crate::photons::photon_instances())];
        let pipeline =
            crate::splat::additive_pipeline(device, &pipeline_layout, &module, format, &instances, "volume", &[], None);
        VolumePass { pipeline, bind_group, uniforms }
    }

    /// New parameters (a moved camera) from the next frame on.
    pub fn set_params(&self, queue: &wgpu::Queue, params: &VolumeParams) {
        queue.write_buffer(&self.uniforms, 0, bytemuck::bytes_of(params));
    }

    /// Clears `target` and adds the surviving volume photons' in-scattering
    /// (only clears it when `draw` is false).
    pub fn record(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        photons: &LodOutput,
        target: &wgpu::TextureView,
        draw: bool,
    ) {
        let mut pass = crate::binding::color_pass(encoder, "volume splat", target, true);
        if !draw {
            return;
        }
        pass.set_pipeline(&self.pipeline);
        pass.set_bind_group(0, &self.bind_group, &[]);
        pass.set_vertex_buffer(0, photons.survivors.slice(..));
        pass.draw_indirect(&photons.draw_args, 0);
    }
}

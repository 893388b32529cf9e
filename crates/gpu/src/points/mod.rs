//! A debug view of the photon maps: every photon the last frame drew, as a
//! point, coloured by its power (global maps white-ish, caustic cyan,
//! volume orange) or by its LOD detail level in false colour.

use crate::gbuffer::{DEPTH_FORMAT, GBuffer};
use crate::lod::LodOutput;
use bytemuck::{Pod, Zeroable};
use glam::{Mat4, Vec3};

pub fn shader_source() -> String {
    use crate::wgsl::{ESTIMATE, Module, compose};
    static POINTS: Module = Module { name: "points.wgsl", source: include_str!("points.wgsl"), requires: &[] };
    compose(&[&ESTIMATE, &POINTS])
}

/// What the points' colours show.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PointColors {
    /// Each photon's power colour, tinted by its map.
    Power,
    /// Each photon's LOD detail level (0 full detail, blue; 1 coarsest, red).
    DetailLevel,
}

/// Mirrors `PointsParams` in points.wgsl.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
struct PointsParams {
    clip_from_world: [[f32; 4]; 4],
    eye: [f32; 3],
    mode: u32,
    tint: [f32; 3],
    _pad: u32,
}

/// The tints of the global, caustic and volume maps' points.
pub const TINTS: [Vec3; 3] = [Vec3::new(1.0, 1.0, 1.0), Vec3::new(0.3, 0.9, 1.0), Vec3::new(1.0, 0.6, 0.2)];

pub struct PointsPass {
    pipeline: wgpu::RenderPipeline,
    /// One uniform buffer and bind group per map, written each time.
    params: [(wgpu::Buffer, wgpu::BindGroup); 3],
    /// The view: black where no photon is.
    pub target: wgpu::Texture,
}

impl PointsPass {
    /// A pass drawing into a new `Rgba8Unorm` target the size of `gbuffer`.
    pub fn new(device: &wgpu::Device, gbuffer: &GBuffer) -> Self {
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("points.wgsl"),
            source: wgpu::ShaderSource::Wgsl(shader_source().into()),
        });
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("points"),
            entries: &[crate::binding::entry(0, wgpu::ShaderStages::VERTEX, crate::binding::uniform())],
        });
        let pipeline_layout = crate::binding::pipeline_layout(device, "points", &layout);
        let format = wgpu::TextureFormat::Rgba8Unorm;
        let pipeline = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some("points"),
            layout: Some(&pipeline_layout),
            vertex: wgpu::VertexState {
                module: &module,
                entry_point: Some("vs_main"),
                compilation_options: Default::default(),
                buffers: &[Some(crate::photons::photon_instances())],
            },
            primitive: wgpu::PrimitiveState { topology: wgpu::PrimitiveTopology::PointList, ..Default::default() },
            depth_stencil: Some(wgpu::DepthStencilState {
                format: DEPTH_FORMAT,
                depth_write_enabled: Some(false),
                depth_compare: Some(wgpu::CompareFunction::LessEqual),
                stencil: Default::default(),
                bias: Default::default(),
            }),
            multisample: Default::default(),
            fragment: Some(wgpu::FragmentState {
                module: &module,
                entry_point: Some("fs_main"),
                compilation_options: Default::default(),
                targets: &[Some(wgpu::ColorTargetState { format, blend: None, write_mask: wgpu::ColorWrites::ALL })],
            }),
            multiview_mask: None,
            cache: None,
        });
        let params = std::array::from_fn(|_| {
            let buffer = device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("points params"),
                size: std::mem::size_of::<PointsParams>() as u64,
                usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            });
            let bind_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some("points"),
                layout: &layout,
                entries: &[wgpu::BindGroupEntry { binding: 0, resource: buffer.as_entire_binding() }],
            });
            (buffer, bind_group)
        });
        let target = device.create_texture(&wgpu::TextureDescriptor {
            label: Some("photon points"),
            size: wgpu::Extent3d { width: gbuffer.width, height: gbuffer.height, depth_or_array_layers: 1 },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format,
            usage: wgpu::TextureUsages::RENDER_ATTACHMENT
                | wgpu::TextureUsages::TEXTURE_BINDING
                | wgpu::TextureUsages::COPY_SRC,
            view_formats: &[],
        });
        PointsPass { pipeline, params, target }
    }

    /// Draws `maps` (global, caustic, volume: the survivors of the last
    /// frame's LOD pass) over a black target, behind `gbuffer`'s depth.
    pub fn record(
        &self,
        queue: &wgpu::Queue,
        encoder: &mut wgpu::CommandEncoder,
        maps: [Option<&LodOutput>; 3],
        gbuffer: &GBuffer,
        clip_from_world: Mat4,
        eye: Vec3,
        colors: PointColors,
    ) {
        let view = self.target.create_view(&Default::default());
        let depth = gbuffer.depth.create_view(&Default::default());
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("photon points"),
            color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                view: &view,
                depth_slice: None,
                resolve_target: None,
                ops: wgpu::Operations { load: wgpu::LoadOp::Clear(wgpu::Color::BLACK), store: wgpu::StoreOp::Store },
            })],
            depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                view: &depth,
                depth_ops: Some(wgpu::Operations { load: wgpu::LoadOp::Load, store: wgpu::StoreOp::Store }),
                stencil_ops: None,
            }),
            timestamp_writes: None,
            occlusion_query_set: None,
            multiview_mask: None,
        });
        pass.set_pipeline(&self.pipeline);
        for ((map, tint), (buffer, bind_group)) in maps.into_iter().zip(TINTS).zip(&self.params) {
            let Some(map) = map else { continue };
            let params = PointsParams {
                clip_from_world: clip_from_world.to_cols_array_2d(),
                eye: eye.to_array(),
                mode: (colors == PointColors::DetailLevel) as u32,
                tint: tint.to_array(),
                _pad: 0,
            };
            queue.write_buffer(buffer, 0, bytemuck::bytes_of(&params));
            pass.set_bind_group(0, bind_group, &[]);
            pass.set_vertex_buffer(0, map.survivors.slice(..));
            pass.draw_indirect(&map.draw_args, 0);
        }
    }
}

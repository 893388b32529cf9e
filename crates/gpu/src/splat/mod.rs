//! The photon splat pass: instanced quads, one per photon, additively
//! blended into a float radiance target (METHOD.md §4, steps 2–3).

pub mod depth_tiles;

use crate::gbuffer::GBuffer;
use bytemuck::{Pod, Zeroable};

/// Mirrors `SplatParams` in splat.wgsl.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct SplatParams {
    pub clip_from_world: [[f32; 4]; 4],
    pub radius: f32,
    pub power_unit: f32,
    pub normal_test: u32,
    pub _pad: u32,
    /// The eye, for glossy surfaces' BRDF.
    pub camera_position: [f32; 3],
    pub _pad1: u32,
}

/// The photon footprint vertex shader shared with the volume splat.
pub static FOOTPRINT: crate::wgsl::Module = crate::wgsl::Module {
    name: "footprint.wgsl",
    source: include_str!("footprint.wgsl"),
    requires: &[&crate::wgsl::PHOTON_ENCODING, &FOOTPRINT_RECT],
};

/// The conservative screen rectangle of a photon's sphere (`photon_footprint`).
pub static FOOTPRINT_RECT: crate::wgsl::Module =
    crate::wgsl::Module { name: "footprint_rect.wgsl", source: include_str!("footprint_rect.wgsl"), requires: &[] };

pub fn shader_source() -> String {
    use crate::wgsl::{ESTIMATE, Module, compose};
    static SPLAT: Module =
        Module { name: "splat.wgsl", source: include_str!("splat.wgsl"), requires: &[&depth_tiles::TILE_CONSTANTS] };
    compose(&[&ESTIMATE, &crate::wgsl::PHOTON_BRDF, &crate::gbuffer::layer_texels::LAYER_TEXELS, &FOOTPRINT, &SPLAT])
}

/// A render pipeline (`vs_main`, `fs_main`) that adds its fragments into a
/// float target: the photon splats (a triangle strip per instance when
/// `buffers` holds the photon stream) and the optical-depth pass (a list),
/// with values for `fs_main`'s pipeline-overridable constants and a depth
/// test (read only) where given.
#[allow(clippy::too_many_arguments)]
pub fn additive_pipeline(
    device: &wgpu::Device,
    layout: &wgpu::PipelineLayout,
    module: &wgpu::ShaderModule,
    format: wgpu::TextureFormat,
    buffers: &[Option<wgpu::VertexBufferLayout>],
    label: &str,
    constants: &[(&str, f64)],
    depth_stencil: Option<wgpu::DepthStencilState>,
) -> wgpu::RenderPipeline {
    let additive = wgpu::BlendComponent {
        src_factor: wgpu::BlendFactor::One,
        dst_factor: wgpu::BlendFactor::One,
        operation: wgpu::BlendOperation::Add,
    };
    let topology =
        if buffers.is_empty() { wgpu::PrimitiveTopology::TriangleList } else { wgpu::PrimitiveTopology::TriangleStrip };
    device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
        label: Some(label),
        layout: Some(layout),
        vertex: wgpu::VertexState {
            module,
            entry_point: Some("vs_main"),
            compilation_options: Default::default(),
            buffers,
        },
        primitive: wgpu::PrimitiveState { topology, cull_mode: None, ..Default::default() },
        depth_stencil,
        multisample: Default::default(),
        fragment: Some(wgpu::FragmentState {
            module,
            entry_point: Some("fs_main"),
            compilation_options: wgpu::PipelineCompilationOptions { constants, ..Default::default() },
            targets: &[Some(wgpu::ColorTargetState {
                format,
                blend: Some(wgpu::BlendState { color: additive, alpha: additive }),
                write_mask: wgpu::ColorWrites::ALL,
            })],
        }),
        multiview_mask: None,
        cache: None,
    })
}

/// One map's splat state (its uniforms and bind group), kept between frames.
pub struct SplatBinding {
    uniforms: wgpu::Buffer,
    bind_group: wgpu::BindGroup,
    /// The G-buffer's depth, against which the quads are tested.
    depth: wgpu::TextureView,
}

pub struct SplatPass {
    pipeline: wgpu::RenderPipeline,
    layout: wgpu::BindGroupLayout,
}

impl SplatPass {
    /// Specialised to what a scene with `features` uses.
    pub fn new(
        device: &wgpu::Device,
        target_format: wgpu::TextureFormat,
        features: crate::features::SceneFeatures,
    ) -> Self {
        let source = shader_source();
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("splat.wgsl"),
            source: wgpu::ShaderSource::Wgsl(source.as_str().into()),
        });
        use crate::binding::{entry, texture, uniform};
        use wgpu::TextureViewDimension::D2;
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("splat"),
            entries: &[
                entry(0, wgpu::ShaderStages::VERTEX_FRAGMENT, uniform()),
                // The G-buffer's position: its size is read by the vertex shader.
                entry(1, wgpu::ShaderStages::VERTEX_FRAGMENT, texture(D2)),
                entry(2, wgpu::ShaderStages::FRAGMENT, texture(D2)),
                entry(3, wgpu::ShaderStages::FRAGMENT, texture(D2)),
                entry(4, wgpu::ShaderStages::FRAGMENT, crate::binding::storage(true)),
                entry(5, wgpu::ShaderStages::FRAGMENT, texture(D2)),
                entry(6, wgpu::ShaderStages::VERTEX, texture(D2)),
                entry(7, wgpu::ShaderStages::FRAGMENT, crate::binding::texture_uint()),
            ],
        });
        let pipeline_layout = crate::binding::pipeline_layout(device, "splat", &layout);
        let pipeline = additive_pipeline(
            device,
            &pipeline_layout,
            &module,
            target_format,
            &[Some(crate::photons::photon_instances())],
            "splat",
            &features.constants(&source),
            // Quads lie at their sphere's front depth (footprint_rect.wgsl):
            // pixels whose surface is nearer fail before their fragment runs.
            Some(wgpu::DepthStencilState {
                format: crate::gbuffer::DEPTH_FORMAT,
                depth_write_enabled: Some(false),
                depth_compare: Some(wgpu::CompareFunction::LessEqual),
                stencil: Default::default(),
                bias: Default::default(),
            }),
        );
        SplatPass { pipeline, layout }
    }

    /// The uniforms and bind group of one map's splat over `gbuffer` of a
    /// scene with `surfaces` (`SceneBuffers::surfaces`), with `depth_tiles`
    /// (`depth_tiles::DepthTiles::tiles`), made once per scene.
    pub fn bind(
        &self,
        device: &wgpu::Device,
        gbuffer: &GBuffer,
        surfaces: &wgpu::Buffer,
        depth_tiles: &wgpu::Texture,
    ) -> SplatBinding {
        let uniforms = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("splat params"),
            size: std::mem::size_of::<SplatParams>() as u64,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let view = |t: &wgpu::Texture| t.create_view(&Default::default());
        let (position, normal, albedo) = (view(&gbuffer.position), view(&gbuffer.normal), view(&gbuffer.albedo));
        let (emission, layers) = (view(&gbuffer.emission), view(&gbuffer.layers));
        let bind_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("splat"),
            layout: &self.layout,
            entries: &[
                wgpu::BindGroupEntry { binding: 0, resource: uniforms.as_entire_binding() },
                wgpu::BindGroupEntry { binding: 1, resource: wgpu::BindingResource::TextureView(&position) },
                wgpu::BindGroupEntry { binding: 2, resource: wgpu::BindingResource::TextureView(&normal) },
                wgpu::BindGroupEntry { binding: 3, resource: wgpu::BindingResource::TextureView(&albedo) },
                wgpu::BindGroupEntry { binding: 4, resource: surfaces.as_entire_binding() },
                wgpu::BindGroupEntry { binding: 5, resource: wgpu::BindingResource::TextureView(&emission) },
                wgpu::BindGroupEntry { binding: 6, resource: wgpu::BindingResource::TextureView(&view(depth_tiles)) },
                wgpu::BindGroupEntry { binding: 7, resource: wgpu::BindingResource::TextureView(&layers) },
            ],
        });
        SplatBinding { uniforms, bind_group, depth: view(&gbuffer.depth) }
    }

    /// Adds the surviving photons' radiance (counted by the LOD pass) into
    /// `target` (loaded, not cleared, when `clear` is false, so several maps
    /// can accumulate), with `params` (written now into `binding`).
    #[allow(clippy::too_many_arguments)]
    pub fn record(
        &self,
        queue: &wgpu::Queue,
        encoder: &mut wgpu::CommandEncoder,
        binding: &SplatBinding,
        photons: &crate::lod::LodOutput,
        params: &SplatParams,
        target: &wgpu::TextureView,
        clear: bool,
    ) {
        queue.write_buffer(&binding.uniforms, 0, bytemuck::bytes_of(params));
        let bind_group = &binding.bind_group;
        let load = if clear { wgpu::LoadOp::Clear(wgpu::Color::TRANSPARENT) } else { wgpu::LoadOp::Load };
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("photon splat"),
            color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                view: target,
                depth_slice: None,
                resolve_target: None,
                ops: wgpu::Operations { load, store: wgpu::StoreOp::Store },
            })],
            // The G-buffer's depth, read only.
            depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                view: &binding.depth,
                depth_ops: None,
                stencil_ops: None,
            }),
            timestamp_writes: None,
            occlusion_query_set: None,
            multiview_mask: None,
        });
        pass.set_pipeline(&self.pipeline);
        pass.set_bind_group(0, bind_group, &[]);
        pass.set_vertex_buffer(0, photons.survivors.slice(..));
        pass.draw_indirect(&photons.draw_args, 0);
    }
}

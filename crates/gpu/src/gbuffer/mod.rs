//! The G-buffer pass: rasterizes the scene once, storing per pixel what the
//! later passes shade (METHOD.md §4, step 1).

pub mod geometric_normal;
pub mod layer_texels;

use crate::scene_upload::{GpuVertex, SceneBuffers};
use bytemuck::{Pod, Zeroable};

/// Mirrors `GBufferParams` in gbuffer.wgsl.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct GBufferParams {
    pub clip_from_world: [[f32; 4]; 4],
    pub camera_position: [f32; 3],
    /// Changes from pass to pass: which fragments of BLEND surfaces are
    /// there (gbuffer.wgsl's `fragment_blend_threshold`).
    pub blend_seed: u32,
}

pub const TARGET_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba32Float;
pub const DEPTH_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Depth32Float;
pub fn shader_source() -> String {
    use crate::wgsl::{Module, SURFACE, compose};
    static GBUFFER: Module = Module {
        name: "gbuffer.wgsl",
        source: include_str!("gbuffer.wgsl"),
        requires: &[
            &SURFACE,
            &crate::textures::SURFACE_POINT,
            &geometric_normal::GEOMETRIC_NORMAL,
            &layer_texels::LAYER_TEXELS,
        ],
    };
    compose(&[&GBUFFER])
}

/// gbuffer.wgsl with the storage path's fragment entry point.
pub fn storage_shader_source() -> String {
    format!("{}\n{}", shader_source(), include_str!("gbuffer_storage.wgsl"))
}

/// `GpuVertex` as vertex attributes, offsets written by hand (a test checks
/// them against the struct).
pub const VERTEX_ATTRIBUTES: [wgpu::VertexAttribute; 6] = [
    wgpu::VertexAttribute { format: wgpu::VertexFormat::Float32x3, offset: 0, shader_location: 0 },
    wgpu::VertexAttribute { format: wgpu::VertexFormat::Float32x3, offset: 12, shader_location: 1 },
    wgpu::VertexAttribute { format: wgpu::VertexFormat::Float32x3, offset: 24, shader_location: 2 },
    wgpu::VertexAttribute { format: wgpu::VertexFormat::Uint32, offset: 36, shader_location: 3 },
    wgpu::VertexAttribute { format: wgpu::VertexFormat::Float32x2, offset: 40, shader_location: 4 },
    wgpu::VertexAttribute { format: wgpu::VertexFormat::Snorm16x4, offset: 48, shader_location: 5 },
];

/// The G-buffer's textures, all `width × height`.
pub struct GBuffer {
    pub width: u32,
    pub height: u32,
    pub position: wgpu::Texture,
    pub normal: wgpu::Texture,
    pub albedo: wgpu::Texture,
    pub emission: wgpu::Texture,
    /// The layer textures' texels (`layer_texels`), where the scene is
    /// LAYERED; else one texel, which the passes bind and never read.
    pub layers: wgpu::Texture,
    pub depth: wgpu::Texture,
}

impl GBuffer {
    /// With `storage`, the targets are written as storage textures
    /// (`GBufferPass` on adapters that cannot render to Rgba32Float); with
    /// `layered`, the fifth target is the image's size.
    pub fn new(device: &wgpu::Device, width: u32, height: u32, storage: bool, layered: bool) -> Self {
        let written_as =
            if storage { wgpu::TextureUsages::STORAGE_BINDING } else { wgpu::TextureUsages::RENDER_ATTACHMENT };
        let texture = |label, format, (width, height)| {
            device.create_texture(&wgpu::TextureDescriptor {
                label: Some(label),
                size: wgpu::Extent3d { width, height, depth_or_array_layers: 1 },
                mip_level_count: 1,
                sample_count: 1,
                dimension: wgpu::TextureDimension::D2,
                format,
                usage: written_as | wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_SRC,
                view_formats: &[],
            })
        };
        let target = |label| texture(label, TARGET_FORMAT, (width, height));
        let layers_size = if layered { (width, height) } else { (1, 1) };
        let depth = device.create_texture(&wgpu::TextureDescriptor {
            label: Some("gbuffer depth"),
            size: wgpu::Extent3d { width, height, depth_or_array_layers: 1 },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: DEPTH_FORMAT,
            usage: wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::TEXTURE_BINDING,
            view_formats: &[],
        });
        GBuffer {
            width,
            height,
            position: target("gbuffer position"),
            normal: target("gbuffer normal"),
            albedo: target("gbuffer albedo"),
            emission: target("gbuffer emission"),
            layers: texture("gbuffer layers", layer_texels::LAYERS_FORMAT, layers_size),
            depth,
        }
    }
}

/// A `GBufferPass`'s per-target state, kept between frames.
pub struct GBufferBinding {
    uniforms: wgpu::Buffer,
    bind_group: wgpu::BindGroup,
    views: Vec<wgpu::TextureView>,
}

pub struct GBufferPass {
    layout: wgpu::BindGroupLayout,
    mode: Mode,
    /// The fifth target is written (`SceneFeatures::layered`).
    layered: bool,
}

/// How the G-buffer is written.
enum Mode {
    /// Four Rgba32Float colour targets (and the layers' Rgba32Uint).
    Targets(wgpu::RenderPipeline),
    /// A depth-only draw, then a draw whose nearest fragments store into
    /// storage textures (gbuffer_storage.wgsl).
    Storage { depth: wgpu::RenderPipeline, store: wgpu::RenderPipeline },
}

impl GBufferPass {
    /// With `storage`, the storage path (`GpuContext::gbuffer_storage`);
    /// specialised to what a scene with `features` uses.
    pub fn new(device: &wgpu::Device, storage: bool, features: crate::features::SceneFeatures) -> Self {
        let source = if storage { storage_shader_source() } else { shader_source() };
        let constants = features.constants(&source);
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("gbuffer.wgsl"),
            source: wgpu::ShaderSource::Wgsl(source.into()),
        });
        let mut entries = vec![
            crate::binding::entry(0, wgpu::ShaderStages::VERTEX_FRAGMENT, crate::binding::uniform()),
            crate::binding::entry(1, wgpu::ShaderStages::FRAGMENT, crate::binding::storage(true)),
            crate::binding::entry(2, wgpu::ShaderStages::FRAGMENT, crate::binding::storage(true)),
        ];
        let layered = features.layered;
        if storage {
            entries.extend((3..7).map(|b| {
                crate::binding::entry(b, wgpu::ShaderStages::FRAGMENT, crate::binding::storage_texture_rgba32f())
            }));
            if layered {
                let ty = wgpu::BindingType::StorageTexture {
                    access: wgpu::StorageTextureAccess::WriteOnly,
                    format: layer_texels::LAYERS_FORMAT,
                    view_dimension: wgpu::TextureViewDimension::D2,
                };
                entries.push(crate::binding::entry(7, wgpu::ShaderStages::FRAGMENT, ty));
            }
        }
        let layout = device
            .create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor { label: Some("gbuffer"), entries: &entries });
        let pipeline_layout = crate::binding::pipeline_layout(device, "gbuffer", &layout);
        let pipeline = |label: &str, fragment: Option<(&str, &[Option<wgpu::ColorTargetState>])>, depth| {
            device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
                label: Some(label),
                layout: Some(&pipeline_layout),
                vertex: wgpu::VertexState {
                    module: &module,
                    entry_point: Some("vs_main"),
                    compilation_options: Default::default(),
                    buffers: &[Some(wgpu::VertexBufferLayout {
                        array_stride: std::mem::size_of::<GpuVertex>() as u64,
                        step_mode: wgpu::VertexStepMode::Vertex,
                        attributes: &VERTEX_ATTRIBUTES,
                    })],
                },
                primitive: wgpu::PrimitiveState { cull_mode: None, ..Default::default() },
                depth_stencil: Some(depth),
                multisample: Default::default(),
                fragment: fragment.map(|(entry_point, targets)| wgpu::FragmentState {
                    module: &module,
                    entry_point: Some(entry_point),
                    compilation_options: wgpu::PipelineCompilationOptions {
                        constants: &constants,
                        ..Default::default()
                    },
                    targets,
                }),
                multiview_mask: None,
                cache: None,
            })
        };
        let nearest = crate::binding::nearest_depth(DEPTH_FORMAT);
        let mode = if storage {
            let equal = wgpu::DepthStencilState {
                depth_write_enabled: Some(false),
                depth_compare: Some(wgpu::CompareFunction::Equal),
                ..nearest.clone()
            };
            let store = if layered { "fs_storage_layered" } else { "fs_storage" };
            Mode::Storage {
                depth: pipeline("gbuffer depth", Some(("fs_depth", &[])), nearest),
                store: pipeline("gbuffer store", Some((store, &[])), equal),
            }
        } else {
            let target =
                |format| Some(wgpu::ColorTargetState { format, blend: None, write_mask: wgpu::ColorWrites::ALL });
            let mut targets = vec![target(TARGET_FORMAT); 4];
            if layered {
                targets.push(target(layer_texels::LAYERS_FORMAT));
            }
            let entry = if layered { "fs_main_layered" } else { "fs_main" };
            Mode::Targets(pipeline("gbuffer", Some((entry, &targets)), nearest))
        };
        GBufferPass { layout, mode, layered }
    }

    /// The targets of `gbuffer` this pass writes, in location order.
    fn written<'a>(&self, gbuffer: &'a GBuffer) -> Vec<&'a wgpu::Texture> {
        let mut targets = vec![&gbuffer.position, &gbuffer.normal, &gbuffer.albedo, &gbuffer.emission];
        if self.layered {
            targets.push(&gbuffer.layers);
        }
        targets
    }

    /// The uniforms and bind group of frames into `gbuffer`, made once.
    pub fn bind(&self, device: &wgpu::Device, scene: &SceneBuffers, gbuffer: &GBuffer) -> GBufferBinding {
        let uniforms = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("gbuffer params"),
            size: std::mem::size_of::<GBufferParams>() as u64,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let views: Vec<wgpu::TextureView> =
            self.written(gbuffer).iter().map(|t| t.create_view(&Default::default())).collect();
        let mut entries = vec![
            wgpu::BindGroupEntry { binding: 0, resource: uniforms.as_entire_binding() },
            wgpu::BindGroupEntry { binding: 1, resource: scene.surfaces.as_entire_binding() },
            wgpu::BindGroupEntry { binding: 2, resource: scene.textures.as_entire_binding() },
        ];
        if matches!(self.mode, Mode::Storage { .. }) {
            entries.extend(views.iter().enumerate().map(|(i, view)| wgpu::BindGroupEntry {
                binding: 3 + i as u32,
                resource: wgpu::BindingResource::TextureView(view),
            }));
        }
        let bind_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("gbuffer"),
            layout: &self.layout,
            entries: &entries,
        });
        GBufferBinding { uniforms, bind_group, views }
    }

    /// Draws the scene into `gbuffer` as seen with `params` (written now).
    pub fn record(
        &self,
        queue: &wgpu::Queue,
        encoder: &mut wgpu::CommandEncoder,
        scene: &SceneBuffers,
        binding: &GBufferBinding,
        params: &GBufferParams,
        gbuffer: &GBuffer,
    ) {
        queue.write_buffer(&binding.uniforms, 0, bytemuck::bytes_of(params));
        let (bind_group, views) = (&binding.bind_group, &binding.views);
        let depth_view = gbuffer.depth.create_view(&Default::default());
        let draw = |encoder: &mut wgpu::CommandEncoder,
                    pipeline: &wgpu::RenderPipeline,
                    color: &[Option<wgpu::RenderPassColorAttachment>],
                    depth_load: wgpu::LoadOp<f32>| {
            let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("gbuffer"),
                color_attachments: color,
                depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                    view: &depth_view,
                    depth_ops: Some(wgpu::Operations { load: depth_load, store: wgpu::StoreOp::Store }),
                    stencil_ops: None,
                }),
                timestamp_writes: None,
                occlusion_query_set: None,
                multiview_mask: None,
            });
            pass.set_pipeline(pipeline);
            pass.set_bind_group(0, bind_group, &[]);
            pass.set_vertex_buffer(0, scene.vertices.slice(..));
            pass.draw(0..scene.vertex_count, 0..1);
        };
        match &self.mode {
            Mode::Targets(pipeline) => {
                let attachments: Vec<Option<wgpu::RenderPassColorAttachment>> = views
                    .iter()
                    .map(|view| {
                        Some(wgpu::RenderPassColorAttachment {
                            view,
                            depth_slice: None,
                            resolve_target: None,
                            ops: wgpu::Operations {
                                load: wgpu::LoadOp::Clear(wgpu::Color::TRANSPARENT),
                                store: wgpu::StoreOp::Store,
                            },
                        })
                    })
                    .collect();
                draw(encoder, pipeline, &attachments, wgpu::LoadOp::Clear(1.0));
            }
            Mode::Storage { depth, store } => {
                for texture in self.written(gbuffer) {
                    encoder.clear_texture(texture, &Default::default());
                }
                draw(encoder, depth, &[], wgpu::LoadOp::Clear(1.0));
                draw(encoder, store, &[], wgpu::LoadOp::Load);
            }
        }
    }
}

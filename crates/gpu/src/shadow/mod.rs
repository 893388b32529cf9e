//! The shadow pass: renders, for every light sample, the distance to the
//! nearest surface into layers of one float texture array (a cube of six
//! layers for point and area samples, one layer for narrow spots), or for
//! a distant light's sample, in one orthographic layer, the distance along
//! its direction from the plane its photons start from.
//!
//! The distance is stored divided by the view's `range` (in
//! `light_position.w`), so it lies in [0, 1]: then `R16Float`, which
//! adapters that cannot render `R32Float` (Mesa's OpenGL) use instead, keeps
//! it to 2^-11 relative, well inside the shadow bias (1%). Depth textures
//! would avoid the colour target, but GLSL can neither `textureLoad` them
//! nor (on llvmpipe's GL, measured) compare them.

pub mod light_samples;

use crate::gbuffer::DEPTH_FORMAT;
use crate::scene_upload::{GpuVertex, SceneBuffers};
use bytemuck::{Pod, Zeroable};
use glam::Vec3;
use light_samples::{GpuLights, MeshOccluders, ShadowView};
use wgpu::util::DeviceExt;

/// `ShadowView` and the depth a view stores (shared with light_eval.wgsl).
pub static SHADOW_VIEW: crate::wgsl::Module =
    crate::wgsl::Module { name: "shadow_view.wgsl", source: include_str!("shadow_view.wgsl"), requires: &[] };

pub fn shader_source() -> String {
    use crate::wgsl::{Module, compose};
    static SHADOW: Module = Module {
        name: "shadow.wgsl",
        source: include_str!("shadow.wgsl"),
        requires: &[&SHADOW_VIEW, &crate::textures::SURFACE_POINT],
    };
    compose(&[&SHADOW])
}
/// The shadow-map format: `R32Float` where it is renderable, else `R16Float`.
pub fn map_format(r32_renderable: bool) -> wgpu::TextureFormat {
    if r32_renderable { wgpu::TextureFormat::R32Float } else { wgpu::TextureFormat::R16Float }
}

/// Mirrors `ShadowView` in shadow_view.wgsl.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct ShadowViewParams {
    pub clip_from_world: [[f32; 4]; 4],
    /// xyz: the light sample (perspective) or a point of the start plane
    /// (orthographic); w: the range.
    pub light_position: [f32; 4],
    /// Orthographic views: the unit direction light travels and the view's
    /// width; zero for perspective views.
    pub direction: [f32; 4],
    /// x: which fragments of BLEND surfaces cast shadow in this drawing
    /// (shadow.wgsl, `fragment_blend_threshold`); changes from pass to pass
    /// (`ShadowMaps::set_blend_seed`). yzw unused.
    pub blend_seed: [u32; 4],
}

impl ShadowViewParams {
    /// The view of `v`, storing depths as fractions of its range: the
    /// distance from the light sample to the farthest corner of the scene
    /// bounds `(lo, hi)`, or for an orthographic view the farthest corner's
    /// depth along its direction (so every surface's depth fits in [0, 1]).
    pub fn new(v: &ShadowView, (lo, hi): (Vec3, Vec3)) -> Self {
        let (range, direction) = match v.orthographic {
            None => (shadow_range(v.light_position, lo, hi), [0.0; 4]),
            Some((dir, width)) => {
                let corner = Vec3::select(dir.cmpge(Vec3::ZERO), hi, lo);
                let depth = (corner - v.light_position).dot(dir);
                ((depth * 1.01).max(1e-20), dir.extend(width).to_array())
            }
        };
        ShadowViewParams {
            clip_from_world: v.clip_from_world.to_cols_array_2d(),
            light_position: v.light_position.extend(range).to_array(),
            direction,
            blend_seed: [0; 4],
        }
    }
}

/// The farthest distance from `from` to the box `[lo, hi]`, with 1% to spare
/// (at least a tiny positive length, so the shader can divide by it): the
/// shadow views' range, and the far plane of the camera's.
pub fn shadow_range(from: Vec3, lo: Vec3, hi: Vec3) -> f32 {
    let far = (from - lo).abs().max((from - hi).abs());
    (far.length() * 1.01).max(1e-20)
}

pub struct ShadowMaps {
    pub size: u32,
    pub layers: u32,
    /// Distance to the nearest surface / range, one layer per view.
    pub texture: wgpu::Texture,
    depth: wgpu::Texture,
    view_bind_groups: Vec<wgpu::BindGroup>,
    /// Each view's parameters, as bound in `view_bind_groups`.
    view_buffers: Vec<wgpu::Buffer>,
    /// All views, for the direct pass's lookups.
    pub views_buffer: wgpu::Buffer,
    /// The light each view belongs to.
    view_lights: Vec<u32>,
    /// The emissive meshes' triangles (None without any) and their ranges.
    mesh_vertices: Option<wgpu::Buffer>,
    occluders: MeshOccluders,
}

impl ShadowMaps {
    /// Moves the views to those of `lights` (lights moved) in a scene now
    /// within `bounds`, from the next frame on. False, with nothing written,
    /// when the number of views or of mesh-light vertices differs: then the
    /// maps must be created anew.
    pub fn update(&self, queue: &wgpu::Queue, lights: &GpuLights, bounds: (Vec3, Vec3)) -> bool {
        let views = &lights.views;
        if views.len() != self.view_buffers.len()
            || views.is_empty()
            || lights.occluders.vertices.len() != self.occluders.vertices.len()
        {
            return false;
        }
        let params: Vec<ShadowViewParams> = views.iter().map(|v| ShadowViewParams::new(v, bounds)).collect();
        for (buffer, p) in self.view_buffers.iter().zip(&params) {
            queue.write_buffer(buffer, 0, bytemuck::bytes_of(p));
        }
        queue.write_buffer(&self.views_buffer, 0, bytemuck::cast_slice(&params));
        if let Some(buffer) = &self.mesh_vertices {
            queue.write_buffer(buffer, 0, bytemuck::cast_slice(&lights.occluders.vertices));
        }
        true
    }
}

impl ShadowMaps {
    /// Sets the seed with which the next drawing of the views decides which
    /// fragments of BLEND surfaces cast shadow.
    pub fn set_blend_seed(&self, queue: &wgpu::Queue, seed: u32) {
        let offset = std::mem::offset_of!(ShadowViewParams, blend_seed) as u64;
        for buffer in &self.view_buffers {
            queue.write_buffer(buffer, offset, bytemuck::bytes_of(&seed));
        }
    }
}

pub struct ShadowPass {
    pipeline: wgpu::RenderPipeline,
    layout: wgpu::BindGroupLayout,
    /// Group 1: the scene's surfaces and textures (cut-outs).
    scene_layout: wgpu::BindGroupLayout,
    format: wgpu::TextureFormat,
}

impl ShadowPass {
    /// Maps in `format` (`map_format`), of a scene with `features`.
    pub fn new(device: &wgpu::Device, format: wgpu::TextureFormat, features: crate::features::SceneFeatures) -> Self {
        let source = shader_source();
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("shadow.wgsl"),
            source: wgpu::ShaderSource::Wgsl(source.as_str().into()),
        });
        let constants = features.constants(&source);
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("shadow view"),
            entries: &[crate::binding::entry(0, wgpu::ShaderStages::VERTEX_FRAGMENT, crate::binding::uniform())],
        });
        let storage = |b| crate::binding::entry(b, wgpu::ShaderStages::FRAGMENT, crate::binding::storage(true));
        let scene_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("shadow scene"),
            entries: &[storage(0), storage(1)],
        });
        let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("shadow"),
            bind_group_layouts: &[Some(&layout), Some(&scene_layout)],
            immediate_size: 0,
        });
        let pipeline = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some("shadow"),
            layout: Some(&pipeline_layout),
            vertex: wgpu::VertexState {
                module: &module,
                entry_point: Some("vs_main"),
                compilation_options: Default::default(),
                buffers: &[Some(wgpu::VertexBufferLayout {
                    array_stride: std::mem::size_of::<GpuVertex>() as u64,
                    step_mode: wgpu::VertexStepMode::Vertex,
                    attributes: &[
                        crate::gbuffer::VERTEX_ATTRIBUTES[0],
                        crate::gbuffer::VERTEX_ATTRIBUTES[3],
                        crate::gbuffer::VERTEX_ATTRIBUTES[4],
                    ],
                })],
            },
            primitive: wgpu::PrimitiveState { cull_mode: None, ..Default::default() },
            depth_stencil: Some(crate::binding::nearest_depth(DEPTH_FORMAT)),
            multisample: Default::default(),
            fragment: Some(wgpu::FragmentState {
                module: &module,
                entry_point: Some("fs_main"),
                compilation_options: wgpu::PipelineCompilationOptions { constants: &constants, ..Default::default() },
                targets: &[Some(wgpu::ColorTargetState { format, blend: None, write_mask: wgpu::ColorWrites::ALL })],
            }),
            multiview_mask: None,
            cache: None,
        });
        ShadowPass { pipeline, layout, scene_layout, format }
    }

    /// The bind group of `scene`'s surfaces and textures, made once per scene.
    pub fn bind_scene(&self, device: &wgpu::Device, scene: &SceneBuffers) -> wgpu::BindGroup {
        device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("shadow scene"),
            layout: &self.scene_layout,
            entries: &[
                wgpu::BindGroupEntry { binding: 0, resource: scene.surfaces.as_entire_binding() },
                wgpu::BindGroupEntry { binding: 1, resource: scene.textures.as_entire_binding() },
            ],
        })
    }

    /// One layer per view of `lights`, each `size²`, for a scene within `bounds`.
    pub fn create_maps(
        &self,
        device: &wgpu::Device,
        lights: &GpuLights,
        size: u32,
        bounds: (Vec3, Vec3),
    ) -> ShadowMaps {
        let views = &lights.views;
        let layers = views.len().max(1) as u32;
        let texture = device.create_texture(&wgpu::TextureDescriptor {
            label: Some("shadow maps"),
            size: wgpu::Extent3d {
                width: size,
                height: size,
                depth_or_array_layers: crate::binding::array_layers(size, size, layers),
            },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: self.format,
            usage: wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::TEXTURE_BINDING,
            view_formats: &[],
        });
        let depth = device.create_texture(&wgpu::TextureDescriptor {
            label: Some("shadow depth"),
            size: wgpu::Extent3d { width: size, height: size, depth_or_array_layers: 1 },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: DEPTH_FORMAT,
            usage: wgpu::TextureUsages::RENDER_ATTACHMENT,
            view_formats: &[],
        });
        let params: Vec<ShadowViewParams> = views.iter().map(|v| ShadowViewParams::new(v, bounds)).collect();
        let view_buffers: Vec<wgpu::Buffer> = params
            .iter()
            .map(|p| {
                device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                    label: Some("shadow view"),
                    contents: bytemuck::bytes_of(p),
                    usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
                })
            })
            .collect();
        let view_bind_groups = view_buffers
            .iter()
            .map(|buffer| {
                device.create_bind_group(&wgpu::BindGroupDescriptor {
                    label: Some("shadow view"),
                    layout: &self.layout,
                    entries: &[wgpu::BindGroupEntry { binding: 0, resource: buffer.as_entire_binding() }],
                })
            })
            .collect();
        let zero = [ShadowViewParams::zeroed()];
        let views_buffer = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("shadow views"),
            contents: bytemuck::cast_slice(if params.is_empty() { &zero[..] } else { &params }),
            // COPY_SRC: the specular pass copies the views into its tables.
            usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::COPY_SRC,
        });
        let occluders = lights.occluders.clone();
        let mesh_vertices = (!occluders.vertices.is_empty()).then(|| {
            device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some("mesh light occluders"),
                contents: bytemuck::cast_slice(&occluders.vertices),
                usage: wgpu::BufferUsages::VERTEX | wgpu::BufferUsages::COPY_DST,
            })
        });
        ShadowMaps {
            size,
            layers,
            texture,
            depth,
            view_bind_groups,
            view_buffers,
            views_buffer,
            view_lights: views.iter().map(|v| v.light).collect(),
            mesh_vertices,
            occluders,
        }
    }

    /// Renders every shadow view of `maps`; `scene_group` is `bind_scene`'s.
    pub fn record(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        scene: &SceneBuffers,
        scene_group: &wgpu::BindGroup,
        maps: &ShadowMaps,
    ) {
        let depth_view = maps.depth.create_view(&Default::default());
        for (layer, bind_group) in maps.view_bind_groups.iter().enumerate() {
            let target = maps.texture.create_view(&wgpu::TextureViewDescriptor {
                dimension: Some(wgpu::TextureViewDimension::D2),
                base_array_layer: layer as u32,
                array_layer_count: Some(1),
                ..Default::default()
            });
            let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("shadow view"),
                color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                    view: &target,
                    depth_slice: None,
                    resolve_target: None,
                    // Texels that see nothing hold the whole range: lit.
                    ops: wgpu::Operations {
                        load: wgpu::LoadOp::Clear(wgpu::Color { r: 1.0, g: 0.0, b: 0.0, a: 0.0 }),
                        store: wgpu::StoreOp::Store,
                    },
                })],
                depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                    view: &depth_view,
                    depth_ops: Some(wgpu::Operations { load: wgpu::LoadOp::Clear(1.0), store: wgpu::StoreOp::Discard }),
                    stencil_ops: None,
                }),
                timestamp_writes: None,
                occlusion_query_set: None,
                multiview_mask: None,
            });
            pass.set_pipeline(&self.pipeline);
            pass.set_bind_group(0, bind_group, &[]);
            pass.set_bind_group(1, scene_group, &[]);
            pass.set_vertex_buffer(0, scene.vertices.slice(..));
            pass.draw(0..scene.occluder_count, 0..1);
            // Emissive meshes are scene surfaces: they shadow every light but themselves.
            if let Some(mesh_vertices) = &maps.mesh_vertices {
                pass.set_vertex_buffer(0, mesh_vertices.slice(..));
                for range in maps.occluders.drawn_by(maps.view_lights[layer]) {
                    pass.draw(range, 0..1);
                }
            }
        }
    }
}

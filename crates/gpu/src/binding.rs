//! Bind-group layout entries, pipeline layouts, compute pipelines and the
//! one-target render pass, written once for every pass.

pub fn entry(binding: u32, visibility: wgpu::ShaderStages, ty: wgpu::BindingType) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry { binding, visibility, ty, count: None }
}

pub fn uniform() -> wgpu::BindingType {
    wgpu::BindingType::Buffer {
        ty: wgpu::BufferBindingType::Uniform,
        has_dynamic_offset: false,
        min_binding_size: None,
    }
}

/// A uniform bound at a dynamic offset, `size` bytes at a time.
pub fn dynamic_uniform(size: u64) -> wgpu::BindingType {
    wgpu::BindingType::Buffer {
        ty: wgpu::BufferBindingType::Uniform,
        has_dynamic_offset: true,
        min_binding_size: std::num::NonZeroU64::new(size),
    }
}

pub fn storage(read_only: bool) -> wgpu::BindingType {
    wgpu::BindingType::Buffer {
        ty: wgpu::BufferBindingType::Storage { read_only },
        has_dynamic_offset: false,
        min_binding_size: None,
    }
}

/// A float texture read with `textureLoad` (unfilterable, so Rgba32Float works).
pub fn texture(view_dimension: wgpu::TextureViewDimension) -> wgpu::BindingType {
    wgpu::BindingType::Texture {
        sample_type: wgpu::TextureSampleType::Float { filterable: false },
        view_dimension,
        multisampled: false,
    }
}

/// A 2D unsigned-integer texture read with `textureLoad` (the G-buffer's
/// layer texels).
pub fn texture_uint() -> wgpu::BindingType {
    wgpu::BindingType::Texture {
        sample_type: wgpu::TextureSampleType::Uint,
        view_dimension: wgpu::TextureViewDimension::D2,
        multisampled: false,
    }
}

/// A write-only `Rgba32Float` storage texture.
pub fn storage_texture_rgba32f() -> wgpu::BindingType {
    wgpu::BindingType::StorageTexture {
        access: wgpu::StorageTextureAccess::WriteOnly,
        format: wgpu::TextureFormat::Rgba32Float,
        view_dimension: wgpu::TextureViewDimension::D2,
    }
}

/// Layers to allocate for a 2D array of `layers` layers of `width × height`.
/// wgpu's OpenGL backend makes every square texture whose layers are a
/// multiple of 6 a cube map (its heuristic, wgpu issues #1574 and #1614),
/// and then renders nothing into its layers as 2D views (measured: the shadow
/// maps of a point light stayed zero), and a texture of one layer a plain 2D
/// texture, which reads as zeros through an array view (measured: a sun's
/// one shadow view shadowed everything); one spare layer keeps either an array.
pub fn array_layers(width: u32, height: u32, layers: u32) -> u32 {
    let layers = layers.max(1);
    if layers == 1 || (width == height && layers % 6 == 0) { layers + 1 } else { layers }
}

/// The layout of a pipeline with one bind group (every pass has one).
pub fn pipeline_layout(device: &wgpu::Device, label: &str, layout: &wgpu::BindGroupLayout) -> wgpu::PipelineLayout {
    device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
        label: Some(label),
        bind_group_layouts: &[Some(layout)],
        immediate_size: 0,
    })
}

/// A pipeline drawing `vs_fullscreen` (fullscreen.wgsl) and `fs_main` of
/// `module` into one target of `format`, no blending: 3 vertices shade
/// every pixel.
pub fn fullscreen_pipeline(
    device: &wgpu::Device,
    label: &str,
    layout: &wgpu::PipelineLayout,
    module: &wgpu::ShaderModule,
    format: wgpu::TextureFormat,
) -> wgpu::RenderPipeline {
    fullscreen_pipeline_with(device, label, layout, module, format, &[])
}

/// `fullscreen_pipeline` with values for `fs_main`'s pipeline-overridable
/// constants.
pub fn fullscreen_pipeline_with(
    device: &wgpu::Device,
    label: &str,
    layout: &wgpu::PipelineLayout,
    module: &wgpu::ShaderModule,
    format: wgpu::TextureFormat,
    constants: &[(&str, f64)],
) -> wgpu::RenderPipeline {
    device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
        label: Some(label),
        layout: Some(layout),
        vertex: wgpu::VertexState {
            module,
            entry_point: Some("vs_fullscreen"),
            compilation_options: Default::default(),
            buffers: &[],
        },
        primitive: Default::default(),
        depth_stencil: None,
        multisample: Default::default(),
        fragment: Some(wgpu::FragmentState {
            module,
            entry_point: Some("fs_main"),
            compilation_options: wgpu::PipelineCompilationOptions { constants, ..Default::default() },
            targets: &[Some(wgpu::ColorTargetState { format, blend: None, write_mask: wgpu::ColorWrites::ALL })],
        }),
        multiview_mask: None,
        cache: None,
    })
}

/// A compute pipeline running `entry_point` of `module`.
pub fn compute_pipeline(
    device: &wgpu::Device,
    label: &str,
    layout: &wgpu::PipelineLayout,
    module: &wgpu::ShaderModule,
    entry_point: &str,
) -> wgpu::ComputePipeline {
    compute_pipeline_with(device, label, layout, module, entry_point, &[])
}

/// A compute pipeline running `entry_point` of `module` whose workgroups are
/// `side × side` invocations: the WGSL declares `override WORKGROUP: u32`
/// and `@workgroup_size(WORKGROUP, WORKGROUP)`, and the Rust side
/// dispatches with the same `side`, so the size is written once.
pub fn square_compute_pipeline(
    device: &wgpu::Device,
    label: &str,
    layout: &wgpu::PipelineLayout,
    module: &wgpu::ShaderModule,
    entry_point: &str,
    side: u32,
) -> wgpu::ComputePipeline {
    compute_pipeline_with(device, label, layout, module, entry_point, &[("WORKGROUP", side as f64)])
}

/// A compute pipeline with values for the shader's pipeline-overridable
/// constants.
pub fn compute_pipeline_with(
    device: &wgpu::Device,
    label: &str,
    layout: &wgpu::PipelineLayout,
    module: &wgpu::ShaderModule,
    entry_point: &str,
    constants: &[(&str, f64)],
) -> wgpu::ComputePipeline {
    device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
        label: Some(label),
        layout: Some(layout),
        module,
        entry_point: Some(entry_point),
        compilation_options: wgpu::PipelineCompilationOptions { constants, ..Default::default() },
        cache: None,
    })
}

/// An `Rgba32Float` image a compute pass writes and later passes read or copy.
pub fn storage_output_texture(device: &wgpu::Device, label: &str, width: u32, height: u32) -> wgpu::Texture {
    device.create_texture(&wgpu::TextureDescriptor {
        label: Some(label),
        size: wgpu::Extent3d { width, height, depth_or_array_layers: 1 },
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format: wgpu::TextureFormat::Rgba32Float,
        usage: wgpu::TextureUsages::STORAGE_BINDING
            | wgpu::TextureUsages::COPY_SRC
            | wgpu::TextureUsages::TEXTURE_BINDING,
        view_formats: &[],
    })
}

/// Depth test keeping the nearest surface (G-buffer and shadow maps).
pub fn nearest_depth(format: wgpu::TextureFormat) -> wgpu::DepthStencilState {
    wgpu::DepthStencilState {
        format,
        depth_write_enabled: Some(true),
        depth_compare: Some(wgpu::CompareFunction::Less),
        stencil: Default::default(),
        bias: Default::default(),
    }
}

/// A render pass into one colour target, cleared to zero or (with `clear`
/// false) loaded so passes can accumulate.
pub fn color_pass<'a>(
    encoder: &'a mut wgpu::CommandEncoder,
    label: &str,
    target: &wgpu::TextureView,
    clear: bool,
) -> wgpu::RenderPass<'a> {
    let load = if clear { wgpu::LoadOp::Clear(wgpu::Color::TRANSPARENT) } else { wgpu::LoadOp::Load };
    encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
        label: Some(label),
        color_attachments: &[Some(wgpu::RenderPassColorAttachment {
            view: target,
            depth_slice: None,
            resolve_target: None,
            ops: wgpu::Operations { load, store: wgpu::StoreOp::Store },
        })],
        depth_stencil_attachment: None,
        timestamp_writes: None,
        occlusion_query_set: None,
        multiview_mask: None,
    })
}

#[cfg(test)]
mod tests {
    #[test]
    fn array_textures_are_never_cube_compatible_nor_single() {
        assert_eq!(super::array_layers(64, 64, 6), 7);
        assert_eq!(super::array_layers(64, 64, 12), 13);
        assert_eq!(super::array_layers(64, 32, 6), 6);
        assert_eq!(super::array_layers(64, 64, 8), 8);
        assert_eq!(super::array_layers(64, 64, 0), 2);
        assert_eq!(super::array_layers(64, 32, 1), 2);
    }
}

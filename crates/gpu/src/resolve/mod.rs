//! The resolve pass: sums the frame's radiance targets into one linear
//! `Rgba32Float` image (the only texture read back for output).

pub fn shader_source() -> String {
    use crate::wgsl::{Module, UNCOUNTED_LOOPS, compose};
    static RESOLVE: Module = Module { name: "resolve.wgsl", source: include_str!("resolve.wgsl"), requires: &[] };
    compose(&[
        &UNCOUNTED_LOOPS,
        &crate::media::MEDIA,
        &crate::media::REGION_ARRAY,
        &crate::media::VIEW_DEPTH,
        &crate::textures::ENVIRONMENT,
        &RESOLVE,
    ])
}
/// Workgroup side (the `WORKGROUP` override of the shader).
const WORKGROUP: u32 = 8;

/// Which radiance terms the frame holds. Mirrors `Terms` in resolve.wgsl.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct Terms {
    pub direct: f32,
    pub indirect: f32,
    pub caustic: f32,
    pub specular: f32,
    pub volume: f32,
    pub _pad: [f32; 3],
}

impl Terms {
    /// Every term: the whole image.
    pub const ALL: Terms =
        Terms { direct: 1.0, indirect: 1.0, caustic: 1.0, specular: 1.0, volume: 1.0, _pad: [0.0; 3] };
}

impl Default for Terms {
    fn default() -> Self {
        Terms::ALL
    }
}

pub struct ResolvePass {
    pipeline: wgpu::ComputePipeline,
    bind_group: wgpu::BindGroup,
    terms: wgpu::Buffer,
    /// The sky's radiance (rgb), seen where a pixel sees no surface.
    sky: wgpu::Buffer,
    pub output: wgpu::Texture,
}

impl ResolvePass {
    /// `inputs`: emission, direct, indirect, caustic, specular (same size);
    /// `volume`: the volume splat's target; `sky`: the radiance of pixels
    /// that see no surface, times `environment`'s image where there is one
    /// (`SceneBuffers::environment`; a moved scene keeps its sky).
    #[allow(clippy::too_many_arguments)]
    pub fn new(
        device: &wgpu::Device,
        inputs: [&wgpu::Texture; 5],
        volume: &wgpu::Texture,
        gbuffer: &crate::gbuffer::GBuffer,
        media: &crate::media::GpuMedia,
        sky: glam::Vec3,
        environment: &wgpu::Buffer,
        features: crate::features::SceneFeatures,
    ) -> Self {
        let (width, height) = (inputs[0].width(), inputs[0].height());
        use crate::binding::{entry, storage, storage_texture_rgba32f, texture, uniform};
        let source = shader_source();
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("resolve.wgsl"),
            source: wgpu::ShaderSource::Wgsl(source.as_str().into()),
        });
        let stage = wgpu::ShaderStages::COMPUTE;
        let mut entries: Vec<wgpu::BindGroupLayoutEntry> =
            (0..5).map(|b| entry(b, stage, texture(wgpu::TextureViewDimension::D2))).collect();
        entries.push(entry(5, stage, storage_texture_rgba32f()));
        entries.push(entry(6, stage, texture(wgpu::TextureViewDimension::D2)));
        entries.push(entry(7, stage, texture(wgpu::TextureViewDimension::D2)));
        entries.push(entry(8, stage, uniform()));
        entries.push(entry(9, stage, storage(true)));
        entries.push(entry(10, stage, texture(wgpu::TextureViewDimension::D2Array)));
        entries.push(entry(11, stage, uniform()));
        entries.push(entry(12, stage, uniform()));
        entries.push(entry(13, stage, storage(true)));
        let layout = device
            .create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor { label: Some("resolve"), entries: &entries });
        let pipeline_layout = crate::binding::pipeline_layout(device, "resolve", &layout);
        let mut constants = features.constants(&source);
        constants.push(("WORKGROUP", WORKGROUP as f64));
        let pipeline =
            crate::binding::compute_pipeline_with(device, "resolve", &pipeline_layout, &module, "main", &constants);
        let output = crate::binding::storage_output_texture(device, "resolved radiance", width, height);
        let mut views: Vec<wgpu::TextureView> = inputs.iter().map(|t| t.create_view(&Default::default())).collect();
        views.push(output.create_view(&Default::default()));
        views.push(volume.create_view(&Default::default()));
        views.push(gbuffer.position.create_view(&Default::default()));
        let slices = media.slices.create_view(&wgpu::TextureViewDescriptor {
            dimension: Some(wgpu::TextureViewDimension::D2Array),
            ..Default::default()
        });
        let mut bind_entries: Vec<wgpu::BindGroupEntry> = views
            .iter()
            .enumerate()
            .map(|(i, v)| wgpu::BindGroupEntry { binding: i as u32, resource: wgpu::BindingResource::TextureView(v) })
            .collect();
        bind_entries.push(wgpu::BindGroupEntry { binding: 8, resource: media.params_buffer.as_entire_binding() });
        bind_entries.push(wgpu::BindGroupEntry { binding: 9, resource: media.regions.as_entire_binding() });
        bind_entries.push(wgpu::BindGroupEntry { binding: 10, resource: wgpu::BindingResource::TextureView(&slices) });
        let terms = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("resolve terms"),
            size: std::mem::size_of::<Terms>() as u64,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        bind_entries.push(wgpu::BindGroupEntry { binding: 11, resource: terms.as_entire_binding() });
        use wgpu::util::DeviceExt;
        let sky = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("resolve sky"),
            contents: bytemuck::bytes_of(&sky.extend(0.0).to_array()),
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
        });
        bind_entries.push(wgpu::BindGroupEntry { binding: 12, resource: sky.as_entire_binding() });
        bind_entries.push(wgpu::BindGroupEntry { binding: 13, resource: environment.as_entire_binding() });
        let bind_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("resolve"),
            layout: &layout,
            entries: &bind_entries,
        });
        ResolvePass { pipeline, bind_group, terms, sky, output }
    }

    /// Shows `sky` where pixels see no surface from the next frame on (an
    /// edited sky).
    pub fn set_sky(&self, queue: &wgpu::Queue, sky: glam::Vec3) {
        queue.write_buffer(&self.sky, 0, bytemuck::bytes_of(&sky.extend(0.0).to_array()));
    }

    /// Sums the terms `terms` selects (written now) into `output`.
    pub fn record(&self, queue: &wgpu::Queue, encoder: &mut wgpu::CommandEncoder, terms: &Terms) {
        queue.write_buffer(&self.terms, 0, bytemuck::bytes_of(terms));
        let mut pass =
            encoder.begin_compute_pass(&wgpu::ComputePassDescriptor { label: Some("resolve"), timestamp_writes: None });
        pass.set_pipeline(&self.pipeline);
        pass.set_bind_group(0, &self.bind_group, &[]);
        pass.dispatch_workgroups(self.output.width().div_ceil(WORKGROUP), self.output.height().div_ceil(WORKGROUP), 1);
    }
}

//! The running mean of frames from independent photon sets: what the
//! viewer shows while the camera stands still, so the noise of the photon
//! maps falls as it looks (`count` frames: variance / count), and the
//! progressive GPU render's mean. The odd frames' mean is kept apart too:
//! the two interleaved half-images from which the mean's remaining noise
//! is estimated (`hikari_core::progressive::noise_from_sums`).

use bytemuck::{Pod, Zeroable};

/// Workgroup side (the `WORKGROUP` override of the shader).
const WORKGROUP: u32 = 8;
pub const SHADER: &str = include_str!("accumulate.wgsl");

/// Mirrors `AccumulateParams` in accumulate.wgsl.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct AccumulateParams {
    pub width: u32,
    pub height: u32,
    pub count: u32,
    pub _pad: u32,
}

pub struct AccumulatePass {
    pipeline: wgpu::ComputePipeline,
    bind_group: wgpu::BindGroup,
    params: wgpu::Buffer,
    width: u32,
    height: u32,
    /// Frames in the mean.
    count: u32,
    /// The mean so far (`Rgba32Float`).
    pub mean: wgpu::Texture,
    /// The mean of the odd frames (1st, 3rd, …) alone.
    pub odd_mean: wgpu::Texture,
}

impl AccumulatePass {
    /// Averages the frames `frame` will hold (an `Rgba32Float` texture,
    /// e.g. `GpuRenderer::resolved`).
    pub fn new(device: &wgpu::Device, frame: &wgpu::Texture) -> Self {
        let (width, height) = (frame.width(), frame.height());
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("accumulate.wgsl"),
            source: wgpu::ShaderSource::Wgsl(SHADER.into()),
        });
        use crate::binding::{entry, storage, storage_texture_rgba32f, texture, uniform};
        let stage = wgpu::ShaderStages::COMPUTE;
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("accumulate"),
            entries: &[
                entry(0, stage, uniform()),
                entry(1, stage, texture(wgpu::TextureViewDimension::D2)),
                entry(2, stage, storage(false)),
                entry(3, stage, storage_texture_rgba32f()),
                entry(4, stage, storage_texture_rgba32f()),
            ],
        });
        let pipeline_layout = crate::binding::pipeline_layout(device, "accumulate", &layout);
        let pipeline =
            crate::binding::square_compute_pipeline(device, "accumulate", &pipeline_layout, &module, "main", WORKGROUP);
        let params = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("accumulate params"),
            size: std::mem::size_of::<AccumulateParams>() as u64,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let sum = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("accumulated sums"),
            // All frames' sum, then the odd frames'.
            size: 2 * width as u64 * height as u64 * 16,
            usage: wgpu::BufferUsages::STORAGE,
            mapped_at_creation: false,
        });
        let mean = crate::binding::storage_output_texture(device, "accumulated mean", width, height);
        let frame_view = frame.create_view(&Default::default());
        let mean_view = mean.create_view(&Default::default());
        let odd_mean = crate::binding::storage_output_texture(device, "accumulated odd mean", width, height);
        let odd_mean_view = odd_mean.create_view(&Default::default());
        let bind_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("accumulate"),
            layout: &layout,
            entries: &[
                wgpu::BindGroupEntry { binding: 0, resource: params.as_entire_binding() },
                wgpu::BindGroupEntry { binding: 1, resource: wgpu::BindingResource::TextureView(&frame_view) },
                wgpu::BindGroupEntry { binding: 2, resource: sum.as_entire_binding() },
                wgpu::BindGroupEntry { binding: 3, resource: wgpu::BindingResource::TextureView(&mean_view) },
                wgpu::BindGroupEntry { binding: 4, resource: wgpu::BindingResource::TextureView(&odd_mean_view) },
            ],
        });
        AccumulatePass { pipeline, bind_group, params, width, height, count: 0, mean, odd_mean }
    }

    /// Frames in the mean.
    pub fn count(&self) -> u32 {
        self.count
    }

    /// Whether the noise estimate is worth reading back now: after frames
    /// 2, 3, 4, 6, 8, 12, 16, 24, … (2^k and 3·2^k), so a render that stops
    /// at a target error renders at most half again as many passes as it
    /// needed, and the readbacks (two images) cost a logarithm's worth.
    pub fn noise_due(&self) -> bool {
        let n = self.count;
        n >= 2 && (n.is_power_of_two() || (n.is_multiple_of(3) && (n / 3).is_power_of_two()))
    }

    /// The noise of the mean as its frames estimate it, relative to the
    /// mean (None before two frames): the means read back.
    pub fn read_noise(&self, ctx: &crate::GpuContext) -> Result<Option<f64>, crate::GpuError> {
        crate::block::wait_for(self.noise_reading().read_async(ctx))
    }

    /// What `read_noise` reads, taken now, to read back without holding
    /// the mean (the web page's frames await it while input goes on).
    pub fn noise_reading(&self) -> NoiseReading {
        NoiseReading { mean: self.mean.clone(), odd_mean: self.odd_mean.clone(), width: self.width, count: self.count }
    }

    /// Starts a new mean with the next frame (the camera or scene changed).
    pub fn reset(&mut self) {
        self.count = 0;
    }

    /// Adds the current frame to the mean.
    pub fn record(&mut self, queue: &wgpu::Queue, encoder: &mut wgpu::CommandEncoder) {
        self.count += 1;
        let params = AccumulateParams { width: self.width, height: self.height, count: self.count, _pad: 0 };
        queue.write_buffer(&self.params, 0, bytemuck::bytes_of(&params));
        let mut pass = encoder
            .begin_compute_pass(&wgpu::ComputePassDescriptor { label: Some("accumulate"), timestamp_writes: None });
        pass.set_pipeline(&self.pipeline);
        pass.set_bind_group(0, &self.bind_group, &[]);
        pass.dispatch_workgroups(self.width.div_ceil(WORKGROUP), self.height.div_ceil(WORKGROUP), 1);
    }
}

/// The mean's noise estimate to read back (`AccumulatePass::noise_reading`).
pub struct NoiseReading {
    mean: wgpu::Texture,
    odd_mean: wgpu::Texture,
    width: u32,
    count: u32,
}

impl NoiseReading {
    /// The estimate, read back without blocking; valid until the mean
    /// takes another frame.
    pub async fn read_async(self, ctx: &crate::GpuContext) -> Result<Option<f64>, crate::GpuError> {
        let mean = crate::readback::read_rgba_async(ctx, &self.mean).await?;
        let odd_mean = crate::readback::read_rgba_async(ctx, &self.odd_mean).await?;
        Ok(self.noise_from(&mean, &odd_mean))
    }

    /// The estimate from `mean` and `odd_mean` as read back.
    fn noise_from(&self, mean: &[glam::Vec4], odd_mean: &[glam::Vec4]) -> Option<f64> {
        let (n, odd) = (self.count as f64, self.count.div_ceil(2) as f64);
        let sums = |m: &[glam::Vec4], k: f64| -> Vec<[f64; 3]> {
            m.iter().map(|v| [v.x as f64 * k, v.y as f64 * k, v.z as f64 * k]).collect()
        };
        hikari_core::progressive::noise_from_sums(self.width as usize, self.count, &sums(mean, n), &sums(odd_mean, odd))
    }
}

//! The wgpu device: found once, shared by every pass.

use thiserror::Error;

#[derive(Debug, Error)]
pub enum GpuError {
    #[error("no GPU adapter found ({0})")]
    NoAdapter(String),
    #[error("the GPU adapter refused a device: {0}")]
    Device(String),
    #[error("GPU readback failed: {0}")]
    Readback(String),
}

pub struct GpuContext {
    pub device: wgpu::Device,
    pub queue: wgpu::Queue,
    pub adapter_info: wgpu::AdapterInfo,
    /// Format of the additive radiance targets: Rgba32Float where the adapter
    /// can blend it, else Rgba16Float (and `float32_blend` is false).
    pub radiance_format: wgpu::TextureFormat,
    pub float32_blend: bool,
    /// GPU timestamps can be written between passes (per-pass timings).
    pub timestamps: bool,
}

impl GpuContext {
    /// Finds an adapter (honouring `WGPU_BACKEND` and friends) and opens a device.
    pub fn new() -> Result<Self, GpuError> {
        let instance = wgpu::Instance::new(wgpu::InstanceDescriptor::new_without_display_handle_from_env());
        let adapter = pollster::block_on(instance.request_adapter(&wgpu::RequestAdapterOptions {
            power_preference: wgpu::PowerPreference::HighPerformance,
            compatible_surface: None,
            force_fallback_adapter: false,
            apply_limit_buckets: false,
        }))
        .map_err(|e| GpuError::NoAdapter(e.to_string()))?;
        let float32_blend = adapter.features().contains(wgpu::Features::FLOAT32_BLENDABLE);
        let mut required_features = wgpu::Features::empty();
        if float32_blend {
            required_features |= wgpu::Features::FLOAT32_BLENDABLE;
        }
        let timestamp_features = wgpu::Features::TIMESTAMP_QUERY | wgpu::Features::TIMESTAMP_QUERY_INSIDE_ENCODERS;
        let timestamps = adapter.features().contains(timestamp_features);
        if timestamps {
            required_features |= timestamp_features;
        }
        let (device, queue) = pollster::block_on(adapter.request_device(&wgpu::DeviceDescriptor {
            label: Some("hikari"),
            required_features,
            // The adapter's own limits: the G-buffer needs 64 bytes per sample of
            // colour attachments, above the portable default of 32.
            required_limits: adapter.limits(),
            ..Default::default()
        }))
        .map_err(|e| GpuError::Device(e.to_string()))?;
        Ok(GpuContext {
            device,
            queue,
            adapter_info: adapter.get_info(),
            radiance_format: if float32_blend {
                wgpu::TextureFormat::Rgba32Float
            } else {
                wgpu::TextureFormat::Rgba16Float
            },
            float32_blend,
            timestamps,
        })
    }

    /// One line naming the adapter, for logs and summaries.
    pub fn describe(&self) -> String {
        let i = &self.adapter_info;
        format!("{} ({:?}, {:?})", i.name, i.backend, i.device_type)
    }
}

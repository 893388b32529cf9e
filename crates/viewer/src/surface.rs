//! A window's (or a canvas's) surface: its configuration, its next frame,
//! and the texture a frame shows.

use hikari_gpu::accumulate::AccumulatePass;
use hikari_gpu::points::PointColors;
use hikari_gpu::present::PresentMode;
use hikari_gpu::{GpuError, GpuRenderer};

/// Frames of `width × height` in `format`, paced by the display (FIFO).
pub fn surface_config(format: wgpu::TextureFormat, width: u32, height: u32) -> wgpu::SurfaceConfiguration {
    wgpu::SurfaceConfiguration {
        usage: wgpu::TextureUsages::RENDER_ATTACHMENT,
        format,
        width,
        height,
        present_mode: wgpu::PresentMode::Fifo,
        desired_maximum_frame_latency: 2,
        alpha_mode: wgpu::CompositeAlphaMode::Auto,
        view_formats: vec![],
        color_space: wgpu::SurfaceColorSpace::Auto,
    }
}

/// The surface's next frame to draw into, or None when there is none now
/// (timed out, hidden, or just reconfigured after it went out of date).
pub fn next_frame(
    surface: &wgpu::Surface,
    device: &wgpu::Device,
    config: &wgpu::SurfaceConfiguration,
) -> Result<Option<wgpu::SurfaceTexture>, GpuError> {
    match surface.get_current_texture() {
        wgpu::CurrentSurfaceTexture::Success(t) | wgpu::CurrentSurfaceTexture::Suboptimal(t) => Ok(Some(t)),
        wgpu::CurrentSurfaceTexture::Timeout | wgpu::CurrentSurfaceTexture::Occluded => Ok(None),
        wgpu::CurrentSurfaceTexture::Outdated | wgpu::CurrentSurfaceTexture::Lost => {
            surface.configure(device, config);
            Ok(None)
        }
        wgpu::CurrentSurfaceTexture::Validation => Err(GpuError::Failed("the surface refused a frame".into())),
    }
}

/// What the panel's view `mode` shows: the mean, a G-buffer target, or the
/// photons drawn as points.
pub fn shown_texture<'a>(
    mode: PresentMode,
    renderer: &'a GpuRenderer,
    mean: &'a AccumulatePass,
) -> Result<&'a wgpu::Texture, GpuError> {
    Ok(match mode {
        PresentMode::Radiance => &mean.mean,
        PresentMode::Normals => &renderer.targets.gbuffer.normal,
        PresentMode::Albedo => &renderer.targets.gbuffer.albedo,
        PresentMode::Photons => renderer.draw_points(PointColors::Power)?,
        PresentMode::DetailLevels => renderer.draw_points(PointColors::DetailLevel)?,
    })
}

//! The window shows what files hold: present.wgsl's tone mapping against
//! `hikari_core::output::tone_map` on the same linear values.

use glam::Vec3;
use hikari_core::output::tone_map;
use hikari_core::render::Image;
use hikari_gpu::present::PresentPass;
use hikari_gpu::test_support::test_context;

#[test]
fn present_pass_tone_maps_as_png_output() {
    let ctx = test_context("present");
    let (width, height) = (64u32, 4u32);
    // Linear values from 0 to 4 (clamped above 1), a negative and a NaN.
    let mut image = Image::new(width, height);
    for (i, p) in image.pixels.iter_mut().enumerate() {
        let t = i as f32 / (width * height) as f32;
        *p = Vec3::new(4.0 * t * t, t, 0.25 * t);
    }
    image.pixels[1] = Vec3::new(-1.0, f32::NAN, f32::INFINITY);
    let texels: Vec<[f32; 4]> = image.pixels.iter().map(|p| p.extend(1.0).to_array()).collect();
    let device = &ctx.device;
    let frame = device.create_texture(&wgpu::TextureDescriptor {
        label: Some("frame"),
        size: wgpu::Extent3d { width, height, depth_or_array_layers: 1 },
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format: wgpu::TextureFormat::Rgba32Float,
        usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
        view_formats: &[],
    });
    ctx.queue.write_texture(
        frame.as_image_copy(),
        bytemuck::cast_slice(&texels),
        wgpu::TexelCopyBufferLayout { offset: 0, bytes_per_row: Some(width * 16), rows_per_image: Some(height) },
        frame.size(),
    );
    let target = device.create_texture(&wgpu::TextureDescriptor {
        label: Some("window stand-in"),
        size: frame.size(),
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format: wgpu::TextureFormat::Rgba8Unorm,
        usage: wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC,
        view_formats: &[],
    });
    let exposure = 0.5;
    let mut pass = PresentPass::new(device, wgpu::TextureFormat::Rgba8Unorm);
    let mut encoder = device.create_command_encoder(&Default::default());
    let mode = hikari_gpu::present::PresentMode::Radiance;
    pass.record(device, &ctx.queue, &mut encoder, &frame, &target.create_view(&Default::default()), exposure, mode);
    ctx.queue.submit([encoder.finish()]);
    let shown = hikari_gpu::readback::read_rgba8(&ctx, &target).unwrap();
    let want = tone_map(&image, exposure);
    let mut worst = 0;
    for (i, rgb) in want.chunks(3).enumerate() {
        for c in 0..3 {
            worst = worst.max(rgb[c].abs_diff(shown[4 * i + c]));
        }
    }
    assert_eq!(&shown[4..7], &[0, 0, 0], "negative, NaN and infinite values show black");
    // One step of 255 for float rounding at the byte boundary.
    assert!(worst <= 1, "present differs from tone_map by up to {worst}/255");
}

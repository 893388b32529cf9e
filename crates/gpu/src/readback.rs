//! Copying textures and buffers back to the CPU (image output, status
//! words, traced photons). Each read has an `_async` form, which waits
//! without blocking (a browser's only way), and a blocking one for native
//! callers, which runs the same future.

use crate::block::wait_for;
use crate::context::{GpuContext, GpuError};
use glam::Vec4;
use std::pin::Pin;
use std::sync::{Arc, Mutex};
use std::task::{Context, Poll, Waker};

/// Reads a 2D `Rgba32Float` or `Rgba16Float` texture as row-major RGBA,
/// row 0 at the top.
pub fn read_rgba(ctx: &GpuContext, texture: &wgpu::Texture) -> Result<Vec<Vec4>, GpuError> {
    wait_for(read_rgba_layer_async(ctx, texture, 0))
}

/// `read_rgba` without blocking.
pub async fn read_rgba_async(ctx: &GpuContext, texture: &wgpu::Texture) -> Result<Vec<Vec4>, GpuError> {
    read_rgba_layer_async(ctx, texture, 0).await
}

/// Every layer of a 2D-array texture, each as `read_rgba` reads one.
pub fn read_rgba_layers(ctx: &GpuContext, texture: &wgpu::Texture) -> Result<Vec<Vec<Vec4>>, GpuError> {
    (0..texture.depth_or_array_layers()).map(|layer| read_rgba_layer(ctx, texture, layer)).collect()
}

/// A 2D `Rgba32Uint` texture's words (the G-buffer's layer texels),
/// row-major, row 0 at the top.
pub fn read_rgba32uint(ctx: &GpuContext, texture: &wgpu::Texture) -> Result<Vec<[u32; 4]>, GpuError> {
    if texture.format() != wgpu::TextureFormat::Rgba32Uint {
        return Err(GpuError::Readback(format!("not Rgba32Uint: {:?}", texture.format())));
    }
    let bytes = wait_for(read_rows(ctx, texture, 0, 16))?;
    Ok(bytemuck::cast_slice::<u8, [u32; 4]>(&bytes).to_vec())
}

/// A 2D `Rgba8Unorm` (or `Rgba8UnormSrgb`) texture's bytes, row-major,
/// row 0 at the top.
pub fn read_rgba8(ctx: &GpuContext, texture: &wgpu::Texture) -> Result<Vec<u8>, GpuError> {
    wait_for(read_rgba8_async(ctx, texture))
}

/// `read_rgba8` without blocking.
pub async fn read_rgba8_async(ctx: &GpuContext, texture: &wgpu::Texture) -> Result<Vec<u8>, GpuError> {
    use wgpu::TextureFormat::{Rgba8Unorm, Rgba8UnormSrgb};
    if !matches!(texture.format(), Rgba8Unorm | Rgba8UnormSrgb) {
        return Err(GpuError::Readback(format!("not Rgba8Unorm: {:?}", texture.format())));
    }
    read_rows(ctx, texture, 0, 4).await
}

/// One layer of a 2D (array) texture.
pub fn read_rgba_layer(ctx: &GpuContext, texture: &wgpu::Texture, layer: u32) -> Result<Vec<Vec4>, GpuError> {
    wait_for(read_rgba_layer_async(ctx, texture, layer))
}

async fn read_rgba_layer_async(ctx: &GpuContext, texture: &wgpu::Texture, layer: u32) -> Result<Vec<Vec4>, GpuError> {
    let texel_bytes = match texture.format() {
        wgpu::TextureFormat::Rgba32Float => 16,
        wgpu::TextureFormat::Rgba16Float => 8,
        other => return Err(GpuError::Readback(format!("cannot read back {other:?}"))),
    };
    let bytes = read_rows(ctx, texture, layer, texel_bytes).await?;
    if texel_bytes == 16 {
        Ok(bytemuck::cast_slice::<u8, [f32; 4]>(&bytes).iter().map(|&v| Vec4::from(v)).collect())
    } else {
        Ok(bytemuck::cast_slice::<u8, [u16; 4]>(&bytes).iter().map(|v| Vec4::from(v.map(f16_to_f32))).collect())
    }
}

/// The texels of one layer, rows unpadded, `texel_bytes` each.
async fn read_rows(
    ctx: &GpuContext,
    texture: &wgpu::Texture,
    layer: u32,
    texel_bytes: u32,
) -> Result<Vec<u8>, GpuError> {
    let (width, height) = (texture.width(), texture.height());
    let unpadded = width * texel_bytes;
    let padded = unpadded.div_ceil(wgpu::COPY_BYTES_PER_ROW_ALIGNMENT) * wgpu::COPY_BYTES_PER_ROW_ALIGNMENT;
    let buffer = ctx.device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("readback"),
        size: (padded * height) as u64,
        usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ,
        mapped_at_creation: false,
    });
    let mut encoder = ctx.device.create_command_encoder(&Default::default());
    encoder.copy_texture_to_buffer(
        wgpu::TexelCopyTextureInfo {
            texture,
            mip_level: 0,
            origin: wgpu::Origin3d { x: 0, y: 0, z: layer },
            aspect: wgpu::TextureAspect::All,
        },
        wgpu::TexelCopyBufferInfo {
            buffer: &buffer,
            layout: wgpu::TexelCopyBufferLayout {
                offset: 0,
                bytes_per_row: Some(padded),
                rows_per_image: Some(height),
            },
        },
        wgpu::Extent3d { width, height, depth_or_array_layers: 1 },
    );
    ctx.queue.submit([encoder.finish()]);
    let data = map_read(ctx, &buffer).await?;
    let mut out = Vec::with_capacity((unpadded * height) as usize);
    for row in 0..height {
        out.extend_from_slice(&data[(row * padded) as usize..(row * padded + unpadded) as usize]);
    }
    Ok(out)
}

/// Maps a MAP_READ buffer after the submitted work and copies its bytes out.
async fn map_read(ctx: &GpuContext, buffer: &wgpu::Buffer) -> Result<Vec<u8>, GpuError> {
    let error = |e: &dyn std::fmt::Display| GpuError::Readback(e.to_string());
    let slice = buffer.slice(..);
    let answer = Answer::default();
    let callback = answer.clone();
    slice.map_async(wgpu::MapMode::Read, move |r| callback.set(r));
    // Natively the callback runs inside the device's poll; in a browser
    // the map is a promise that resolves once the work is done.
    ctx.wait()?;
    // A map fails when the device is lost meanwhile (a browser gives no
    // reason with it): the loss, recorded by then, is the error to report.
    answer.await.map_err(|e| ctx.check().err().unwrap_or_else(|| error(&e)))?;
    ctx.check()?;
    let bytes = slice.get_mapped_range().map_err(|e| error(&e))?.to_vec();
    buffer.unmap();
    Ok(bytes)
}

/// Waits, without blocking in a browser, until the work submitted so far
/// is done (wall-clock timing of a pass where there are no timestamps).
pub async fn work_done_async(ctx: &GpuContext) -> Result<(), GpuError> {
    let answer = Answer::default();
    let callback = answer.clone();
    ctx.queue.on_submitted_work_done(move || callback.set(()));
    ctx.wait()?;
    answer.await;
    ctx.check()
}

/// A value that a callback sets once, awaited as a future.
struct Answer<T>(Arc<Mutex<(Option<T>, Option<Waker>)>>);

impl<T> Default for Answer<T> {
    fn default() -> Self {
        Answer(Arc::new(Mutex::new((None, None))))
    }
}

impl<T> Clone for Answer<T> {
    fn clone(&self) -> Self {
        Answer(self.0.clone())
    }
}

impl<T> Answer<T> {
    fn set(&self, value: T) {
        let mut slot = self.0.lock().unwrap_or_else(|e| e.into_inner());
        slot.0 = Some(value);
        if let Some(waker) = slot.1.take() {
            waker.wake();
        }
    }
}

impl<T> Future for Answer<T> {
    type Output = T;
    fn poll(self: Pin<&mut Self>, cx: &mut Context<'_>) -> Poll<T> {
        let mut slot = self.0.lock().unwrap_or_else(|e| e.into_inner());
        match slot.0.take() {
            Some(value) => Poll::Ready(value),
            None => {
                slot.1 = Some(cx.waker().clone());
                Poll::Pending
            }
        }
    }
}

/// Reads the first `count` u32 words of `buffer` (which needs COPY_SRC).
pub fn read_u32s(ctx: &GpuContext, buffer: &wgpu::Buffer, count: u64) -> Result<Vec<u32>, GpuError> {
    wait_for(read_u32s_async(ctx, buffer, count))
}

/// `read_u32s` without blocking.
pub async fn read_u32s_async(ctx: &GpuContext, buffer: &wgpu::Buffer, count: u64) -> Result<Vec<u32>, GpuError> {
    let staging = ctx.device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("readback words"),
        size: count * 4,
        usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ,
        mapped_at_creation: false,
    });
    let mut encoder = ctx.device.create_command_encoder(&Default::default());
    encoder.copy_buffer_to_buffer(buffer, 0, &staging, 0, count * 4);
    ctx.queue.submit([encoder.finish()]);
    Ok(bytemuck::pod_collect_to_vec(&map_read(ctx, &staging).await?))
}

/// IEEE half to single precision, exactly.
fn f16_to_f32(h: u16) -> f32 {
    let sign = ((h >> 15) as u32) << 31;
    let exp = ((h >> 10) & 0x1f) as u32;
    let mant = (h & 0x3ff) as u32;
    let bits = match exp {
        0 if mant == 0 => sign,
        0 => {
            return f32::from_bits(sign) + (mant as f32) * 2f32.powi(-24) * if sign != 0 { -1.0 } else { 1.0 };
        }
        31 => sign | 0x7f80_0000 | (mant << 13),
        _ => sign | ((exp + 112) << 23) | (mant << 13),
    };
    f32::from_bits(bits)
}

#[cfg(test)]
mod tests {
    #[test]
    fn half_floats_convert_exactly() {
        assert_eq!(super::f16_to_f32(0x3c00), 1.0);
        assert_eq!(super::f16_to_f32(0xc000), -2.0);
        assert_eq!(super::f16_to_f32(0x0001), 2f32.powi(-24));
        assert_eq!(super::f16_to_f32(0x7bff), 65504.0);
    }
}

//! The G-buffer's depth range per tile of `DEPTH_TILE`² pixels
//! (depth_tiles.wgsl), made after the G-buffer each frame: the surface
//! splat's vertex shader trims a photon's quad to the tiles whose depths
//! meet its sphere's (a wall seen at a grazing angle leaves most of the
//! quad of a photon on it outside), and drops photons no tile meets.

use bytemuck::{Pod, Zeroable};

/// Pixels per side of a tile.
pub const DEPTH_TILE: u32 = 16;

/// Most tiles per side a quad is trimmed over (larger quads, photons near
/// the eye, are drawn whole: the vertex shader reads this many squared).
pub const TRIM_TILES: u32 = 8;

/// `DEPTH_TILE` and `TRIM_TILES` for the WGSL that reads them (a test
/// holds the two to the Rust constants).
pub static TILE_CONSTANTS: crate::wgsl::Module = crate::wgsl::Module {
    name: "depth_tile_constants",
    source: "const DEPTH_TILE: u32 = 16u;\nconst TRIM_TILES: u32 = 8u;\n",
    requires: &[],
};

/// Mirrors `DepthTileParams` in depth_tiles.wgsl.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
struct DepthTileParams {
    clip_from_world: [[f32; 4]; 4],
}

/// The pass and its per-target state, kept between frames.
pub struct DepthTiles {
    pipeline: wgpu::ComputePipeline,
    bind_group: wgpu::BindGroup,
    uniforms: wgpu::Buffer,
    /// One texel per tile: x the nearest depth, y the farthest.
    pub tiles: wgpu::Texture,
}

impl DepthTiles {
    pub fn new(device: &wgpu::Device, gbuffer: &crate::gbuffer::GBuffer) -> Self {
        let source = crate::wgsl::compose(&[
            &TILE_CONSTANTS,
            &crate::wgsl::Module { name: "depth_tiles.wgsl", source: include_str!("depth_tiles.wgsl"), requires: &[] },
        ]);
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("depth_tiles.wgsl"),
            source: wgpu::ShaderSource::Wgsl(source.into()),
        });
        use crate::binding::{entry, storage_texture_rgba32f, texture, uniform};
        let compute = |b, ty| entry(b, wgpu::ShaderStages::COMPUTE, ty);
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("depth tiles"),
            entries: &[
                compute(0, uniform()),
                compute(1, texture(wgpu::TextureViewDimension::D2)),
                compute(2, storage_texture_rgba32f()),
            ],
        });
        let pipeline_layout = crate::binding::pipeline_layout(device, "depth tiles", &layout);
        let pipeline = crate::binding::compute_pipeline(device, "depth tiles", &pipeline_layout, &module, "main");
        let tiles = crate::binding::storage_output_texture(
            device,
            "depth tiles",
            gbuffer.width.div_ceil(DEPTH_TILE),
            gbuffer.height.div_ceil(DEPTH_TILE),
        );
        let uniforms = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("depth tile params"),
            size: std::mem::size_of::<DepthTileParams>() as u64,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let view = |t: &wgpu::Texture| t.create_view(&Default::default());
        let bind_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("depth tiles"),
            layout: &layout,
            entries: &[
                wgpu::BindGroupEntry { binding: 0, resource: uniforms.as_entire_binding() },
                wgpu::BindGroupEntry {
                    binding: 1,
                    resource: wgpu::BindingResource::TextureView(&view(&gbuffer.position)),
                },
                wgpu::BindGroupEntry { binding: 2, resource: wgpu::BindingResource::TextureView(&view(&tiles)) },
            ],
        });
        DepthTiles { pipeline, bind_group, uniforms, tiles }
    }

    /// Records the tiles' depth ranges of the G-buffer drawn with `clip_from_world`.
    pub fn record(&self, queue: &wgpu::Queue, encoder: &mut wgpu::CommandEncoder, clip_from_world: glam::Mat4) {
        let params = DepthTileParams { clip_from_world: clip_from_world.to_cols_array_2d() };
        queue.write_buffer(&self.uniforms, 0, bytemuck::bytes_of(&params));
        let mut pass = encoder
            .begin_compute_pass(&wgpu::ComputePassDescriptor { label: Some("depth tiles"), timestamp_writes: None });
        pass.set_pipeline(&self.pipeline);
        pass.set_bind_group(0, &self.bind_group, &[]);
        pass.dispatch_workgroups(self.tiles.width().div_ceil(8), self.tiles.height().div_ceil(8), 1);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_wgsl_constants_are_the_rust_ones() {
        let source = TILE_CONSTANTS.source;
        assert!(source.contains(&format!("const DEPTH_TILE: u32 = {DEPTH_TILE}u;")), "{source}");
        assert!(source.contains(&format!("const TRIM_TILES: u32 = {TRIM_TILES}u;")), "{source}");
    }
}

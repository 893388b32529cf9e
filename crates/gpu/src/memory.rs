//! What a frame will allocate, checked against the adapter's limits before
//! anything is created (and, in the CLI, before photons are traced), so a
//! scene or setting too large for the adapter is a one-line reason, never
//! an out-of-memory panic or a killed process.

use crate::context::{GpuContext, GpuError};

/// Bytes a stored photon takes in a map, and as an LOD survivor.
const PHOTON_BYTES: u64 = 20;
const SURVIVOR_BYTES: u64 = 24;

/// On a software adapter GPU memory is the process's own memory: beyond
/// this much the operating system, not wgpu, would stop the render.
pub const SOFTWARE_MEMORY_CAP: u64 = 6 << 30;

/// The sizes that decide a frame's memory.
#[derive(Clone, Copy, Debug)]
pub struct FrameSize {
    pub width: u32,
    pub height: u32,
    pub shadow_map_size: u32,
    pub shadow_layers: u32,
    /// Optical-depth slices (0 without region media).
    pub volume_slices: u32,
    /// Photons in the global, caustic and volume maps.
    pub photons: [u64; 3],
    /// The packed textures' buffer (`textures::packed_bytes`).
    pub texture_bytes: u64,
    /// The vertex buffer and the BVH's largest storage buffer
    /// (`scene_upload::scene_buffer_bytes`).
    pub vertex_bytes: u64,
    pub bvh_bytes: u64,
}

impl FrameSize {
    /// Bytes of textures and buffers a frame allocates, roughly (within
    /// a few per cent: small uniform and scene buffers are left out).
    pub fn bytes(&self) -> u64 {
        let pixels = self.width as u64 * self.height as u64;
        // G-buffer (4 × Rgba32Float + depth), 4 radiance targets, the
        // specular output and its accumulation, the resolve output.
        let targets = pixels * (4 * 16 + 4 + 4 * 16 + 3 * 16);
        let shadows = self.shadow_bytes();
        let slices = pixels * self.volume_slices as u64 * 16;
        // Each map: its photons, its LOD survivors, and (for the specular
        // pass) its hashed grid: the photons again plus two bucket starts each.
        let photons: u64 = self.photons.iter().map(|n| n * (2 * PHOTON_BYTES + SURVIVOR_BYTES + 8)).sum();
        // The BVH's nodes, primitives and shading records: about 2.5 times
        // the largest of them.
        let scene = self.texture_bytes + self.vertex_bytes + self.bvh_bytes * 5 / 2;
        targets + shadows + slices + photons + scene
    }

    /// Bytes of the shadow maps (one Depth32Float layer per view).
    pub fn shadow_bytes(&self) -> u64 {
        (self.shadow_map_size as u64).pow(2) * self.shadow_layers.max(1) as u64 * 4
    }

    /// Every limit of `ctx` this frame would pass, in one line; Ok if none.
    pub fn check(&self, ctx: &GpuContext) -> Result<(), GpuError> {
        let software = ctx.adapter_info.device_type == wgpu::DeviceType::Cpu;
        let over = self.over_limits(&ctx.limits, software);
        if over.is_empty() { Ok(()) } else { Err(GpuError::TooLarge(over.join("; "))) }
    }

    /// What this frame would pass of `limits` (and, on a `software`
    /// adapter, of the memory a process may take), one item each.
    pub fn over_limits(&self, limits: &wgpu::Limits, software: bool) -> Vec<String> {
        let mut over = Vec::new();
        let side = limits.max_texture_dimension_2d;
        if self.width > side || self.height > side {
            over.push(format!(
                "resolution {}x{} exceeds the adapter's {side} texels per side",
                self.width, self.height
            ));
        }
        if self.shadow_map_size > side {
            over.push(format!(
                "--shadow-map-size {} exceeds the adapter's {side} texels per side",
                self.shadow_map_size
            ));
        }
        let layers = limits.max_texture_array_layers;
        if self.shadow_layers > layers {
            over.push(format!("{} shadow views exceed the adapter's {layers} texture layers", self.shadow_layers));
        }
        if self.volume_slices > layers {
            over.push(format!("{} volume slices exceed the adapter's {layers} texture layers", self.volume_slices));
        }
        let binding = limits.max_storage_buffer_binding_size.min(limits.max_buffer_size);
        for (name, count) in ["global", "caustic", "volume"].iter().zip(self.photons) {
            if count * SURVIVOR_BYTES > binding {
                over.push(format!(
                    "{count} photons in the {name} map exceed the adapter's {} MiB per buffer (at most {})",
                    binding >> 20,
                    binding / SURVIVOR_BYTES
                ));
            }
        }
        let grid_bytes: u64 = self.photons.iter().map(|n| n * (PHOTON_BYTES + 8)).sum();
        if grid_bytes > binding {
            over.push(format!(
                "the photon grids of the specular pass ({} MiB) exceed the adapter's {} MiB per buffer",
                grid_bytes >> 20,
                binding >> 20
            ));
        }
        if self.vertex_bytes > limits.max_buffer_size {
            over.push(format!(
                "the scene's {} MiB of vertices exceed the adapter's {} MiB per buffer",
                self.vertex_bytes >> 20,
                limits.max_buffer_size >> 20
            ));
        }
        if self.bvh_bytes > binding {
            over.push(format!(
                "the scene's BVH ({} MiB of primitive records) exceeds the adapter's {} MiB per buffer",
                self.bvh_bytes >> 20,
                binding >> 20
            ));
        }
        if self.texture_bytes > binding {
            over.push(format!(
                "the scene's textures ({} MiB with their mip levels and coordinates, 4 bytes a texel) exceed the \
                 adapter's {} MiB per buffer",
                self.texture_bytes >> 20,
                binding >> 20
            ));
        }
        let total = self.bytes();
        if software && total > SOFTWARE_MEMORY_CAP {
            over.push(format!(
                "the frame needs about {} MiB ({} MiB of them shadow maps: {} views of {}²), more than the {} MiB \
                 allowed on a software adapter",
                total >> 20,
                self.shadow_bytes() >> 20,
                self.shadow_layers,
                self.shadow_map_size,
                SOFTWARE_MEMORY_CAP >> 20
            ));
        }
        over
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn frame() -> FrameSize {
        FrameSize {
            width: 512,
            height: 512,
            shadow_map_size: 1024,
            shadow_layers: 6,
            volume_slices: 0,
            photons: [200_000, 20_000, 0],
            texture_bytes: 16,
            vertex_bytes: 48 << 10,
            bvh_bytes: 64 << 10,
        }
    }

    #[test]
    fn bytes_grow_with_every_size() {
        let base = frame().bytes();
        assert!(FrameSize { width: 1024, ..frame() }.bytes() > base);
        assert!(FrameSize { shadow_layers: 12, ..frame() }.bytes() > base);
        assert!(FrameSize { volume_slices: 8, ..frame() }.bytes() > base);
        assert!(FrameSize { photons: [400_000, 20_000, 0], ..frame() }.bytes() > base);
        assert!(FrameSize { texture_bytes: 1 << 20, ..frame() }.bytes() > base);
        assert!(FrameSize { vertex_bytes: 1 << 20, ..frame() }.bytes() > base);
        assert!(FrameSize { bvh_bytes: 1 << 20, ..frame() }.bytes() > base);
        // 8192² shadow maps × 24 layers: 6 GiB of depth alone.
        assert!(FrameSize { shadow_map_size: 8192, shadow_layers: 24, ..frame() }.bytes() >= 6 << 30);
    }

    /// A scene larger than the adapter's buffers is refused with the
    /// buffer that does not fit, never created.
    #[test]
    fn scene_buffers_beyond_the_limits_are_named() {
        let limits = wgpu::Limits {
            max_storage_buffer_binding_size: 16 << 20,
            max_buffer_size: 16 << 20,
            max_texture_dimension_2d: 8192,
            max_texture_array_layers: 256,
            ..Default::default()
        };
        assert!(frame().over_limits(&limits, false).is_empty(), "{:?}", frame().over_limits(&limits, false));
        let big = FrameSize { vertex_bytes: 17 << 20, bvh_bytes: 17 << 20, texture_bytes: 17 << 20, ..frame() };
        let over = big.over_limits(&limits, false).join("; ");
        for what in ["vertices", "BVH", "textures"] {
            assert!(over.contains(what), "{what} missing from: {over}");
        }
    }
}

//! The LOD pass: culls photons by distance and scales the survivors' power
//! (hikari_core::lod, mirrored in lod.wgsl), compacting them in storage
//! order (count, scan, scatter) into the instances and count of an indirect
//! draw, so culled photons cost no rasterization and every run draws the
//! same instances in the same order.

use crate::photons::{LodPhoton, PhotonBuffer};
use bytemuck::{Pod, Zeroable};
use hikari_core::lod::LodSettings;
use wgpu::util::DeviceExt;

/// The LOD pass's output record (`photons::LodPhoton`).
pub static LOD_PHOTON: crate::wgsl::Module =
    crate::wgsl::Module { name: "lod_photon.wgsl", source: include_str!("lod_photon.wgsl"), requires: &[] };

pub fn shader_source() -> String {
    use crate::wgsl::{Module, PREFIX_SUM, compose};
    static LOD: Module =
        Module { name: "lod.wgsl", source: include_str!("lod.wgsl"), requires: &[&PREFIX_SUM, &LOD_PHOTON] };
    compose(&[&LOD])
}

/// Matches `SCAN_WORKGROUP` in prefix_sum.wgsl.
const WORKGROUP: u32 = crate::wgsl::SCAN_WORKGROUP;

/// Mirrors `LodParams` in lod.wgsl.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct LodParams {
    pub eye: [f32; 3],
    pub near: f32,
    pub far: f32,
    pub groups: u32,
    pub count: u32,
    pub enabled: u32,
    pub workgroups: u32,
    pub _pad0: u32,
    pub _pad1: u32,
    pub _pad2: u32,
}

/// The instances and indirect arguments of one photon map's splat.
pub struct LodOutput {
    pub survivors: wgpu::Buffer,
    /// `wgpu::util::DrawIndirectArgs`: 4 vertices, surviving instances.
    pub draw_args: wgpu::Buffer,
    bind_group: wgpu::BindGroup,
    params: wgpu::Buffer,
    count: u32,
}

pub struct LodPass {
    count: wgpu::ComputePipeline,
    scan: wgpu::ComputePipeline,
    scatter: wgpu::ComputePipeline,
    layout: wgpu::BindGroupLayout,
}

/// Workgroups per dispatch dimension that every adapter offers.
pub const MAX_WORKGROUPS_PER_DIMENSION: u32 = 65_535;

/// `workgroups` laid out as x × y with x ≤ 65,535 (the shader skips the
/// surplus of the last row).
pub fn dispatch_grid(workgroups: u32) -> (u32, u32) {
    let rows = workgroups.div_ceil(MAX_WORKGROUPS_PER_DIMENSION).max(1);
    (workgroups.div_ceil(rows), rows)
}

impl LodOutput {
    /// Photons the map holds (survivors are at most this many).
    pub fn capacity(&self) -> u32 {
        self.count
    }
}

impl LodPass {
    pub fn new(device: &wgpu::Device) -> Self {
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("lod.wgsl"),
            source: wgpu::ShaderSource::Wgsl(shader_source().into()),
        });
        use crate::binding::{storage, uniform};
        let entry = |b, ty| crate::binding::entry(b, wgpu::ShaderStages::COMPUTE, ty);
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("lod"),
            entries: &[
                entry(0, uniform()),
                entry(1, storage(true)),
                entry(2, storage(false)),
                entry(3, storage(false)),
                entry(4, storage(false)),
            ],
        });
        let pipeline_layout = crate::binding::pipeline_layout(device, "lod", &layout);
        let pipeline = |entry_point: &str| {
            crate::binding::compute_pipeline(device, entry_point, &pipeline_layout, &module, entry_point)
        };
        LodPass { count: pipeline("count"), scan: pipeline("scan"), scatter: pipeline("scatter"), layout }
    }

    /// Buffers for culling `photons`; capacity for all of them.
    pub fn create_output(&self, device: &wgpu::Device, photons: &PhotonBuffer) -> LodOutput {
        let capacity = photons.count.max(1) as u64 * std::mem::size_of::<LodPhoton>() as u64;
        let survivors = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("lod survivors"),
            size: capacity,
            usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::VERTEX | wgpu::BufferUsages::COPY_SRC,
            mapped_at_creation: false,
        });
        let draw_args = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("splat draw args"),
            contents: bytemuck::cast_slice(&[4u32, 0, 0, 0]),
            usage: wgpu::BufferUsages::STORAGE
                | wgpu::BufferUsages::INDIRECT
                | wgpu::BufferUsages::COPY_DST
                | wgpu::BufferUsages::COPY_SRC,
        });
        let params = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("lod params"),
            size: std::mem::size_of::<LodParams>() as u64,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let group_sums = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("lod group sums"),
            size: photons.count.div_ceil(WORKGROUP).max(1) as u64 * 4,
            usage: wgpu::BufferUsages::STORAGE,
            mapped_at_creation: false,
        });
        let bind_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("lod"),
            layout: &self.layout,
            entries: &[
                wgpu::BindGroupEntry { binding: 0, resource: params.as_entire_binding() },
                wgpu::BindGroupEntry { binding: 1, resource: photons.buffer.as_entire_binding() },
                wgpu::BindGroupEntry { binding: 2, resource: survivors.as_entire_binding() },
                wgpu::BindGroupEntry { binding: 3, resource: draw_args.as_entire_binding() },
                wgpu::BindGroupEntry { binding: 4, resource: group_sums.as_entire_binding() },
            ],
        });
        LodOutput { survivors, draw_args, bind_group, params, count: photons.count }
    }

    /// Resets the count and records the cull for the eye at `eye`.
    pub fn record(
        &self,
        queue: &wgpu::Queue,
        encoder: &mut wgpu::CommandEncoder,
        output: &LodOutput,
        eye: glam::Vec3,
        settings: Option<&LodSettings>,
    ) {
        // group_of's u32 arithmetic needs count · groups < 2^32.
        let max_groups = (u32::MAX / output.count.max(1)).max(1);
        let (near, far, groups) = settings.map_or((0.0, 0.0, 1), |s| (s.near, s.far, s.groups.clamp(1, max_groups)));
        let workgroups = output.count.div_ceil(WORKGROUP);
        let params = LodParams {
            eye: eye.to_array(),
            near,
            far,
            groups,
            count: output.count,
            enabled: settings.is_some() as u32,
            workgroups,
            _pad0: 0,
            _pad1: 0,
            _pad2: 0,
        };
        queue.write_buffer(&output.params, 0, bytemuck::bytes_of(&params));
        queue.write_buffer(&output.draw_args, 0, bytemuck::cast_slice(&[4u32, 0, 0, 0]));
        if output.count == 0 {
            return;
        }
        let mut pass = encoder
            .begin_compute_pass(&wgpu::ComputePassDescriptor { label: Some("lod cull"), timestamp_writes: None });
        pass.set_bind_group(0, &output.bind_group, &[]);
        let (x, y) = dispatch_grid(workgroups);
        pass.set_pipeline(&self.count);
        pass.dispatch_workgroups(x, y, 1);
        pass.set_pipeline(&self.scan);
        pass.dispatch_workgroups(1, 1, 1);
        pass.set_pipeline(&self.scatter);
        pass.dispatch_workgroups(x, y, 1);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn dispatch_grid_covers_every_workgroup_within_the_limit() {
        for workgroups in [1, 255, 65_535, 65_536, 131_071, 1_000_000, u32::MAX / 256] {
            let (x, y) = dispatch_grid(workgroups);
            assert!(x <= MAX_WORKGROUPS_PER_DIMENSION && y <= MAX_WORKGROUPS_PER_DIMENSION, "{workgroups}");
            assert!(x as u64 * y as u64 >= workgroups as u64, "{workgroups}");
            assert!((x as u64) * (y as u64 - 1) < workgroups as u64, "a whole idle row for {workgroups}");
        }
    }
}

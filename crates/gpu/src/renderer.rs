//! The GPU frame: G-buffer, photon splats of the global and caustic maps,
//! then (by later passes) direct light and the resolve.

use crate::context::{GpuContext, GpuError};
use crate::direct::DirectPass;
use crate::gbuffer::{GBuffer, GBufferParams, GBufferPass};
use crate::readback::read_rgba;
use crate::scene_upload::SceneBuffers;
use crate::shadow::light_samples::GpuLights;
use crate::shadow::{ShadowMaps, ShadowPass};
use crate::splat::{PhotonBuffer, SplatParams, SplatPass};
use glam::{Vec3, Vec4};
use hikari_core::estimate::FixedRadius;
use hikari_core::photon::{PathClass, Photon, TracedPhotons};
use hikari_core::render::Image;
use hikari_core::scene::Scene;

/// Settings shared with `photon-cpu`, so both estimate the same thing, plus
/// the shadow-map settings of the direct-light pass.
#[derive(Clone, Debug)]
pub struct GpuSettings {
    pub global: FixedRadius,
    pub caustic: FixedRadius,
    /// Shadow-mapped samples per area light.
    pub area_light_samples: u32,
    /// Side of each shadow view in texels.
    pub shadow_map_size: u32,
    /// Shadow depth bias, a fraction of the distance to the light.
    pub shadow_bias: f32,
}

impl GpuSettings {
    pub fn new(global: FixedRadius, caustic: FixedRadius) -> Self {
        GpuSettings { global, caustic, area_light_samples: 4, shadow_map_size: 1024, shadow_bias: 0.01 }
    }
}

/// What a frame leaves on the GPU: the G-buffer and the radiance targets.
pub struct FrameTargets {
    pub gbuffer: GBuffer,
    pub direct: wgpu::Texture,
    pub indirect: wgpu::Texture,
    pub caustic: wgpu::Texture,
    pub shadow_maps: ShadowMaps,
}

pub struct GpuRenderer {
    pub ctx: GpuContext,
    gbuffer_pass: GBufferPass,
    splat_pass: SplatPass,
    shadow_pass: ShadowPass,
    direct_pass: DirectPass,
    lights: GpuLights,
    scene: SceneBuffers,
    global_photons: PhotonBuffer,
    caustic_photons: PhotonBuffer,
    power_unit: f32,
    pub settings: GpuSettings,
    pub targets: FrameTargets,
    clip_from_world: glam::Mat4,
    camera_position: Vec3,
}

/// The photons the global-map estimate shows: indirect ones only, as in
/// `photon-cpu` (direct light and caustics are rendered separately).
pub fn global_map_photons(traced: &TracedPhotons) -> Vec<Photon> {
    traced.global.iter().filter(|p| p.class() == PathClass::Indirect).copied().collect()
}

/// Near and far planes enclosing the scene's bounding box.
fn depth_range(scene: &Scene) -> (f32, f32) {
    let (lo, hi) = scene.accel.bounds();
    let eye = scene.camera.position;
    let far = (0..8)
        .map(|i| {
            let corner = Vec3::new(
                if i & 1 == 0 { lo.x } else { hi.x },
                if i & 2 == 0 { lo.y } else { hi.y },
                if i & 4 == 0 { lo.z } else { hi.z },
            );
            (corner - eye).length()
        })
        .fold(0.0f32, f32::max)
        * 1.01;
    (far.max(1e-3) * 1e-4, far.max(1e-3))
}

impl GpuRenderer {
    pub fn new(ctx: GpuContext, scene: &Scene, traced: &TracedPhotons, settings: GpuSettings) -> Self {
        let device = &ctx.device;
        let (w, h) = (scene.camera.width, scene.camera.height);
        let radiance_target = |label| {
            device.create_texture(&wgpu::TextureDescriptor {
                label: Some(label),
                size: wgpu::Extent3d { width: w, height: h, depth_or_array_layers: 1 },
                mip_level_count: 1,
                sample_count: 1,
                dimension: wgpu::TextureDimension::D2,
                format: ctx.radiance_format,
                usage: wgpu::TextureUsages::RENDER_ATTACHMENT
                    | wgpu::TextureUsages::TEXTURE_BINDING
                    | wgpu::TextureUsages::COPY_SRC,
                view_formats: &[],
            })
        };
        let shadow_pass = ShadowPass::new(device);
        let lights = GpuLights::new(scene, settings.area_light_samples);
        let targets = FrameTargets {
            gbuffer: GBuffer::new(device, w, h),
            direct: radiance_target("direct radiance"),
            indirect: radiance_target("indirect radiance"),
            caustic: radiance_target("caustic radiance"),
            shadow_maps: shadow_pass.create_maps(device, &lights.views, settings.shadow_map_size),
        };
        let (near, far) = depth_range(scene);
        GpuRenderer {
            gbuffer_pass: GBufferPass::new(device),
            splat_pass: SplatPass::new(device, ctx.radiance_format),
            direct_pass: DirectPass::new(device, ctx.radiance_format),
            shadow_pass,
            lights,
            scene: SceneBuffers::upload(device, scene),
            global_photons: PhotonBuffer::upload(device, &global_map_photons(traced), "global photons"),
            caustic_photons: PhotonBuffer::upload(device, &traced.caustic, "caustic photons"),
            power_unit: traced.power_unit,
            settings,
            targets,
            clip_from_world: scene.camera.clip_from_view(near, far) * scene.camera.view_from_world(),
            camera_position: scene.camera.position,
            ctx,
        }
    }

    fn splat_params(&self, estimate: &FixedRadius) -> SplatParams {
        SplatParams {
            clip_from_world: self.clip_from_world.to_cols_array_2d(),
            radius: estimate.radius,
            power_unit: self.power_unit,
            normal_test: estimate.normal_test as u32,
            _pad: 0,
        }
    }

    /// Records and submits one frame.
    pub fn render(&self) {
        let device = &self.ctx.device;
        let mut encoder = device.create_command_encoder(&Default::default());
        let gparams = GBufferParams {
            clip_from_world: self.clip_from_world.to_cols_array_2d(),
            camera_position: self.camera_position.to_array(),
            _pad: 0.0,
        };
        self.gbuffer_pass.record(device, &mut encoder, &self.scene, &gparams, &self.targets.gbuffer);
        self.shadow_pass.record(&mut encoder, &self.scene, &self.targets.shadow_maps);
        let direct_view = self.targets.direct.create_view(&Default::default());
        self.direct_pass.record(
            device,
            &mut encoder,
            &self.targets.gbuffer,
            &self.lights,
            &self.targets.shadow_maps,
            self.settings.shadow_bias,
            &direct_view,
        );
        let indirect_view = self.targets.indirect.create_view(&Default::default());
        let caustic_view = self.targets.caustic.create_view(&Default::default());
        let global = &self.global_photons;
        self.splat_pass.record(
            device,
            &mut encoder,
            &self.targets.gbuffer,
            global,
            0..global.count,
            &self.splat_params(&self.settings.global),
            &indirect_view,
            true,
        );
        let caustic = &self.caustic_photons;
        self.splat_pass.record(
            device,
            &mut encoder,
            &self.targets.gbuffer,
            caustic,
            0..caustic.count,
            &self.splat_params(&self.settings.caustic),
            &caustic_view,
            true,
        );
        self.ctx.queue.submit([encoder.finish()]);
    }

    pub fn read(&self, texture: &wgpu::Texture) -> Result<Vec<Vec4>, GpuError> {
        read_rgba(&self.ctx, texture)
    }

    /// Reads the frame back as one image: emission + direct + indirect +
    /// caustics. Non-finite values are dropped (counted in the second value).
    pub fn read_image(&self) -> Result<(Image, u64), GpuError> {
        let t = &self.targets;
        let parts =
            [self.read(&t.gbuffer.emission)?, self.read(&t.direct)?, self.read(&t.indirect)?, self.read(&t.caustic)?];
        let mut image = Image::new(t.gbuffer.width, t.gbuffer.height);
        let mut nonfinite = 0;
        for (i, pixel) in image.pixels.iter_mut().enumerate() {
            let sum: Vec3 = parts.iter().map(|p| p[i].truncate()).sum();
            if sum.is_finite() {
                *pixel = sum;
            } else {
                nonfinite += 1;
            }
        }
        Ok((image, nonfinite))
    }
}

//! The GPU frame: G-buffer, shadow maps, optical-depth slices, direct light,
//! photon splats of the global, caustic and volume maps, the specular pass
//! and the resolve.

use crate::context::{GpuContext, GpuError};
use crate::direct::DirectPass;
use crate::features::SceneFeatures;
use crate::gbuffer::{GBuffer, GBufferBinding, GBufferParams, GBufferPass};
use crate::lod::{LodOutput, LodPass};
use crate::media::GpuMedia;
use crate::memory::FrameSize;
use crate::photons::PhotonBuffer;
use crate::readback::read_rgba;
use crate::resolve::ResolvePass;
use crate::scene_upload::SceneBuffers;
use crate::shadow::light_samples::{GpuLights, LightSource};
use crate::shadow::{ShadowMaps, ShadowPass};
use crate::specular::{SpecularInputs, SpecularPass};
use crate::splat::depth_tiles::DepthTiles;
use crate::splat::{SplatBinding, SplatParams, SplatPass};
use crate::tiled::{Estimator, TiledBinding, TiledMap, TiledPass};
use crate::volume::{VolumeParams, VolumePass};
use glam::{Vec3, Vec4};
use hikari_core::estimate::FixedRadius;
use hikari_core::lod::LodSettings;
use hikari_core::photon::TracedPhotons;
use hikari_core::render::Image;
use hikari_core::scene::Scene;
use std::cell::{OnceCell, RefCell};

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
    /// Level of detail for the photon splats; None draws every photon.
    pub lod: Option<LodSettings>,
    /// Mirror/glass bounces followed from the eye (as photon-cpu's).
    pub max_specular_depth: u32,
    /// Radius of the volume photons' spheres (photon-cpu's `volume_radius`).
    pub volume_radius: f32,
    /// Optical-depth slices along each view ray through region media.
    pub volume_slices: u32,
    /// The terms the frame holds (all by default; the viewer toggles them).
    pub terms: crate::resolve::Terms,
    /// How the global and caustic maps are estimated (raster splat by default).
    pub estimator: Estimator,
    /// The progressive pass this frame is (from 1): it seeds the random
    /// streams with which glossy points sample their lobes and area lights,
    /// so each pass draws new samples and the passes' mean converges.
    pub pass: u32,
}

impl GpuSettings {
    pub fn new(global: FixedRadius, caustic: FixedRadius) -> Self {
        GpuSettings {
            global,
            caustic,
            area_light_samples: 4,
            shadow_map_size: 1024,
            shadow_bias: 0.01,
            lod: None,
            max_specular_depth: 8,
            volume_radius: global.radius,
            volume_slices: 8,
            terms: crate::resolve::Terms::ALL,
            estimator: Estimator::Raster,
            pass: 1,
        }
    }
}

/// The seed's Cornell-box LOD setting n = 20, f = 7 is in the seed's units,
/// and its box size is not given. Scaled by 2/7 (as if its box were 7 units
/// wide against our 2) it culls the nearest photons: 31% of the indirect
/// photons of `cornell-box` at 10,000 emitted (measured by the LOD test).
pub const SEED_CORNELL_LOD: LodSettings = LodSettings { near: 20.0 * 2.0 / 7.0, far: 7.0 * 2.0 / 7.0, groups: 20 };

/// What a frame leaves on the GPU: the G-buffer and the radiance targets.
pub struct FrameTargets {
    pub gbuffer: GBuffer,
    pub direct: wgpu::Texture,
    pub indirect: wgpu::Texture,
    pub caustic: wgpu::Texture,
    /// Light the media scatter toward the eye.
    pub volume: wgpu::Texture,
    pub shadow_maps: ShadowMaps,
}

/// The passes of a frame, in order.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Stage {
    GBuffer,
    Shadows,
    /// Region media rasterized into optical-depth slices.
    OpticalDepth,
    Direct,
    /// LOD cull and splat of the global map.
    GlobalSplat,
    /// LOD cull and splat of the caustic map.
    CausticSplat,
    /// LOD cull and splat of the volume map.
    VolumeSplat,
    /// Mirrors and glass seen by the camera, ray-traced to diffuse hits.
    Specular,
    /// The sum of all radiance targets.
    Resolve,
}

impl Stage {
    pub const ALL: [Stage; 9] = [
        Stage::GBuffer,
        Stage::Shadows,
        Stage::OpticalDepth,
        Stage::Direct,
        Stage::GlobalSplat,
        Stage::CausticSplat,
        Stage::VolumeSplat,
        Stage::Specular,
        Stage::Resolve,
    ];

    pub fn name(self) -> &'static str {
        match self {
            Stage::GBuffer => "g-buffer",
            Stage::Shadows => "shadow maps",
            Stage::OpticalDepth => "optical depth",
            Stage::Direct => "direct light",
            Stage::GlobalSplat => "global splat",
            Stage::CausticSplat => "caustic splat",
            Stage::VolumeSplat => "volume splat",
            Stage::Specular => "specular",
            Stage::Resolve => "resolve",
        }
    }
}

/// The error of a specular pass that no split of its gathers fits.
fn specular_over_budget(invocations: u32, budget: u32) -> GpuError {
    GpuError::LoopBudget(format!(
        "mirrors/glass: {invocations} pixel invocations need more than this adapter's {budget} shader loop \
         iterations even with the photon gathers split {} ways",
        crate::specular::MAX_SLICES
    ))
}

pub struct GpuRenderer {
    pub ctx: GpuContext,
    /// What the pipelines are specialised to: the scene's features.
    features: SceneFeatures,
    gbuffer_pass: GBufferPass,
    gbuffer_binding: GBufferBinding,
    /// The G-buffer's depth range per tile, made after it each frame (the
    /// surface splat trims its quads by it).
    depth_tiles: DepthTiles,
    splat_pass: SplatPass,
    global_splat: SplatBinding,
    caustic_splat: SplatBinding,
    shadow_pass: ShadowPass,
    /// The shadow pass's bind group of the scene (cut-outs).
    shadow_scene: wgpu::BindGroup,
    /// Whether the shadow maps hold the scene as it is: they depend on the
    /// geometry and lights alone, so frames of a scene that stands still
    /// (progressive passes, camera moves) draw them once, not every frame.
    shadows_drawn: std::cell::Cell<bool>,
    /// The scene's lights, from which each progressive pass draws its own
    /// shadow-mapped samples, and the pass the samples now bound are of.
    light_source: LightSource,
    light_pass: std::cell::Cell<u32>,
    direct_pass: DirectPass,
    direct_binding: crate::direct::DirectBinding,
    specular_pass: SpecularPass,
    resolve_pass: ResolvePass,
    media: GpuMedia,
    volume_pass: VolumePass,
    volume_lod: LodOutput,
    has_media: bool,
    /// The scene has `alphaMode` BLEND surfaces: the shadow views are
    /// redrawn every pass (`resample_lights`), the last for pass `blend_pass`.
    has_blend: bool,
    blend_pass: std::cell::Cell<u32>,
    scene: SceneBuffers,
    lod_pass: LodPass,
    global_lod: LodOutput,
    caustic_lod: LodOutput,
    power_unit: f32,
    pub settings: GpuSettings,
    pub targets: FrameTargets,
    clip_from_world: glam::Mat4,
    camera_position: Vec3,
    camera: hikari_core::camera::Camera,
    /// The scene's bounds (for the depth range of a moved camera).
    bounds: (Vec3, Vec3),
    /// The photons-as-points debug view, made when first drawn.
    points: std::cell::OnceCell<crate::points::PointsPass>,
    /// The tiled estimator, made when first used, and its per-map state
    /// (dropped with the photons it binds; sized to what frames needed).
    tiled_pass: OnceCell<TiledPass>,
    global_tiled: RefCell<Option<TiledBinding>>,
    caustic_tiled: RefCell<Option<TiledBinding>>,
    volume_tiled: RefCell<Option<TiledBinding>>,
}

/// What the specular pass gathers from.
fn specular_inputs<'a>(
    settings: &GpuSettings,
    traced: &'a TracedPhotons,
    global_photons: &'a [hikari_core::photon::Photon],
    iteration_budget: u32,
) -> SpecularInputs<'a> {
    SpecularInputs {
        global_photons,
        caustic_photons: &traced.caustic,
        volume_photons: &traced.volume,
        volume_radius: settings.volume_radius,
        global: settings.global,
        caustic: settings.caustic,
        power_unit: traced.power_unit,
        max_depth: settings.max_specular_depth,
        shadow_bias: settings.shadow_bias,
        iteration_budget,
    }
}

/// What `ctx`'s adapter draws of `scene` otherwise than the CPU renderers,
/// one line each (the front ends print them with the scene's notes).
pub fn adapter_notes(ctx: &GpuContext, scene: &Scene) -> Vec<String> {
    let mut notes = Vec::new();
    if SceneFeatures::of_scene(scene).layered && !ctx.layer_texels {
        let lacks = if ctx.gbuffer_storage {
            format!("{} storage textures a shader stage, 5 needed", ctx.limits.max_storage_textures_per_shader_stage)
        } else {
            format!(
                "{} bytes of colour attachments a sample, 80 needed",
                ctx.limits.max_color_attachment_bytes_per_sample
            )
        };
        notes.push(format!(
            "note: {} has no room for the G-buffer's layer texels ({lacks}): the GPU renderer draws clear-coat, sheen \
             and specular textures with their means over the image, and clear coats on the base's normal (no \
             clearcoatNormalTexture)",
            ctx.describe()
        ));
    }
    notes
}

/// `features` as this adapter draws them: layer textures per point only
/// where its G-buffer can keep their texels (`GpuContext::layer_texels`),
/// else as their means (`scene_upload::scene_surfaces`).
fn within_adapter(ctx: &GpuContext, features: SceneFeatures) -> SceneFeatures {
    SceneFeatures { layered: features.layered && ctx.layer_texels, ..features }
}

/// The rasterizing passes' projection for `camera` in a scene within `bounds`.
fn clip_from_world(camera: &hikari_core::camera::Camera, bounds: (Vec3, Vec3)) -> glam::Mat4 {
    let (near, far) = depth_range(bounds, camera.position);
    camera.clip_from_view(near, far) * camera.view_from_world()
}

/// Near and far planes enclosing the scene bounds `(lo, hi)` seen from `eye`.
fn depth_range((lo, hi): (Vec3, Vec3), eye: Vec3) -> (f32, f32) {
    let far = crate::shadow::shadow_range(eye, lo, hi).max(1e-3);
    (far * 1e-4, far)
}

impl GpuRenderer {
    /// Why `ctx` cannot draw `scene` correctly, if so. Media need 32-bit
    /// float blending: the volume splat adds thousands of small in-scattered
    /// terms per pixel and the optical-depth pass adds and subtracts region
    /// crossings, and 16-bit sums lose both (measured on Mesa's GL: slab
    /// optical depths off by 8e-4 where they are 0, fog frames off by more
    /// than 2%).
    pub fn unsupported(ctx: &GpuContext, scene: &Scene) -> Option<String> {
        (!ctx.float32_blend && !scene.media.is_empty())
            .then(|| "participating media need 32-bit float blending, which this adapter lacks".to_string())
    }

    /// What a frame of `scene` with `settings` allocates, for `photons`
    /// stored in the global, caustic and volume maps (known, or estimated
    /// before tracing).
    pub fn frame_size(scene: &Scene, settings: &GpuSettings, photons: [u64; 3]) -> FrameSize {
        let lights = GpuLights::new(scene, settings.area_light_samples);
        let (vertex_bytes, bvh_bytes) = crate::scene_upload::scene_buffer_bytes(scene);
        FrameSize {
            width: scene.camera.width,
            height: scene.camera.height,
            shadow_map_size: settings.shadow_map_size,
            shadow_layers: lights.views.len() as u32,
            volume_slices: if GpuMedia::has_regions(scene) { settings.volume_slices } else { 0 },
            photons,
            texture_bytes: crate::textures::packed_bytes(
                scene,
                scene.accel.triangles().count() + scene.accel.spheres().count(),
            ),
            vertex_bytes,
            bvh_bytes,
        }
    }

    /// Checks, before anything is traced or allocated, that `scene` with
    /// `settings` fits `ctx`: every texture and buffer within the adapter's
    /// limits, and the direct-light shader's loops (lights × samples ×
    /// region triangles, known here exactly) within its loop budget. The
    /// specular pass's loops depend on the photons and are checked as it
    /// runs (`SpecularPass`).
    pub fn check_fits(
        ctx: &GpuContext,
        scene: &Scene,
        settings: &GpuSettings,
        photons: [u64; 3],
    ) -> Result<(), GpuError> {
        if let Some(why) = Self::unsupported(ctx, scene) {
            return Err(GpuError::SceneUnsupported(why));
        }
        Self::frame_size(scene, settings, photons).check(ctx)?;
        let lights = GpuLights::new(scene, settings.area_light_samples);
        let iterations = crate::direct::loop_iterations(&lights, GpuMedia::region_triangle_count(scene));
        if iterations > ctx.loop_budget as u64 {
            return Err(GpuError::LoopBudget(format!(
                "direct light needs {iterations} shader loop iterations per pixel (light samples × region \
                 triangles), over this adapter's budget of {}",
                ctx.loop_budget
            )));
        }
        Ok(())
    }

    /// Creates every pass and uploads the scene and the photons, under wgpu
    /// error scopes: an adapter that refuses anything gives an error.
    pub fn new(
        ctx: GpuContext,
        scene: &Scene,
        traced: &TracedPhotons,
        settings: GpuSettings,
    ) -> Result<Self, GpuError> {
        Self::with_features(ctx, scene, traced, settings, SceneFeatures::of_scene(scene))
    }

    /// `new` with pipelines specialised to `features`, which must include
    /// the scene's (tests compare `SceneFeatures::ALL` with the scene's own).
    #[doc(hidden)]
    pub fn with_features(
        ctx: GpuContext,
        scene: &Scene,
        traced: &TracedPhotons,
        settings: GpuSettings,
        features: SceneFeatures,
    ) -> Result<Self, GpuError> {
        let photons = [traced.indirect().len() as u64, traced.caustic.len() as u64, traced.volume.len() as u64];
        Self::check_fits(&ctx, scene, &settings, photons)?;
        let features = within_adapter(&ctx, features);
        let scopes = ctx.error_scopes();
        let renderer = Self::create(ctx, scene, traced, settings, features);
        scopes.finish()?;
        renderer.ctx.check()?;
        Ok(renderer)
    }

    fn create(
        ctx: GpuContext,
        scene: &Scene,
        traced: &TracedPhotons,
        settings: GpuSettings,
        features: SceneFeatures,
    ) -> Self {
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
                    | wgpu::TextureUsages::STORAGE_BINDING
                    | wgpu::TextureUsages::COPY_SRC,
                view_formats: &[],
            })
        };
        let shadow_pass = ShadowPass::new(device, crate::shadow::map_format(ctx.r32_renderable), features);
        let lod_pass = LodPass::new(device);
        let lights = GpuLights::new(scene, settings.area_light_samples);
        let targets = FrameTargets {
            gbuffer: GBuffer::new(device, w, h, ctx.gbuffer_storage, features.layered),
            direct: radiance_target("direct radiance"),
            indirect: radiance_target("indirect radiance"),
            caustic: radiance_target("caustic radiance"),
            volume: radiance_target("volume radiance"),
            shadow_maps: shadow_pass.create_maps(device, &lights, settings.shadow_map_size, scene.accel.bounds()),
        };
        let scene_buffers = SceneBuffers::upload(device, scene, features.layered);
        let global_photons = traced.indirect();
        let bounds = scene.accel.bounds();
        let clip_from_world = clip_from_world(&scene.camera, bounds);
        let media = GpuMedia::new(
            device,
            scene,
            settings.volume_slices,
            &targets.gbuffer,
            clip_from_world,
            ctx.radiance_format,
        );
        let specular_pass = SpecularPass::new(
            device,
            scene,
            &scene_buffers,
            &lights,
            &targets.shadow_maps,
            &targets.gbuffer,
            &media,
            &specular_inputs(&settings, traced, &global_photons, ctx.loop_budget),
            features,
        );
        let volume_params = VolumeParams {
            clip_from_world: clip_from_world.to_cols_array_2d(),
            radius: settings.volume_radius,
            power_unit: traced.power_unit,
            _pad0: 0,
            _pad1: 0,
        };
        let gbuffer_pass = GBufferPass::new(device, ctx.gbuffer_storage, features);
        let depth_tiles = DepthTiles::new(device, &targets.gbuffer);
        let splat_pass = SplatPass::new(device, ctx.radiance_format, features);
        let direct_pass = DirectPass::new(device, ctx.radiance_format, features);
        let volume_pass = VolumePass::new(device, ctx.radiance_format, &volume_params, &media, &targets.gbuffer);
        let t = &targets;
        let resolve_pass = ResolvePass::new(
            device,
            [&t.gbuffer.emission, &t.direct, &t.indirect, &t.caustic, &specular_pass.output],
            &t.volume,
            &t.gbuffer,
            &media,
            lights.sky_radiance,
            &scene_buffers.environment,
            features,
        );
        GpuRenderer {
            features,
            resolve_pass,
            specular_pass,
            gbuffer_binding: gbuffer_pass.bind(device, &scene_buffers, &targets.gbuffer),
            gbuffer_pass,
            global_splat: splat_pass.bind(device, &targets.gbuffer, &scene_buffers.surfaces, &depth_tiles.tiles),
            caustic_splat: splat_pass.bind(device, &targets.gbuffer, &scene_buffers.surfaces, &depth_tiles.tiles),
            depth_tiles,
            splat_pass,
            direct_binding: direct_pass.bind(
                device,
                &targets.gbuffer,
                &scene_buffers.surfaces,
                &lights,
                &targets.shadow_maps,
                settings.shadow_bias,
                &media,
            ),
            direct_pass,
            shadow_scene: shadow_pass.bind_scene(device, &scene_buffers),
            shadows_drawn: std::cell::Cell::new(false),
            light_source: LightSource::of(scene),
            light_pass: std::cell::Cell::new(1),
            shadow_pass,
            scene: scene_buffers,
            global_lod: lod_pass
                .create_output(device, &PhotonBuffer::upload(device, &traced.indirect(), "global photons")),
            caustic_lod: lod_pass
                .create_output(device, &PhotonBuffer::upload(device, &traced.caustic, "caustic photons")),
            volume_lod: lod_pass.create_output(device, &PhotonBuffer::upload(device, &traced.volume, "volume photons")),
            has_media: !scene.media.is_empty(),
            has_blend: scene.texturing.as_ref().is_some_and(|t| t.has_blend()),
            blend_pass: std::cell::Cell::new(0),
            media,
            volume_pass,
            lod_pass,
            power_unit: traced.power_unit,
            settings,
            targets,
            clip_from_world,
            camera_position: scene.camera.position,
            camera: scene.camera.clone(),
            bounds,
            points: std::cell::OnceCell::new(),
            tiled_pass: OnceCell::new(),
            global_tiled: RefCell::new(None),
            caustic_tiled: RefCell::new(None),
            volume_tiled: RefCell::new(None),
            ctx,
        }
    }

    /// The resolved frame (linear radiance, `Rgba32Float`), as `read_image` reads it.
    pub fn resolved(&self) -> &wgpu::Texture {
        &self.resolve_pass.output
    }

    /// The camera the frames are drawn from.
    pub fn camera(&self) -> &hikari_core::camera::Camera {
        &self.camera
    }

    /// Draws the next frames from `camera`, which must keep the resolution
    /// (the targets are sized for it). The photon maps stay: they do not
    /// depend on the eye.
    pub fn set_camera(&mut self, camera: &hikari_core::camera::Camera) -> Result<(), GpuError> {
        if (camera.width, camera.height) != (self.camera.width, self.camera.height) {
            return Err(GpuError::Failed(format!(
                "a camera of {}x{} for targets of {}x{}",
                camera.width, camera.height, self.camera.width, self.camera.height
            )));
        }
        let queue = &self.ctx.queue;
        self.clip_from_world = clip_from_world(camera, self.bounds);
        self.camera_position = camera.position;
        self.camera = camera.clone();
        self.media.set_camera(queue, camera, self.clip_from_world);
        self.specular_pass.set_camera(queue, camera);
        self.volume_pass.set_params(queue, &self.volume_params());
        Ok(())
    }

    /// Draws the next frames from `traced`, a new photon set of the same
    /// scene (the viewer's progressive frames): new photon buffers, LOD
    /// outputs and specular grids; the pipelines and every other resource
    /// stay. Checked against the adapter's limits first.
    pub fn set_photons(&mut self, scene: &Scene, traced: &TracedPhotons) -> Result<(), GpuError> {
        let global_photons = traced.indirect();
        let counts = [global_photons.len() as u64, traced.caustic.len() as u64, traced.volume.len() as u64];
        Self::check_fits(&self.ctx, scene, &self.settings, counts)?;
        let scopes = self.ctx.error_scopes();
        let device = &self.ctx.device;
        let upload = |photons: &[hikari_core::photon::Photon], label| {
            self.lod_pass.create_output(device, &PhotonBuffer::upload(device, photons, label))
        };
        self.global_lod = upload(&global_photons, "global photons");
        self.caustic_lod = upload(&traced.caustic, "caustic photons");
        // The tiled state binds the old photon buffers.
        self.global_tiled.replace(None);
        self.caustic_tiled.replace(None);
        self.volume_tiled.replace(None);
        self.volume_lod = upload(&traced.volume, "volume photons");
        self.power_unit = traced.power_unit;
        let inputs = specular_inputs(&self.settings, traced, &global_photons, self.ctx.loop_budget);
        self.specular_pass.set_photons(device, &self.ctx.queue, &inputs);
        self.volume_pass.set_params(&self.ctx.queue, &self.volume_params());
        scopes.finish()?;
        self.ctx.check()
    }

    /// Draws the next frames of `scene`, the renderer's scene moved (the
    /// same surfaces, lights and media, posed anew: `Scene::posed`), with
    /// `traced`, its photons. Pipelines, targets and the photon passes stay;
    /// the geometry, lights, shadow views, BVH and photons are uploaded. A
    /// scene whose materials use other features (`SceneFeatures`) gets
    /// pipelines made for them, the camera kept.
    pub fn set_scene(&mut self, scene: &Scene, traced: &TracedPhotons) -> Result<(), GpuError> {
        let counts = [traced.indirect().len() as u64, traced.caustic.len() as u64, traced.volume.len() as u64];
        Self::check_fits(&self.ctx, scene, &self.settings, counts)?;
        let features = within_adapter(&self.ctx, SceneFeatures::of_scene(scene));
        if features.union(self.features) != self.features {
            let mut posed = scene.clone();
            posed.camera = self.camera.clone();
            *self = Self::with_features(self.ctx.clone(), &posed, traced, self.settings.clone(), features)?;
            return Ok(());
        }
        let scopes = self.ctx.error_scopes();
        let (device, queue) = (&self.ctx.device, &self.ctx.queue);
        self.scene = SceneBuffers::upload(device, scene, self.features.layered);
        self.gbuffer_binding = self.gbuffer_pass.bind(device, &self.scene, &self.targets.gbuffer);
        self.shadow_scene = self.shadow_pass.bind_scene(device, &self.scene);
        self.global_splat =
            self.splat_pass.bind(device, &self.targets.gbuffer, &self.scene.surfaces, &self.depth_tiles.tiles);
        self.caustic_splat =
            self.splat_pass.bind(device, &self.targets.gbuffer, &self.scene.surfaces, &self.depth_tiles.tiles);
        self.bounds = scene.accel.bounds();
        let lights = GpuLights::new(scene, self.settings.area_light_samples);
        self.light_source = LightSource::of(scene);
        self.light_pass.set(1);
        self.has_blend = scene.texturing.as_ref().is_some_and(|t| t.has_blend());
        self.blend_pass.set(0);
        self.shadows_drawn.set(false);
        if !self.targets.shadow_maps.update(queue, &lights, self.bounds) {
            self.targets.shadow_maps =
                self.shadow_pass.create_maps(device, &lights, self.settings.shadow_map_size, self.bounds);
        }
        self.resolve_pass.set_sky(queue, lights.sky_radiance);
        self.direct_binding = self.direct_pass.bind(
            device,
            &self.targets.gbuffer,
            &self.scene.surfaces,
            &lights,
            &self.targets.shadow_maps,
            self.settings.shadow_bias,
            &self.media,
        );
        self.specular_pass.set_scene(device, queue, scene, &self.scene, &lights, &self.targets.shadow_maps);
        self.media.set_scene(queue, scene);
        self.clip_from_world = clip_from_world(&self.camera, self.bounds);
        self.media.set_camera(queue, &self.camera, self.clip_from_world);
        scopes.finish()?;
        self.set_photons(scene, traced)
    }

    fn volume_params(&self) -> VolumeParams {
        VolumeParams {
            clip_from_world: self.clip_from_world.to_cols_array_2d(),
            radius: self.settings.volume_radius,
            power_unit: self.power_unit,
            _pad0: 0,
            _pad1: 0,
        }
    }

    fn splat_params(&self, estimate: &FixedRadius) -> SplatParams {
        SplatParams {
            clip_from_world: self.clip_from_world.to_cols_array_2d(),
            radius: estimate.radius,
            power_unit: self.power_unit,
            normal_test: estimate.normal_test as u32,
            _pad: 0,
            camera_position: self.camera_position.to_array(),
            _pad1: 0,
        }
    }

    /// Renders one frame and waits for it. When the specular pass reports
    /// pixels over the loop budget, its gathers are split into four times
    /// as many dispatches and it (and the resolve) run again, up to
    /// `specular::MAX_SLICES`; past that the frame is an error, never an
    /// image with light silently missing.
    pub fn render(&self) -> Result<(), GpuError> {
        crate::block::wait_for(self.render_async())
    }

    /// `render` without blocking: the status readbacks that settle the
    /// frame are awaited (a browser's frame goes on once they resolve).
    pub async fn render_async(&self) -> Result<(), GpuError> {
        let scopes = self.ctx.error_scopes();
        let mut encoder = self.ctx.device.create_command_encoder(&Default::default());
        for stage in Stage::ALL {
            self.record_stage(stage, &mut encoder);
        }
        self.ctx.queue.submit([encoder.finish()]);
        scopes.finish()?;
        self.ctx.wait()?;
        self.settle_specular().await?;
        self.settle_tiled().await
    }

    /// The tiled estimator's pass, made on first use.
    fn tiled_pass(&self) -> &TiledPass {
        self.tiled_pass.get_or_init(|| TiledPass::new(&self.ctx.device, self.ctx.radiance_format, self.features))
    }

    /// The tiled estimator's state for one map and what it estimates into.
    fn tiled_maps(&self) -> [(&RefCell<Option<TiledBinding>>, TiledMap, &LodOutput, &wgpu::Texture); 3] {
        [
            (&self.global_tiled, TiledMap::Surface, &self.global_lod, &self.targets.indirect),
            (&self.caustic_tiled, TiledMap::Surface, &self.caustic_lod, &self.targets.caustic),
            (&self.volume_tiled, TiledMap::Volume, &self.volume_lod, &self.targets.volume),
        ]
    }

    /// Records one map's tiled estimate, making its state on first use.
    fn record_tiled(&self, encoder: &mut wgpu::CommandEncoder, map: usize, params: &SplatParams) {
        let (cell, kind, output, target) = self.tiled_maps()[map];
        let pass = self.tiled_pass();
        let budget = self.ctx.loop_budget;
        let mut state = cell.borrow_mut();
        let tiled = state.get_or_insert_with(|| {
            // A first guess: four tiles a photon, settled by `render`.
            let entries = output.capacity().saturating_mul(4).clamp(1024, self.max_tile_entries());
            let (device, gbuffer) = (&self.ctx.device, &self.targets.gbuffer);
            pass.bind(device, gbuffer, &self.media, kind, output, &self.scene.surfaces, target, entries, 1, budget)
        });
        pass.record(&self.ctx.queue, encoder, tiled, params, output, budget);
    }

    /// List entries the adapter's largest storage buffer holds.
    fn max_tile_entries(&self) -> u32 {
        (self.ctx.limits.max_storage_buffer_binding_size / 4).min(u32::MAX as u64) as u32
    }

    /// After a tiled frame: when a map's tile lists overflowed their buffer or
    /// a list was longer than its gather slices read, the map's buffers are
    /// sized to what the frame needed and the estimate and resolve run
    /// again; a photon covering more tiles than the loop budget allows is an
    /// error. Never an image with photons silently left out.
    async fn settle_tiled(&self) -> Result<(), GpuError> {
        if self.settings.estimator != Estimator::Tiled {
            return Ok(());
        }
        for _ in 0..4 {
            let mut rerun = false;
            for (cell, kind, output, target) in self.tiled_maps() {
                let Some(status) = ({
                    let binding = cell.borrow();
                    match binding.as_ref() {
                        Some(current) => Some(current.check_async(&self.ctx).await?),
                        None => None,
                    }
                }) else {
                    continue;
                };
                let mut binding = cell.borrow_mut();
                let Some(current) = binding.as_ref() else { continue };
                if current.fits(&status) {
                    continue;
                }
                let budget = self.ctx.loop_budget;
                let (entries, slices) = crate::tiled::fitted_sizes(&status, budget, self.max_tile_entries())?;
                let device = &self.ctx.device;
                let gbuffer = &self.targets.gbuffer;
                let media = &self.media;
                let surfaces = &self.scene.surfaces;
                *binding = Some(
                    self.tiled_pass()
                        .bind(device, gbuffer, media, kind, output, surfaces, target, entries, slices, budget),
                );
                rerun = true;
            }
            if !rerun {
                return Ok(());
            }
            let scopes = self.ctx.error_scopes();
            let mut encoder = self.ctx.device.create_command_encoder(&Default::default());
            for stage in [Stage::GlobalSplat, Stage::CausticSplat, Stage::VolumeSplat, Stage::Resolve] {
                self.record_stage(stage, &mut encoder);
            }
            self.ctx.queue.submit([encoder.finish()]);
            scopes.finish()?;
            self.ctx.wait()?;
        }
        Err(GpuError::Failed("the tiled estimator's buffers did not settle after 4 resizes".into()))
    }

    /// Dispatches and list entries of the tiled estimator's global map (tests).
    pub fn tiled_sizes(&self) -> Option<(u32, u32)> {
        self.global_tiled.borrow().as_ref().map(|b| (b.slices(), b.list_capacity()))
    }

    /// Re-runs the specular pass with more slices until no pixel runs over
    /// budget (see `render`). Before the first split, one probe dispatch
    /// says whether even the finest split fits: where the rays alone run
    /// over (lavapipe's budget on deep glass), the renderer says so at
    /// once rather than after 341 retracings of every pixel (~40 s).
    async fn settle_specular(&self) -> Result<(), GpuError> {
        let pass = &self.specular_pass;
        if !pass.enabled() {
            return Ok(());
        }
        let mut probed = false;
        loop {
            let status = pass.read_status_async(&self.ctx).await?;
            if status.over_budget == 0 {
                return Ok(());
            }
            if !probed {
                probed = true;
                let scopes = self.ctx.error_scopes();
                let mut encoder = self.ctx.device.create_command_encoder(&Default::default());
                pass.record_probe(&self.ctx.queue, &mut encoder, self.settings.pass);
                self.ctx.queue.submit([encoder.finish()]);
                scopes.finish()?;
                let finest = pass.read_status_async(&self.ctx).await?;
                if finest.over_budget > 0 {
                    return Err(specular_over_budget(finest.over_budget, pass.iteration_budget()));
                }
            }
            if pass.slices() >= crate::specular::MAX_SLICES {
                return Err(specular_over_budget(status.over_budget, pass.iteration_budget()));
            }
            pass.set_slices(pass.slices() * 4);
            let scopes = self.ctx.error_scopes();
            let mut encoder = self.ctx.device.create_command_encoder(&Default::default());
            self.record_stage(Stage::Specular, &mut encoder);
            self.record_stage(Stage::Resolve, &mut encoder);
            self.ctx.queue.submit([encoder.finish()]);
            scopes.finish()?;
        }
    }

    /// What the last frame's specular pass reported.
    pub fn specular_status(&self) -> Result<crate::specular::SpecularStatus, GpuError> {
        self.specular_pass.read_status(&self.ctx)
    }

    /// Dispatches the specular gathers are split into (grown by `render`).
    pub fn specular_slices(&self) -> u32 {
        self.specular_pass.slices()
    }

    /// Splits the specular gathers into `slices` dispatches from now on.
    pub fn set_specular_slices(&self, slices: u32) {
        self.specular_pass.set_slices(slices)
    }

    /// Renders one frame and times each stage: with GPU timestamps written
    /// between the stages when the adapter has them (true = timestamps),
    /// else wall-clock around a separate submit per stage, waited for.
    /// The frame is a whole one, as `render` makes it (the specular pass
    /// split further if it ran over budget, the tiled estimator's buffers
    /// resized; those reruns are not timed).
    pub fn render_timed(&self) -> Result<(Vec<(Stage, f64)>, bool), GpuError> {
        crate::block::wait_for(self.render_timed_async())
    }

    /// `render_timed` without blocking (the web page's timed frames).
    pub async fn render_timed_async(&self) -> Result<(Vec<(Stage, f64)>, bool), GpuError> {
        let timed = if self.ctx.timestamps {
            let scopes = self.ctx.error_scopes();
            let times = self.render_timestamped().await;
            scopes.finish_async().await?;
            (times?, true)
        } else {
            let mut times = Vec::new();
            for stage in Stage::ALL {
                let start = web_time::Instant::now();
                // Scopes closed before the wait: a browser's page runs
                // other tasks (the photon tracer) meanwhile.
                let scopes = self.ctx.error_scopes();
                let mut encoder = self.ctx.device.create_command_encoder(&Default::default());
                self.record_stage(stage, &mut encoder);
                self.ctx.queue.submit([encoder.finish()]);
                scopes.finish_async().await?;
                crate::readback::work_done_async(&self.ctx).await?;
                times.push((stage, start.elapsed().as_secs_f64()));
            }
            (times, false)
        };
        // As `render_async` settles them (reruns untimed).
        self.settle_specular().await?;
        self.settle_tiled().await?;
        Ok(timed)
    }

    async fn render_timestamped(&self) -> Result<Vec<(Stage, f64)>, GpuError> {
        let device = &self.ctx.device;
        let count = Stage::ALL.len() as u32 + 1;
        let queries = device.create_query_set(&wgpu::QuerySetDescriptor {
            label: Some("stage timestamps"),
            ty: wgpu::QueryType::Timestamp,
            count,
        });
        let resolved = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("stage timestamps"),
            size: count as u64 * 8,
            usage: wgpu::BufferUsages::QUERY_RESOLVE | wgpu::BufferUsages::COPY_SRC,
            mapped_at_creation: false,
        });
        let mut encoder = device.create_command_encoder(&Default::default());
        encoder.write_timestamp(&queries, 0);
        for (i, stage) in Stage::ALL.into_iter().enumerate() {
            self.record_stage(stage, &mut encoder);
            encoder.write_timestamp(&queries, i as u32 + 1);
        }
        encoder.resolve_query_set(&queries, 0..count, &resolved, 0);
        self.ctx.queue.submit([encoder.finish()]);
        let words = crate::readback::read_u32s_async(&self.ctx, &resolved, count as u64 * 2).await?;
        let ticks: Vec<u64> = words.chunks(2).map(|w| w[0] as u64 | ((w[1] as u64) << 32)).collect();
        let period_ns = self.ctx.queue.get_timestamp_period() as f64;
        Ok(Stage::ALL
            .into_iter()
            .enumerate()
            .map(|(i, stage)| (stage, ticks[i + 1].saturating_sub(ticks[i]) as f64 * period_ns * 1e-9))
            .collect())
    }

    /// Blocks until the GPU has finished all submitted work.
    pub fn wait(&self) -> Result<(), GpuError> {
        self.ctx.wait()
    }

    /// Draws this pass's samples of the lights whose samples change from
    /// pass to pass (skies, area lights, emissive meshes), so that the
    /// progressive mean of their shadows converges (`GpuLights::sampled`):
    /// new shadow views, redrawn, and the direct and specular passes' sample
    /// tables rewritten; and, in a scene with BLEND surfaces, redraws the
    /// views with this pass's choice of their fragments. Nothing is redone
    /// while the pass stays the same (a moving camera, the viewer without
    /// converging).
    fn resample_lights(&self) {
        let (pass, n) = (self.settings.pass.max(1), self.settings.area_light_samples);
        if pass != self.light_pass.get() && self.light_source.varies_per_pass(n) {
            let lights = GpuLights::sampled(&self.light_source, n, pass);
            let queue = &self.ctx.queue;
            // The same lights: the same number of views, so the maps are rewritten in place.
            if self.targets.shadow_maps.update(queue, &lights, self.bounds) {
                self.direct_pass.set_samples(queue, &self.direct_binding, &lights);
                self.specular_pass.set_light_samples(queue, &lights);
                self.shadows_drawn.set(false);
                self.light_pass.set(pass);
                // `update` wrote the views' seeds too.
                self.blend_pass.set(0);
            }
        }
        if self.has_blend && pass != self.blend_pass.replace(pass) {
            self.targets.shadow_maps.set_blend_seed(&self.ctx.queue, pass);
            self.shadows_drawn.set(false);
        }
    }

    fn record_stage(&self, stage: Stage, encoder: &mut wgpu::CommandEncoder) {
        let queue = &self.ctx.queue;
        let lod = self.settings.lod.as_ref();
        let splat = |encoder: &mut wgpu::CommandEncoder,
                     binding: &SplatBinding,
                     output: &LodOutput,
                     estimate: &FixedRadius,
                     target: &wgpu::Texture| {
            self.lod_pass.record(queue, encoder, output, self.camera_position, lod);
            let params = self.splat_params(estimate);
            match self.settings.estimator {
                Estimator::Raster => {
                    let view = target.create_view(&Default::default());
                    self.splat_pass.record(queue, encoder, binding, output, &params, &view, true);
                }
                Estimator::Tiled => {
                    let map = if std::ptr::eq(target, &self.targets.indirect) { 0 } else { 1 };
                    self.record_tiled(encoder, map, &params);
                }
            }
        };
        match stage {
            Stage::GBuffer => {
                let params = GBufferParams {
                    clip_from_world: self.clip_from_world.to_cols_array_2d(),
                    camera_position: self.camera_position.to_array(),
                    blend_seed: self.settings.pass,
                };
                let t = &self.targets;
                self.gbuffer_pass.record(queue, encoder, &self.scene, &self.gbuffer_binding, &params, &t.gbuffer);
                self.depth_tiles.record(queue, encoder, self.clip_from_world);
            }
            Stage::Shadows => {
                self.resample_lights();
                if !self.shadows_drawn.replace(true) {
                    self.shadow_pass.record(encoder, &self.scene, &self.shadow_scene, &self.targets.shadow_maps)
                }
            }
            Stage::OpticalDepth => self.media.record(encoder),
            Stage::Direct => {
                let view = self.targets.direct.create_view(&Default::default());
                self.direct_pass.record(&self.ctx.queue, encoder, &self.direct_binding, self.settings.pass, &view);
            }
            Stage::GlobalSplat => {
                splat(encoder, &self.global_splat, &self.global_lod, &self.settings.global, &self.targets.indirect)
            }
            Stage::CausticSplat => {
                splat(encoder, &self.caustic_splat, &self.caustic_lod, &self.settings.caustic, &self.targets.caustic)
            }
            Stage::VolumeSplat => {
                // Without media the target is only cleared: the resolve reads it.
                if self.has_media {
                    self.lod_pass.record(&self.ctx.queue, encoder, &self.volume_lod, self.camera_position, lod);
                }
                if self.has_media && self.settings.estimator == Estimator::Tiled {
                    let params = SplatParams {
                        radius: self.settings.volume_radius,
                        normal_test: 0,
                        ..self.splat_params(&self.settings.global)
                    };
                    self.record_tiled(encoder, 2, &params);
                    return;
                }
                let view = self.targets.volume.create_view(&Default::default());
                let photons = if self.has_media { &self.volume_lod } else { &self.caustic_lod };
                self.volume_pass.record(encoder, photons, &view, self.has_media);
            }
            Stage::Specular => self.specular_pass.record(&self.ctx.queue, encoder, self.settings.pass),
            Stage::Resolve => self.resolve_pass.record(queue, encoder, &self.settings.terms),
        }
    }

    /// Draws the photons of the last frame (`render` first) as points into
    /// the points view's target, and returns it. The pass is made on first
    /// use and kept.
    pub fn draw_points(&self, colors: crate::points::PointColors) -> Result<&wgpu::Texture, GpuError> {
        let scopes = self.ctx.error_scopes();
        let pass = self.points.get_or_init(|| crate::points::PointsPass::new(&self.ctx.device, &self.targets.gbuffer));
        let mut encoder = self.ctx.device.create_command_encoder(&Default::default());
        let volume = self.has_media.then_some(&self.volume_lod);
        pass.record(
            &self.ctx.queue,
            &mut encoder,
            [Some(&self.global_lod), Some(&self.caustic_lod), volume],
            &self.targets.gbuffer,
            self.clip_from_world,
            self.camera_position,
            colors,
        );
        self.ctx.queue.submit([encoder.finish()]);
        scopes.finish()?;
        Ok(&pass.target)
    }

    /// The specular pass's radiance target.
    pub fn specular_output(&self) -> &wgpu::Texture {
        &self.specular_pass.output
    }

    /// Photons drawn in the last frame by the global and caustic splats.
    pub fn drawn_photons(&self) -> Result<(u32, u32), GpuError> {
        let count = |o: &LodOutput| crate::readback::read_u32s(&self.ctx, &o.draw_args, 4).map(|v| v[1]);
        Ok((count(&self.global_lod)?, count(&self.caustic_lod)?))
    }

    /// The global map's splat instances of the last frame, in draw order.
    pub fn global_survivors(&self) -> Result<Vec<crate::photons::LodPhoton>, GpuError> {
        let drawn = crate::readback::read_u32s(&self.ctx, &self.global_lod.draw_args, 4)?[1] as u64;
        let words = crate::readback::read_u32s(&self.ctx, &self.global_lod.survivors, drawn.max(1) * 6)?;
        Ok(bytemuck::cast_slice::<u32, crate::photons::LodPhoton>(&words)[..drawn as usize].to_vec())
    }

    /// Volume photons drawn in the last frame.
    pub fn drawn_volume_photons(&self) -> Result<u32, GpuError> {
        crate::readback::read_u32s(&self.ctx, &self.volume_lod.draw_args, 4).map(|v| v[1])
    }

    /// The regions' optical-depth slices, layer by layer.
    pub fn read_slices(&self) -> Result<Vec<Vec<Vec4>>, GpuError> {
        let mut layers = crate::readback::read_rgba_layers(&self.ctx, &self.media.slices)?;
        layers.truncate(self.media.params.slices.max(1) as usize);
        Ok(layers)
    }

    /// The media parameters the passes see.
    pub fn media_params(&self) -> &crate::media::MediaParams {
        &self.media.params
    }

    pub fn read(&self, texture: &wgpu::Texture) -> Result<Vec<Vec4>, GpuError> {
        read_rgba(&self.ctx, texture)
    }

    /// Reads the resolved frame back as one image. Non-finite values are
    /// dropped (counted in the second value), so they never reach a file.
    pub fn read_image(&self) -> Result<(Image, u64), GpuError> {
        let resolved = self.read(&self.resolve_pass.output)?;
        let t = &self.targets;
        let mut image = Image::new(t.gbuffer.width, t.gbuffer.height);
        let mut nonfinite = 0;
        for (pixel, value) in image.pixels.iter_mut().zip(&resolved) {
            let v = value.truncate();
            if v.is_finite() {
                *pixel = v;
            } else {
                nonfinite += 1;
            }
        }
        Ok((image, nonfinite))
    }
}

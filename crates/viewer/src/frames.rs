//! The viewer's frame loop, once for the window and the web page: what a
//! frame keeps from the last (the renderer of the photon set on screen, the
//! running mean of its frames, the panel values the renderer was last
//! given) and the steps of a frame:
//!
//! 1. `wants_photons`: whether to ask the tracer for a set (the pose moved,
//!    or nothing is pending and one more set of the pose on screen lets the
//!    mean converge);
//! 2. `update`: the camera, the panel's edits and a new set applied to the
//!    renderer, which says whether the frame is to be rendered;
//! 3. the front end renders (the window blocks, the page awaits);
//! 4. `accumulate`: the frame added to the mean;
//! 5. `present`: the mean (or a debug view) drawn with the panel.
//!
//! Each front end keeps only its event loop, its photon tracer (a thread,
//! a task), its frame pacing and its error checks.

use crate::panel::{Controls, Panel, Readouts};
use crate::photon_set::PhotonSet;
use crate::settings::{gpu_settings, restart_for_edits, set_pass};
use crate::surface::shown_texture;
use hikari_core::camera::Camera;
use hikari_core::scene::{Pose, Scene};
use hikari_gpu::accumulate::AccumulatePass;
use hikari_gpu::present::PresentPass;
use hikari_gpu::{GpuContext, GpuError, GpuRenderer};
use std::rc::Rc;
use winit::window::Window;

/// Whether to ask the tracer for a set: the pose or the photon count
/// differ from what was `requested` last, or the set on screen is the
/// newest asked for (nothing pending: one more set of the same pose, with
/// a new seed, to converge).
pub fn wants_photons(requested: Option<&(Pose, u64)>, pose: &Pose, photons: u64, shown_is_newest: bool) -> bool {
    let changed = requested.is_none_or(|(p, n)| p != pose || *n != photons);
    changed || shown_is_newest
}

/// What `Frames::update` did.
#[derive(Debug, Default)]
pub struct Update {
    /// The frame is to be rendered: the camera moved, an edit restarted
    /// the mean, a new set is drawn, or the mean is empty.
    pub render: bool,
    /// The new set is the one on screen now.
    pub drew_new_set: bool,
    /// A set the adapter cannot hold (checked before anything changed):
    /// its photon count and why. The last set stays on screen; the front
    /// end asks for smaller ones.
    pub refused: Option<(u64, String)>,
    /// Seconds the new set's upload took on this thread, and whether it
    /// came in a new pose (`GpuRenderer::set_scene`: the posed scene and
    /// the photons) or the one shown (`set_photons`: the photons alone).
    pub upload: Option<(f64, Posed)>,
}

/// Whether a photon set's pose was on screen before ([`Update::upload`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Posed {
    Before,
    Anew,
}

/// What a viewer's frames keep between them.
pub struct Frames {
    /// Shared with a frame in flight on the page (which awaits its
    /// render); only `Frames` changes it, between frames.
    renderer: Rc<GpuRenderer>,
    /// The mean of the frames since the camera, the scene or an edit that
    /// restarts it last changed.
    pub mean: AccumulatePass,
    shown: PhotonSet,
    /// The panel's values the renderer was last given.
    applied: Controls,
}

impl Frames {
    /// Frames of `set` seen through `camera` (its size is the frames'),
    /// with the panel's `controls`; fills the read-outs that come from the
    /// scene (its size, media, lights and objects).
    pub fn new(
        ctx: GpuContext,
        set: PhotonSet,
        camera: Camera,
        controls: &Controls,
        readouts: &mut Readouts,
    ) -> Result<Self, GpuError> {
        let renderer = renderer_for(ctx, &set, camera, controls, readouts)?;
        let mean = AccumulatePass::new(&renderer.ctx.device, renderer.resolved());
        Ok(Frames { renderer: Rc::new(renderer), mean, shown: set, applied: controls.clone() })
    }

    /// The renderer, to render a frame with.
    pub fn renderer(&self) -> &GpuRenderer {
        &self.renderer
    }

    /// The renderer, for a frame that renders without holding the frames
    /// (the page awaits its render while input goes on). Drop it before
    /// the next `update`.
    pub fn shared_renderer(&self) -> Rc<GpuRenderer> {
        self.renderer.clone()
    }

    /// The photon set on screen, with the posed scene it was traced in.
    pub fn shown(&self) -> &PhotonSet {
        &self.shown
    }

    /// The panel's values the renderer was last given.
    pub fn applied(&self) -> &Controls {
        &self.applied
    }

    /// The renderer made anew for frames through `camera` (a new size),
    /// the mean started over.
    pub fn resize(&mut self, camera: Camera, readouts: &mut Readouts) -> Result<(), GpuError> {
        let ctx = self.renderer.ctx.clone();
        // The old renderer lives until the new one is made (a frame in
        // flight on the page may hold it): both sets of targets, briefly.
        self.renderer = Rc::new(renderer_for(ctx.clone(), &self.shown, camera.clone(), &self.applied, readouts)?);
        self.mean = AccumulatePass::new(&ctx.device, self.renderer.resolved());
        Ok(())
    }

    /// Applies what changed since the last frame: the camera (its size
    /// unchanged; see `resize`), the panel's `controls` and `new_set`, if
    /// one came. See `Update`.
    pub fn update(
        &mut self,
        camera: &Camera,
        controls: &Controls,
        new_set: Option<PhotonSet>,
        readouts: &mut Readouts,
    ) -> Result<Update, GpuError> {
        if controls.volume_slices != self.applied.volume_slices {
            // The slices size the renderer's targets.
            self.applied.volume_slices = controls.volume_slices;
            let current = self.renderer.camera().clone();
            self.resize(current, readouts)?;
        }
        // Fields borrowed one by one: the renderer changes beside the set on screen.
        let Frames { renderer, mean, shown, applied } = self;
        let renderer = Rc::get_mut(renderer).expect("no frame holds the renderer between frames");
        let moved = camera.position != renderer.camera().position || camera.look_at != renderer.camera().look_at;
        if moved {
            renderer.set_camera(camera)?;
        }
        let mut restart = false;
        if let Some(radii_changed) = restart_for_edits(renderer, controls, applied) {
            if radii_changed && new_set.is_none() {
                // The specular pass's photon grids are cells of the radii.
                renderer.set_photons(&shown.scene, &shown.traced)?;
            }
            restart = true;
        }
        if moved || restart {
            mean.reset();
        }
        if controls != applied {
            *applied = controls.clone();
        }
        let mut update = Update::default();
        if let Some(set) = new_set {
            let same_scene = shown.pose == set.pose;
            // The frame this set draws is pass k of the mean (k = 1 after
            // any change): progressive radii and a sub-pixel jitter for
            // pass k, so the mean converges as `render --passes` does
            // (docs/progressive.md).
            let pass = if same_scene { mean.count() + 1 } else { 1 };
            set_pass(renderer, controls, pass)?;
            let start = web_time::Instant::now();
            let result = if same_scene {
                renderer.set_photons(&set.scene, &set.traced)
            } else {
                renderer.set_scene(&set.scene, &set.traced)
            };
            let posed = if same_scene { Posed::Before } else { Posed::Anew };
            update.upload = Some((start.elapsed().as_secs_f64(), posed));
            match result {
                Ok(()) => {
                    if !same_scene {
                        mean.reset();
                    }
                    *shown = set;
                    update.drew_new_set = true;
                }
                Err(GpuError::TooLarge(why)) => update.refused = Some((set.photons, why)),
                Err(e) => return Err(e),
            }
        }
        update.render = moved || restart || update.drew_new_set || mean.count() == 0;
        Ok(update)
    }

    /// Adds the frame just rendered to the mean. Its noise estimate is
    /// unknown again after a restart.
    pub fn accumulate(&mut self, readouts: &mut Readouts) {
        let ctx = &self.renderer.ctx;
        let mut encoder = ctx.device.create_command_encoder(&Default::default());
        self.mean.record(&ctx.queue, &mut encoder);
        ctx.queue.submit([encoder.finish()]);
        if self.mean.count() == 1 {
            readouts.noise = None;
        }
    }

    /// Draws the mean (or the panel's debug view) into `frame` at the
    /// panel's exposure, the panel over it with the front end's own
    /// `widgets` at its top, and presents it.
    #[allow(clippy::too_many_arguments)]
    pub fn present(
        &self,
        frame: wgpu::SurfaceTexture,
        present: &mut PresentPass,
        panel: &mut Panel,
        window: &Window,
        controls: &mut Controls,
        readouts: &mut Readouts,
        widgets: impl FnOnce(&mut egui::Ui),
    ) -> Result<(), GpuError> {
        self.draw(&frame.texture, present, panel, window, controls, readouts, widgets)?;
        window.pre_present_notify();
        self.renderer.ctx.queue.present(frame);
        Ok(())
    }

    /// As `present`, into `target` (of `present`'s format), not presented.
    #[allow(clippy::too_many_arguments)]
    pub fn draw(
        &self,
        target: &wgpu::Texture,
        present: &mut PresentPass,
        panel: &mut Panel,
        window: &Window,
        controls: &mut Controls,
        readouts: &mut Readouts,
        widgets: impl FnOnce(&mut egui::Ui),
    ) -> Result<(), GpuError> {
        let ctx = &self.renderer.ctx;
        let size = [target.width(), target.height()];
        let target = target.create_view(&Default::default());
        let mut encoder = ctx.device.create_command_encoder(&Default::default());
        let shown = shown_texture(controls.mode, &self.renderer, &self.mean)?;
        present.record(&ctx.device, &ctx.queue, &mut encoder, shown, &target, controls.exposure, controls.mode);
        readouts.frames_in_mean = self.mean.count();
        panel.draw(window, &ctx.device, &ctx.queue, &mut encoder, &target, size, controls, readouts, widgets);
        ctx.queue.submit([encoder.finish()]);
        Ok(())
    }
}

/// A renderer of `set` through `camera` with the panel's `controls`; the
/// read-outs that come from the scene filled in.
fn renderer_for(
    ctx: GpuContext,
    set: &PhotonSet,
    camera: Camera,
    controls: &Controls,
    readouts: &mut Readouts,
) -> Result<GpuRenderer, GpuError> {
    let mut scene = Scene::clone(&set.scene);
    scene.camera = camera;
    let r = readouts;
    r.diagonal = scene.diagonal();
    r.has_media = !scene.media.is_empty();
    r.has_regions = hikari_gpu::media::GpuMedia::has_regions(&scene);
    r.light_names = scene.names.lights.clone();
    r.objects = scene.names.objects.clone();
    let settings = gpu_settings(&scene, controls, &ctx);
    let mut renderer = GpuRenderer::new(ctx, &scene, &set.traced, settings)?;
    set_pass(&mut renderer, controls, 1)?;
    Ok(renderer)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn pose(time: f32) -> Pose {
        Pose { time, lights: Vec::new(), offsets: Vec::new() }
    }

    #[test]
    fn photons_asked_for_when_the_pose_or_count_change_or_nothing_is_pending() {
        let asked = (pose(0.0), 1000);
        // Nothing asked yet.
        assert!(wants_photons(None, &pose(0.0), 1000, false));
        // A set of this pose and count is pending: wait for it.
        assert!(!wants_photons(Some(&asked), &pose(0.0), 1000, false));
        // The set on screen is the newest: one more, to converge.
        assert!(wants_photons(Some(&asked), &pose(0.0), 1000, true));
        // The pose moved or the count changed: a set of the new one.
        assert!(wants_photons(Some(&asked), &pose(0.5), 1000, false));
        assert!(wants_photons(Some(&asked), &pose(0.0), 2000, false));
    }
}

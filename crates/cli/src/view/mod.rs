//! `hikari view`: the GPU renderer in a window, drawn straight to the
//! swapchain, with an orbiting camera, moving lights and objects.
//!
//! A moved camera only updates the passes' uniforms
//! (`GpuRenderer::set_camera`). Photons come from a background thread
//! (`PhotonSets`, all cores) that traces the scene as posed now: the time
//! of its animations and the panel's edits of lights and named objects.
//! When the pose changes, the window keeps drawing the last complete set,
//! in the scene it was traced in, until the new one arrives
//! (`GpuRenderer::set_scene`): a frame never waits for tracing. While
//! nothing moves, fresh sets (new seeds) keep coming and the window shows
//! the running mean of their frames (`AccumulatePass`), so the noise falls
//! as you look; any change starts the mean over. With `--frames N` every
//! frame waits for the set of its own pose, and the animation advances
//! `--step` seconds per frame, so runs are reproducible.
//!
//! Controls: left drag orbits, middle or shift + left drag pans, the wheel
//! zooms; right drag turns in place and WASD/QE fly (the wheel sets the
//! flying speed while the right button is held); Home resets the camera, C
//! prints it as a `[camera]` table, T prints the passes' GPU times, Space
//! pauses the animations, F12 writes a PNG and an EXR of the frame, F1
//! hides the panel, Escape quits.
//!
//! The panel (egui) shows the frame rate, per-pass GPU times, photon counts
//! and tracing rate, and edits the image's terms, the radii, LOD,
//! exposure, photons per set ("trace every frame" sizes them to keep up
//! with the frame rate), the lights (position, direction, colour,
//! strength), named objects' positions and debug views (G-buffer normals,
//! albedo). Exposure and views take effect on the next frame; terms, radii
//! and LOD restart the mean (radii rebuild the specular pass's photon
//! grids; no photons are re-traced); photon counts, lights and objects
//! re-trace.
//!
//! A scene file is watched: saving it reloads the scene (the camera kept);
//! a file with an error prints it (`FILE:LINE:COLUMN`, also in the title
//! and the panel) and the last good scene stays on screen.

mod photon_sets;
mod scene_watch;
mod trace_budget;

use crate::render_cmd::{MAX_PHOTONS, Resolution, UsageError, load_scene, parse_resolution, parse_time};
use anyhow::{Result, anyhow};
use clap::Args;
use glam::Vec3;
use hikari_core::output::write_image;
use hikari_core::scene::{Pose, Scene, builtin};
use hikari_engine::tracer::{PhotonTracer, TraceDevice};
use hikari_gpu::GpuContext;
use hikari_gpu::present::PresentPass;
use hikari_viewer::clock::AnimationClock;
use hikari_viewer::frame_stats::FrameStats;
use hikari_viewer::frames::Posed;
use hikari_viewer::frames::{Frames, wants_photons};
use hikari_viewer::orbit::Orbit;
use hikari_viewer::panel::{Controls, Panel, Readouts};
use hikari_viewer::settings::controls_for_scene;
use hikari_viewer::surface::next_frame;
use photon_sets::{Job, PhotonSet, PhotonSets};
use scene_watch::SceneWatch;
use std::path::PathBuf;
use std::sync::Arc;
use std::time::Instant;
use trace_budget::TraceBudget;
use winit::application::ApplicationHandler;
use winit::dpi::{PhysicalPosition, PhysicalSize};
use winit::event::{ElementState, MouseButton, MouseScrollDelta, WindowEvent};
use winit::event_loop::{ActiveEventLoop, EventLoop};
use winit::keyboard::{Key, NamedKey};
use winit::window::{Window, WindowId};

#[derive(Args, Debug)]
pub struct ViewArgs {
    /// A built-in scene name (see `hikari scenes`), a path to a .toml scene
    /// file, or a glTF 2.0 file (.glb, or .gltf with its buffers).
    #[arg(default_value = builtin::DEFAULT)]
    pub scene: String,
    /// Photon paths per photon set (1 to 100,000,000).
    #[arg(long, default_value_t = 200_000, value_parser = clap::value_parser!(u64).range(1..=MAX_PHOTONS))]
    pub photons: u64,
    /// Random seed of the first photon set (set k uses seed + k).
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// Exposure in stops (-64 to 64).
    #[arg(long, default_value_t = 0.0, allow_negative_numbers = true)]
    pub exposure: f32,
    /// Window size in pixels, e.g. 1280x720, or 1280 (or x720) to keep the
    /// camera's aspect ratio [default: the scene's resolution].
    #[arg(long, value_parser = parse_resolution)]
    pub size: Option<Resolution>,
    /// The camera of a glTF file to start from, by name [default: the first
    /// perspective camera; without one, a camera framing the scene].
    #[arg(long)]
    pub camera: Option<String>,
    /// Light the scene by this equirectangular sky image (.hdr or .exr,
    /// Blender's orientation) in place of its environment.
    #[arg(long, value_name = "FILE")]
    pub environment: Option<std::path::PathBuf>,
    /// Quit after this many frames (for tests and benchmarks).
    #[arg(long, value_parser = clap::value_parser!(u64).range(1..))]
    pub frames: Option<u64>,
    /// Write the last frame to this .png or .exr on exit.
    #[arg(long)]
    pub screenshot: Option<PathBuf>,
    /// The animations' time at the first frame, in seconds (0 to 1,000,000).
    #[arg(long, default_value_t = 0.0, value_parser = parse_time, allow_negative_numbers = true)]
    pub at: f32,
    /// With --frames: seconds of animation per frame (0: the scene stands
    /// still and the frames converge).
    #[arg(long, default_value_t = 0.0, requires = "frames", value_parser = parse_time)]
    pub step: f32,
    /// Size each photon set so that tracing keeps up with the frame rate
    /// (--photons is the first set's count).
    #[arg(long)]
    pub trace_every_frame: bool,
    /// Where photon sets are traced: auto is the GPU on a hardware adapter
    /// and the CPU on a software one (as `hikari render --trace`).
    #[arg(long, value_enum, default_value_t = TraceDevice::Auto)]
    pub trace: TraceDevice,
    /// No progress bars.
    #[arg(short, long)]
    pub quiet: bool,
}

pub fn run(args: ViewArgs) -> Result<()> {
    if !(args.exposure.abs() <= 64.0) {
        return Err(UsageError(format!("--exposure {}: must be between -64 and 64 stops", args.exposure)).into());
    }
    if let Some(path) = &args.screenshot {
        let ext = path.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase);
        if !matches!(ext.as_deref(), Some("png" | "exr")) {
            return Err(UsageError(format!("{}: unsupported image type (use .png or .exr)", path.display())).into());
        }
    }
    let scene = load_scene(&args.scene, args.camera.as_deref(), args.environment.as_deref(), false)?;
    if let Some(size) = args.size {
        size.resolve(scene.camera.aspect()).map_err(UsageError)?;
    }
    let event_loop = EventLoop::new()
        .map_err(|e| anyhow!("cannot open a window ({e}); `hikari render` writes an image without one"))?;
    let mut viewer = Viewer::new(args, scene);
    event_loop.run_app(&mut viewer).map_err(|e| anyhow!("the window's event loop failed: {e}"))?;
    if let Some(error) = viewer.error.take() {
        return Err(error);
    }
    viewer.summary();
    Ok(())
}

/// What exists once the window does.
struct Session {
    window: Arc<Window>,
    surface: wgpu::Surface<'static>,
    config: wgpu::SurfaceConfiguration,
    /// The renderer of the set on screen and the mean of its frames.
    frames: Frames,
    present: PresentPass,
    panel: Panel,
}

struct Viewer {
    args: ViewArgs,
    /// The scene as loaded (poses are made from it).
    base: Arc<Scene>,
    orbit: Orbit,
    /// The background tracer, and the pose and count last asked of it.
    photon_sets: Option<PhotonSets>,
    requested: Option<(Pose, u64)>,
    clock: AnimationClock,
    budget: TraceBudget,
    /// Photon sets drawn so far; seconds spent tracing the ones received.
    sets_used: u64,
    trace_seconds: f64,
    first_trace_seconds: f64,
    /// Seconds each new pose took to make (`PhotonSet::pose_seconds`), and
    /// each set to upload in a new pose and in the pose shown
    /// (`Update::upload`).
    pose_seconds: Vec<f64>,
    upload_seconds: [Vec<f64>; 2],
    session: Option<Session>,
    error: Option<anyhow::Error>,
    stats: FrameStats,
    last_frame: Option<Instant>,
    started: Option<Instant>,
    /// When the camera was last moved and the move is not on screen yet.
    pending_camera: Option<Instant>,
    camera_latencies: Vec<f64>,
    /// Pose requests (number, when) whose set is not on screen yet, and
    /// the latency of each that reached it.
    pending_poses: Vec<(u64, Instant)>,
    pose_latencies: Vec<f64>,
    cursor: PhysicalPosition<f64>,
    dragging: Option<MouseButton>,
    shift: bool,
    /// Fly keys held (W, S, D, A, E, Q) and the flying speed (scene units/s).
    flying: [bool; 6],
    fly_speed: f32,
    /// When the fly keys were last applied.
    last_fly: Option<Instant>,
    /// Saves of the scene file.
    watch: SceneWatch,
    /// The error of the last reload that failed, shown in the title.
    reload_error: Option<String>,
    /// What the panel edits.
    controls: Controls,
    readouts: Readouts,
    last_timing: Option<Instant>,
    screenshots: u32,
    title_updated: Option<Instant>,
}

/// The panel's starting values for `scene` (its lights and objects unedited).
fn controls_for(scene: &Scene, args: &ViewArgs) -> Controls {
    controls_for_scene(scene, args.exposure, args.photons, args.trace_every_frame)
}

impl Viewer {
    fn new(args: ViewArgs, scene: Scene) -> Self {
        let fly_speed = 0.25 * scene.diagonal();
        let controls = controls_for(&scene, &args);
        let watch = SceneWatch::new(&args.scene);
        let clock = AnimationClock::new(args.at, args.frames.map(|_| args.step));
        Viewer {
            watch,
            orbit: Orbit::new(&scene.camera),
            base: Arc::new(scene),
            photon_sets: None,
            requested: None,
            clock,
            budget: TraceBudget::default(),
            sets_used: 0,
            trace_seconds: 0.0,
            first_trace_seconds: 0.0,
            pose_seconds: Vec::new(),
            upload_seconds: [Vec::new(), Vec::new()],
            session: None,
            error: None,
            stats: FrameStats::default(),
            last_frame: None,
            started: None,
            pending_camera: None,
            camera_latencies: Vec::new(),
            pending_poses: Vec::new(),
            pose_latencies: Vec::new(),
            cursor: PhysicalPosition::new(0.0, 0.0),
            dragging: None,
            shift: false,
            flying: [false; 6],
            fly_speed,
            last_fly: None,
            reload_error: None,
            controls,
            readouts: Readouts::default(),
            last_timing: None,
            screenshots: 0,
            title_updated: None,
            args,
        }
    }

    fn fail(&mut self, event_loop: &ActiveEventLoop, error: anyhow::Error) {
        self.error.get_or_insert(error);
        event_loop.exit();
    }

    /// The pose the panel and the clock ask for now.
    fn pose(&self) -> Pose {
        Pose {
            time: if self.base.is_animated() { self.clock.time() } else { 0.0 },
            lights: self.controls.lights.clone(),
            offsets: self.controls.offsets.clone(),
        }
    }

    /// Starts the tracing thread for the scene as loaded and waits for its
    /// first set (the scene at the clock's time), the first on screen.
    fn start_tracing(&mut self) -> Result<PhotonSet> {
        // The tracer opens its own device: tracing runs beside the frames.
        let ctx = match self.args.trace {
            TraceDevice::Cpu => None,
            _ => GpuContext::new().ok(),
        };
        let tracer = PhotonTracer::choose(self.args.trace, ctx.as_ref(), &self.base, hikari_engine::Log::stderr());
        let device = tracer.device();
        self.photon_sets = Some(PhotonSets::start(self.base.clone(), tracer)?);
        self.requested = None;
        self.pending_poses.clear();
        if !self.args.quiet {
            eprintln!("view: tracing {} photon paths on the {device}", self.controls.photons);
        }
        self.request(self.pose())?;
        let first = self.photon_sets.as_mut().expect("started").next(true)?.expect("the first set");
        self.first_trace_seconds = first.seconds;
        self.received(&first);
        self.sets_used = 1;
        Ok(first)
    }

    /// Asks for a set of `pose` with the panel's photon count.
    fn request(&mut self, pose: Pose) -> Result<()> {
        let Some(sets) = &mut self.photon_sets else { return Ok(()) };
        let photons = if self.controls.trace_every_frame {
            self.budget.photons(self.controls.photons)
        } else {
            self.controls.photons.min(self.budget.cap)
        };
        self.controls.photons = photons;
        let seed = self.args.seed.wrapping_add(sets.newest().map_or(0, |n| n + 1));
        let id = sets.request(Job { pose: pose.clone(), photons, seed })?;
        let changed = self.requested.as_ref().is_some_and(|(p, _)| *p != pose);
        if changed {
            self.pending_poses.push((id, Instant::now()));
        }
        self.requested = Some((pose, photons));
        Ok(())
    }

    fn received(&mut self, set: &PhotonSet) {
        self.budget.traced(set.photons, set.seconds);
        self.trace_seconds += set.seconds;
        if set.pose_seconds > 0.0 {
            self.pose_seconds.push(set.pose_seconds);
        }
        self.readouts.trace_ms = set.seconds * 1e3;
        self.readouts.photons_per_set = set.photons;
        self.readouts.stored = [set.traced.indirect().len(), set.traced.caustic.len(), set.traced.volume.len()];
    }

    /// Opens the window, finds an adapter that can present to it, traces
    /// the first photon set and builds the renderer.
    fn open(&mut self, event_loop: &ActiveEventLoop) -> Result<Session> {
        let camera = &self.base.camera;
        let (width, height) = match self.args.size {
            // Checked when the viewer started.
            Some(size) => size.resolve(camera.aspect()).unwrap_or((camera.width, camera.height)),
            None => (camera.width, camera.height),
        };
        let attributes = Window::default_attributes()
            .with_title(format!("hikari view — {}", self.args.scene))
            .with_inner_size(PhysicalSize::new(width, height));
        let window = Arc::new(event_loop.create_window(attributes).map_err(|e| anyhow!("cannot open a window: {e}"))?);
        let instance = wgpu::Instance::new(wgpu::InstanceDescriptor::new_with_display_handle_from_env(Box::new(
            event_loop.owned_display_handle(),
        )));
        let surface = instance.create_surface(window.clone()).map_err(|e| anyhow!("cannot draw in the window: {e}"))?;
        let ctx = GpuContext::for_surface(&instance, &surface)
            .map_err(|e| anyhow!("{e}; `hikari render` renders without a usable GPU"))?;
        let size = window.inner_size();
        let (width, height) = (size.width.max(1), size.height.max(1));
        let format = surface.get_capabilities(&ctx.adapter).formats.first().copied().ok_or_else(|| {
            anyhow!("the window offers no surface format on {}; `hikari render` writes an image", ctx.describe())
        })?;
        let config = hikari_viewer::surface::surface_config(format, width, height);
        ctx.scoped(|| surface.configure(&ctx.device, &config))?;
        self.clock.tick(Instant::now());
        let first = self.start_tracing()?;
        eprintln!("view: {} on {}", self.args.scene, ctx.describe());
        for note in hikari_gpu::renderer::adapter_notes(&ctx, &self.base) {
            eprintln!("view: {note}");
        }
        let present = PresentPass::new(&ctx.device, format);
        let panel = Panel::new(&window, &ctx.device, format);
        self.readouts.adapter = ctx.describe();
        let camera = self.orbit.camera(width, height);
        let frames = Frames::new(ctx, first, camera, &self.controls, &mut self.readouts)?;
        Ok(Session { window, surface, config, frames, present, panel })
    }

    /// Reloads the scene file when it changed (checked four times a second).
    fn watch(&mut self) -> Result<()> {
        if !self.watch.changed() {
            return Ok(());
        }
        let options = hikari_core::scene::LoadOptions {
            camera: self.args.camera.clone(),
            environment: self.args.environment.clone(),
        };
        let scene = match Scene::load_with(&self.args.scene, &options) {
            Ok(scene) => scene,
            Err(e) => {
                eprintln!("view: {e} (the last good scene stays)");
                self.reload_error = Some(e.to_string());
                self.readouts.reload_error = self.reload_error.clone();
                return Ok(());
            }
        };
        self.reload_error = None;
        self.readouts.reload_error = None;
        let Some(session) = self.session.take() else { return Ok(()) };
        let Session { window, surface, config, frames, present, panel } = session;
        let ctx = frames.renderer().ctx.clone();
        drop(frames);
        // The new scene with the current camera and settings (its own
        // lights and objects, unedited), from a new tracing thread (the old
        // one ends when its channels close).
        let fresh = controls_for(&scene, &self.args);
        (self.controls.lights, self.controls.offsets) = (fresh.lights, fresh.offsets);
        self.base = Arc::new(scene);
        let first = self.start_tracing()?;
        let camera = self.orbit.camera(config.width, config.height);
        let frames = Frames::new(ctx, first, camera, &self.controls, &mut self.readouts)?;
        self.session = Some(Session { window, surface, config, frames, present, panel });
        self.camera_moved();
        eprintln!("view: reloaded {}", self.args.scene);
        Ok(())
    }

    /// Moves the eye for the fly keys held since the last call (each frame
    /// and each fly key's press and release). At most a second counts, so
    /// that a stall (a scene reload) does not throw the eye across the scene.
    fn fly(&mut self) {
        let now = Instant::now();
        let dt = self.last_fly.map_or(0.0, |t| (now - t).as_secs_f32().min(1.0));
        self.last_fly = Some(now);
        let [w, s, d, a, e, q] = self.flying.map(|held| held as i32 as f32);
        if w + s + d + a + e + q == 0.0 {
            return;
        }
        let step = self.fly_speed * dt;
        self.orbit.fly((w - s) * step, (d - a) * step, (e - q) * step);
        self.camera_moved();
    }

    /// Asks the tracer for what this frame needs: the new pose when the
    /// clock or an edit moved anything (or the photon count changed), else
    /// (nothing pending) the next set of the pose on screen, to converge.
    fn ask_for_photons(&mut self) -> Result<()> {
        if self.last_frame.is_none() {
            return Ok(()); // the first frame draws the set the renderer was built with
        }
        let pose = self.pose();
        let idle = match (&self.photon_sets, &self.session) {
            (Some(sets), Some(session)) => sets.newest() == Some(session.frames.shown().id),
            _ => false,
        };
        if wants_photons(self.requested.as_ref(), &pose, self.controls.photons, idle) {
            self.request(pose)
        } else {
            Ok(())
        }
    }

    /// One turn of the frame loop (`hikari_viewer::frames`): renders when
    /// the camera moved, a setting changed or a new photon set came, adds
    /// the frame to the mean, and presents the mean.
    fn frame(&mut self) -> Result<()> {
        self.watch()?;
        self.fly();
        self.clock.playing = self.controls.playing;
        if self.last_frame.is_some() {
            self.clock.tick(Instant::now());
        }
        self.readouts.time = self.base.is_animated().then(|| self.clock.time());
        self.ask_for_photons()?;
        let new_set = match (&mut self.photon_sets, self.last_frame) {
            (Some(sets), Some(_)) => sets.next(self.args.frames.is_some())?,
            _ => None,
        };
        if let Some(sets) = &self.photon_sets {
            self.readouts.photon_sets = sets.received;
        }
        if let Some(set) = &new_set {
            self.received(set);
        }
        let Some(session) = &mut self.session else { return Ok(()) };
        let camera = self.orbit.camera(session.config.width, session.config.height);
        let update = session.frames.update(&camera, &self.controls, new_set, &mut self.readouts)?;
        if update.drew_new_set {
            self.sets_used += 1;
        }
        if let Some((seconds, posed)) = update.upload {
            self.upload_seconds[(posed == Posed::Anew) as usize].push(seconds);
        }
        // A set the adapter cannot hold: the last one stays and sets get smaller.
        if let Some((photons, why)) = update.refused {
            let cap = (photons * 3 / 4).max(1);
            self.budget.cap = cap;
            self.controls.photons = self.controls.photons.min(cap);
            let warning = format!("{why}; photons per set lowered to {cap}");
            eprintln!("view: {warning}");
            self.readouts.warning = Some(warning);
        }
        if update.render {
            let renderer = session.frames.renderer();
            // Every 2 s (panel shown) the frame itself is the timed one.
            let timing_due = session.panel.visible && self.last_timing.is_none_or(|t| t.elapsed().as_secs_f64() > 2.0);
            if timing_due {
                self.last_timing = Some(Instant::now());
                let (times, timestamps) = renderer.render_timed()?;
                self.readouts.passes = times.iter().map(|(stage, t)| (stage.name(), t * 1e3)).collect();
                self.readouts.timestamps = timestamps;
                // What the LOD kept, read back with the timing (a stall every 2 s, not every frame).
                let (global, caustic) = renderer.drawn_photons()?;
                let volume = if self.readouts.has_media { renderer.drawn_volume_photons()? } else { 0 };
                self.readouts.drawn = Some([global, caustic, volume]);
            } else {
                renderer.render()?;
            }
            session.frames.accumulate(&mut self.readouts);
            let mean = &session.frames.mean;
            if mean.count() > 1 && mean.noise_due() {
                self.readouts.noise = mean.read_noise(&session.frames.renderer().ctx)?;
            }
        }
        let ctx = session.frames.renderer().ctx.clone();
        let Some(texture) = next_frame(&session.surface, &ctx.device, &session.config)? else { return Ok(()) };
        let scopes = ctx.error_scopes();
        let (present, panel) = (&mut session.present, &mut session.panel);
        session.frames.present(
            texture,
            present,
            panel,
            &session.window,
            &mut self.controls,
            &mut self.readouts,
            |_| {},
        )?;
        scopes.finish()?;

        let now = Instant::now();
        if let Some(last) = self.last_frame {
            self.stats.push((now - last).as_secs_f64());
            self.budget.frame((now - last).as_secs_f64());
        }
        self.started.get_or_insert(now);
        self.last_frame = Some(now);
        if let Some(edit) = self.pending_camera.take() {
            self.camera_latencies.push((now - edit).as_secs_f64());
        }
        // Pose requests up to the set on screen have reached it.
        let on_screen = session.frames.shown().id;
        let (done, waiting): (Vec<_>, Vec<_>) = self.pending_poses.drain(..).partition(|(id, _)| *id <= on_screen);
        self.pending_poses = waiting;
        self.pose_latencies.extend(done.iter().map(|(_, t)| (now - *t).as_secs_f64()));
        if self.title_updated.is_none_or(|t| (now - t).as_secs_f64() > 0.5) && self.stats.frames() > 0 {
            let fps = self.stats.mean_fps();
            self.readouts.fps = fps;
            let elapsed = self.started.map_or(0.0, |s| (now - s).as_secs_f64());
            self.readouts.sets_per_second =
                if elapsed > 0.0 { self.photon_sets.as_ref().map_or(0, |s| s.received) as f64 / elapsed } else { 0.0 };
            self.readouts.edit_latency_ms = mean(&self.pose_latencies).map(|s| s * 1e3);
            let frames = session.frames.mean.count();
            let error = self.reload_error.as_ref().map_or(String::new(), |e| format!(" — error: {e}"));
            session
                .window
                .set_title(&format!("hikari view — {} — {fps:.1} fps — mean of {frames}{error}", self.args.scene));
            self.title_updated = Some(now);
        }
        Ok(())
    }

    /// Writes the frame on screen (the mean) to `path` (PNG tone-mapped, EXR linear).
    fn screenshot(&self, path: &std::path::Path) -> Result<()> {
        let Some(session) = &self.session else { return Ok(()) };
        let mut image = hikari_core::render::Image::new(session.config.width, session.config.height);
        for (pixel, value) in image.pixels.iter_mut().zip(session.frames.renderer().read(&session.frames.mean.mean)?) {
            let v = value.truncate();
            *pixel = if v.is_finite() { v } else { Vec3::ZERO };
        }
        write_image(path, &image, self.controls.exposure)?;
        eprintln!("view: wrote {}", path.display());
        Ok(())
    }

    fn resize(&mut self, size: PhysicalSize<u32>) -> Result<()> {
        if size.width == 0 || size.height == 0 {
            return Ok(());
        }
        let Some(session) = &mut self.session else { return Ok(()) };
        if (size.width, size.height) == (session.config.width, session.config.height) {
            return Ok(());
        }
        session.config.width = size.width;
        session.config.height = size.height;
        let ctx = session.frames.renderer().ctx.clone();
        session.surface.configure(&ctx.device, &session.config);
        session.frames.resize(self.orbit.camera(size.width, size.height), &mut self.readouts)?;
        Ok(())
    }

    fn summary(&self) {
        let seconds = match (self.started, self.last_frame) {
            (Some(a), Some(b)) => (b - a).as_secs_f64(),
            _ => 0.0,
        };
        let latency = |what: &str, latencies: &[f64], none: &str| match mean(latencies) {
            None => none.to_string(),
            Some(m) => format!("{what} to screen {:.1} ms mean over {}", m * 1e3, latencies.len()),
        };
        let received = self.photon_sets.as_ref().map_or(0, |s| s.received);
        let per_second = if seconds > 0.0 { received as f64 / seconds } else { 0.0 };
        println!(
            "view: {} frames in {seconds:.2} s: mean {:.2} fps, 1% low {:.2} fps; {} photon sets drawn, \
             {received} traced ({per_second:.2}/s, {:.1} ms each, the first {:.1} ms); {}; {}",
            self.stats.frames() + self.last_frame.is_some() as usize,
            self.stats.mean_fps(),
            self.stats.one_percent_low_fps(),
            self.sets_used,
            if self.sets_used > 0 { self.trace_seconds / self.sets_used as f64 * 1e3 } else { 0.0 },
            self.first_trace_seconds * 1e3,
            latency("scene edit", &self.pose_latencies, "no scene edits"),
            latency("camera move", &self.camera_latencies, "no camera moves"),
        );
        // What a moving scene costs per new pose, besides tracing.
        let uploads = |posed: Posed, what: &str| {
            let seconds = &self.upload_seconds[(posed == Posed::Anew) as usize];
            mean(seconds).map(|m| format!("{what} {:.1} ms mean over {}", m * 1e3, seconds.len()))
        };
        let parts: Vec<String> = [
            mean(&self.pose_seconds).map(|m| {
                format!(
                    "posing the scene (animations, deformed meshes, the BVH) {:.1} ms mean over {}",
                    m * 1e3,
                    self.pose_seconds.len()
                )
            }),
            uploads(Posed::Anew, "uploading a set in a new pose"),
            uploads(Posed::Before, "in the pose shown"),
        ]
        .into_iter()
        .flatten()
        .collect();
        if !parts.is_empty() {
            println!("view: {}", parts.join(", "));
        }
    }

    /// The camera moved: the next presented frame shows it.
    fn camera_moved(&mut self) {
        self.pending_camera.get_or_insert_with(Instant::now);
    }

    fn key(&mut self, event_loop: &ActiveEventLoop, key: &Key) -> Result<()> {
        match key {
            Key::Named(NamedKey::Escape) => event_loop.exit(),
            Key::Named(NamedKey::F1) => {
                if let Some(s) = &mut self.session {
                    s.panel.visible = !s.panel.visible;
                }
            }
            Key::Named(NamedKey::Space) => self.controls.playing = !self.controls.playing,
            Key::Named(NamedKey::Home) => {
                self.orbit.reset();
                self.camera_moved();
            }
            Key::Named(NamedKey::F12) => {
                self.screenshots += 1;
                for ext in ["png", "exr"] {
                    self.screenshot(&PathBuf::from(format!("hikari-view-{}.{ext}", self.screenshots)))?;
                }
            }
            Key::Character(c) if c.eq_ignore_ascii_case("t") => {
                if let Some(s) = &self.session {
                    let (times, timestamps) = s.frames.renderer().render_timed()?;
                    let parts: Vec<String> =
                        times.iter().map(|(stage, t)| format!("{} {:.2} ms", stage.name(), t * 1e3)).collect();
                    let how = if timestamps { "GPU timestamps" } else { "wall clock" };
                    println!("view: per pass ({how}): {}", parts.join(", "));
                }
            }
            Key::Character(c) if c.eq_ignore_ascii_case("c") => {
                if let Some(s) = &self.session {
                    println!("{}", self.orbit.toml(s.config.width, s.config.height));
                }
            }
            _ => {}
        }
        Ok(())
    }
}

fn mean(values: &[f64]) -> Option<f64> {
    (!values.is_empty()).then(|| values.iter().sum::<f64>() / values.len() as f64)
}

impl ApplicationHandler for Viewer {
    fn resumed(&mut self, event_loop: &ActiveEventLoop) {
        if self.session.is_some() {
            return;
        }
        match self.open(event_loop) {
            Ok(session) => {
                session.window.request_redraw();
                self.session = Some(session);
            }
            Err(e) => self.fail(event_loop, e),
        }
    }

    fn window_event(&mut self, event_loop: &ActiveEventLoop, _: WindowId, event: WindowEvent) {
        let input = matches!(
            event,
            WindowEvent::MouseInput { .. }
                | WindowEvent::CursorMoved { .. }
                | WindowEvent::MouseWheel { .. }
                | WindowEvent::KeyboardInput { .. }
        );
        if let Some(session) = &mut self.session {
            let used = session.panel.on_event(&session.window, &event);
            if used && input {
                if let WindowEvent::CursorMoved { position, .. } = event {
                    self.cursor = position;
                }
                return;
            }
        }
        let result = match event {
            WindowEvent::CloseRequested => {
                event_loop.exit();
                Ok(())
            }
            WindowEvent::Resized(size) => self.resize(size),
            WindowEvent::RedrawRequested => self.frame().and_then(|()| {
                let done = self.args.frames.is_some_and(|n| self.stats.frames() as u64 + 1 >= n);
                if done {
                    if let Some(path) = self.args.screenshot.clone() {
                        self.screenshot(&path)?;
                    }
                    event_loop.exit();
                }
                Ok(())
            }),
            WindowEvent::ModifiersChanged(m) => {
                self.shift = m.state().shift_key();
                Ok(())
            }
            WindowEvent::MouseInput { state, button, .. } => {
                self.dragging = (state == ElementState::Pressed).then_some(button);
                Ok(())
            }
            WindowEvent::CursorMoved { position, .. } => {
                let (dx, dy) = ((position.x - self.cursor.x) as f32, (position.y - self.cursor.y) as f32);
                self.cursor = position;
                let size = self.session.as_ref().map_or([1, 1], |s| [s.config.width, s.config.height]);
                match self.dragging {
                    Some(MouseButton::Left) if self.shift => self.orbit.pan(dx, dy, size),
                    Some(MouseButton::Middle) => self.orbit.pan(dx, dy, size),
                    Some(MouseButton::Left) => self.orbit.rotate(dx, dy),
                    Some(MouseButton::Right) => self.orbit.look(dx, dy),
                    _ => return,
                }
                self.camera_moved();
                Ok(())
            }
            WindowEvent::MouseWheel { delta, .. } => {
                let lines = match delta {
                    MouseScrollDelta::LineDelta(_, y) => y,
                    MouseScrollDelta::PixelDelta(p) => p.y as f32 / 40.0,
                };
                if self.dragging == Some(MouseButton::Right) {
                    self.fly_speed = (self.fly_speed * 1.25f32.powf(lines)).clamp(1e-6, 1e7);
                } else {
                    self.orbit.zoom(lines);
                    self.camera_moved();
                }
                Ok(())
            }
            WindowEvent::KeyboardInput { event, .. } => {
                let pressed = event.state == ElementState::Pressed;
                if let Key::Character(c) = &event.logical_key {
                    if let Some(i) = "wsdaeq".find(c.to_ascii_lowercase().as_str()).filter(|_| c.len() == 1) {
                        // Fly up to this moment with the keys held until
                        // now: a key held between two slow frames still
                        // moves the eye for as long as it was held.
                        self.fly();
                        self.flying[i] = pressed;
                    }
                }
                if pressed { self.key(event_loop, &event.logical_key) } else { Ok(()) }
            }
            _ => Ok(()),
        };
        if let Err(e) = result {
            self.fail(event_loop, e);
        }
    }

    fn about_to_wait(&mut self, _: &ActiveEventLoop) {
        if let Some(session) = &self.session {
            session.window.request_redraw();
        }
    }
}

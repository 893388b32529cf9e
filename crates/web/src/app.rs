//! The viewer in a tab. winit owns the canvas and its events; a frame is
//! a task (`frame`) started by a redraw (`requestAnimationFrame`) when the
//! last one is done: it applies what changed (camera, panel edits, a new
//! photon set) to the renderer, awaits `GpuRenderer::render_async`, adds
//! the frame to the running mean and presents the mean with the panel. A
//! hidden tab gets no animation frames, so it renders nothing.

use crate::canvas_copy::CanvasCopy;
use crate::files::{DroppedFile, scene_from_files};
use crate::input::CameraInput;
use crate::options::PageOptions;
use crate::page;
use crate::photons::{Job, Tracing};
use hikari_core::scene::{Pose, Scene, builtin};
use hikari_gpu::accumulate::NoiseReading;
use hikari_gpu::present::PresentPass;
use hikari_gpu::{GpuContext, GpuError, GpuRenderer};
use hikari_viewer::clock::AnimationClock;
use hikari_viewer::frame_stats::FrameStats;
use hikari_viewer::frames::{Frames, wants_photons};
use hikari_viewer::orbit::Orbit;
use hikari_viewer::panel::{Controls, Panel, Readouts, rect_of};
use hikari_viewer::settings::controls_for_scene;
use hikari_viewer::surface::next_frame;
use std::cell::RefCell;
use std::rc::{Rc, Weak};
use std::sync::Arc;
use wasm_bindgen::JsCast;
use web_time::Instant;
use winit::application::ApplicationHandler;
use winit::event::WindowEvent;
use winit::event_loop::{ActiveEventLoop, EventLoop};
use winit::platform::web::{EventLoopExtWebSys, WindowAttributesExtWebSys};
use winit::window::{Window, WindowId};

pub type Shared = Rc<RefCell<Viewer>>;

thread_local! {
    /// The page's viewer, for the functions the page's script calls (`api`).
    pub static VIEWER: RefCell<Weak<RefCell<Viewer>>> = RefCell::new(Weak::new());
}

/// What the panel's page widgets ask for, done at the next frame.
enum Action {
    Builtin(String),
    Files(Vec<DroppedFile>),
    SavePng,
}

/// The device and where frames go, once WebGPU answered.
pub struct Gpu {
    pub window: Arc<Window>,
    /// Frames go to the canvas's WebGPU surface, or (where the browser
    /// cannot present one) through a copy into a 2D canvas.
    surface: Option<wgpu::Surface<'static>>,
    copy: Option<CanvasCopy>,
    /// The frames' size and format.
    config: wgpu::SurfaceConfiguration,
    pub ctx: GpuContext,
    present: PresentPass,
    panel: Panel,
    /// The renderer of the set on screen and the mean of its frames, once
    /// the scene's first photon set came.
    pub frames: Option<Frames>,
}

pub struct Viewer {
    options: PageOptions,
    /// What the page shows: a built-in scene's name or a dropped file's.
    pub scene_name: String,
    base: Arc<Scene>,
    orbit: Orbit,
    input: CameraInput,
    controls: Controls,
    pub readouts: Readouts,
    clock: AnimationClock,
    stats: FrameStats,
    /// When the last rendered frame was finished (frame rate, clock).
    last_frame: Option<Instant>,
    started: Option<Instant>,
    pub gpu: Option<Gpu>,
    tracing: Option<Tracing>,
    /// The pose and count last asked of the tracer.
    requested: Option<(Pose, u64)>,
    /// Whether the renderer must be made anew (a new scene, a new size).
    rebuild: bool,
    frame_in_flight: bool,
    /// When a frame was last timed pass by pass, and frames since.
    last_timing: Option<Instant>,
    frames_since_timing: u32,
    actions: Vec<Action>,
    /// The error on the page, if any (the last good scene stays).
    pub error: Option<String>,
    pub saved_pngs: u32,
    /// Where the page's own panel widgets were drawn (see `Panel::widget_rects`).
    pub page_rects: Vec<(String, [f32; 4])>,
}

/// Starts the page's viewer with `options`.
pub fn run(options: PageOptions) {
    let scene = match Scene::load(&options.scene) {
        Ok(scene) => scene,
        Err(e) => return page::show_error(&e.to_string()),
    };
    let event_loop = match EventLoop::new() {
        Ok(event_loop) => event_loop,
        Err(e) => return page::show_error(&format!("cannot start the page's event loop: {e}")),
    };
    let name = options.scene.clone();
    let viewer = Rc::new(RefCell::new(Viewer::new(options, name, scene)));
    VIEWER.with(|v| *v.borrow_mut() = Rc::downgrade(&viewer));
    let files = Rc::downgrade(&viewer);
    let listening = page::on_files(move |dropped| {
        if let Some(viewer) = files.upgrade() {
            viewer.borrow_mut().actions.push(Action::Files(dropped));
        }
    });
    if let Err(e) = listening {
        page::show_error(&format!("cannot listen for dropped files: {e:?}"));
    }
    event_loop.spawn_app(Page { viewer });
}

impl Viewer {
    fn new(options: PageOptions, scene_name: String, scene: Scene) -> Self {
        let controls = controls_for_scene(&scene, options.exposure, options.photons, false);
        Viewer {
            orbit: Orbit::new(&scene.camera),
            input: CameraInput::new(scene.diagonal()),
            base: Arc::new(scene),
            scene_name,
            controls,
            readouts: Readouts::default(),
            clock: AnimationClock::new(0.0, None),
            stats: FrameStats::default(),
            last_frame: None,
            started: None,
            gpu: None,
            tracing: None,
            requested: None,
            rebuild: true,
            frame_in_flight: false,
            last_timing: None,
            frames_since_timing: 0,
            actions: Vec::new(),
            error: None,
            saved_pngs: 0,
            page_rects: Vec::new(),
            options,
        }
    }

    /// Frames in the mean on screen.
    pub fn frames_in_mean(&self) -> u32 {
        self.gpu.as_ref().and_then(|g| g.frames.as_ref()).map_or(0, |f| f.mean.count())
    }

    /// Where frames go now: see `api::presentation`.
    pub fn presentation(&self) -> &'static str {
        match &self.gpu {
            Some(gpu) if gpu.surface.is_some() => "surface",
            Some(_) => "copy",
            None => "",
        }
    }

    /// Where photon sets are traced now ("" before the adapter answered).
    pub fn tracer_device(&self) -> &'static str {
        self.tracing.as_ref().map_or("", Tracing::device)
    }

    fn pose(&self) -> Pose {
        Pose {
            time: if self.base.is_animated() { self.clock.time() } else { 0.0 },
            lights: self.controls.lights.clone(),
            offsets: self.controls.offsets.clone(),
        }
    }

    /// A scene replaces the one on screen (which stays until the new
    /// one's first photon set is traced).
    fn open_scene(&mut self, name: String, scene: Scene) {
        for note in &scene.notes {
            page::set_status(&format!("{name}: {note}"));
        }
        self.controls = controls_for_scene(&scene, self.controls.exposure, self.controls.photons, false);
        self.orbit = Orbit::new(&scene.camera);
        self.input = CameraInput::new(scene.diagonal());
        self.base = Arc::new(scene);
        self.scene_name = name;
        self.requested = None;
        self.clock = AnimationClock::new(0.0, None);
        if let Some(gpu) = &self.gpu {
            self.tracing = Some(Tracing::new(gpu.ctx.clone(), self.base.clone(), self.options.trace));
        }
        self.rebuild = true;
    }

    fn act(&mut self) {
        for action in std::mem::take(&mut self.actions) {
            match action {
                Action::Builtin(name) => match Scene::load(&name) {
                    Ok(scene) => {
                        self.error = None;
                        page::clear_error();
                        self.open_scene(name, scene);
                    }
                    Err(e) => self.show_error(e.to_string()),
                },
                Action::Files(files) => match scene_from_files(&files) {
                    Ok((name, scene)) => {
                        self.error = None;
                        page::clear_error();
                        self.open_scene(name, scene);
                    }
                    Err(e) => self.show_error(format!("{e} (the last scene stays)")),
                },
                Action::SavePng => self.save_png(),
            }
        }
    }

    fn show_error(&mut self, text: String) {
        page::show_error(&text);
        self.error = Some(text);
    }

    /// Asks the tracer for the next set when it is free: the pose the
    /// panel and the clock ask for when it moved, else (to converge) one
    /// more set of the pose on screen. With `frames=N` the mean stops at
    /// N frames, each of its own set.
    fn ask_for_photons(&mut self) {
        let pose = self.pose();
        let in_mean = self.frames_in_mean();
        let Some(tracing) = &mut self.tracing else { return };
        if tracing.busy() {
            return;
        }
        let photons = self.controls.photons;
        let changed = self.requested.as_ref().is_none_or(|(p, n)| *p != pose || *n != photons);
        let done = self.options.frames.is_some_and(|n| in_mean >= n) && !changed;
        if done {
            return;
        }
        let frames = self.gpu.as_ref().and_then(|g| g.frames.as_ref());
        let shown_is_newest = frames.is_some_and(|f| f.shown().id + 1 == tracing.next_id());
        if wants_photons(self.requested.as_ref(), &pose, photons, shown_is_newest) || self.rebuild {
            let seed = self.options.seed.wrapping_add(tracing.next_id());
            tracing.request(Job { pose: pose.clone(), photons, seed });
            self.requested = Some((pose, photons));
        }
    }

    /// Prepares a frame: the renderer made or updated for what changed.
    /// Returns the renderer when the frame is to be rendered.
    fn prepare(&mut self) -> Result<Option<Rc<GpuRenderer>>, GpuError> {
        self.act();
        let now = Instant::now();
        if self.last_frame.is_some() {
            self.clock.playing = self.controls.playing;
            self.clock.tick(now);
        }
        self.readouts.time = self.base.is_animated().then(|| self.clock.time());
        let Some(gpu) = &mut self.gpu else { return Ok(None) };
        if self.tracing.is_none() {
            self.tracing = Some(Tracing::new(gpu.ctx.clone(), self.base.clone(), self.options.trace));
        }
        if self.input.fly(&mut self.orbit) {
            // Applied below, as any camera move.
        }
        let mut new_set = self.tracing.as_mut().and_then(Tracing::take);
        if let Some(set) = &new_set {
            let r = &mut self.readouts;
            r.trace_ms = set.seconds * 1e3;
            r.photons_per_set = set.photons;
            r.stored = [set.traced.indirect().len(), set.traced.caustic.len(), set.traced.volume.len()];
        }
        let tracing = self.tracing.as_ref().expect("made above");
        self.readouts.photon_sets = tracing.received;
        let copied = if gpu.copy.is_some() { format!("; {}", crate::canvas_copy::NOTE) } else { String::new() };
        self.readouts.adapter = format!("{}; photons traced on the {}{copied}", gpu.ctx.describe(), tracing.device());
        self.readouts.warning = tracing
            .gpu_failed
            .as_ref()
            .map(|why| format!("{why}: photons are traced on the CPU, at most {} a set", crate::photons::CPU_PHOTONS));
        let (width, height) = (gpu.config.width, gpu.config.height);
        let camera = self.orbit.camera(width, height);
        // A new scene: a renderer of its first set.
        if self.rebuild {
            let Some(set) = new_set.take() else {
                self.ask_for_photons();
                return Ok(None);
            };
            gpu.frames = None; // the last scene's targets go first
            gpu.frames = Some(Frames::new(gpu.ctx.clone(), set, camera.clone(), &self.controls, &mut self.readouts)?);
            self.rebuild = false;
            page::set_status("");
        }
        let frames = gpu.frames.as_mut().expect("built above");
        let update = frames.update(&camera, &self.controls, new_set, &mut self.readouts)?;
        if let Some((photons, why)) = update.refused {
            // A set the adapter cannot hold: the last one stays and sets get smaller.
            let cap = (photons * 3 / 4).max(1);
            self.controls.photons = self.controls.photons.min(cap);
            self.readouts.warning = Some(format!("{why}; photons per set lowered to {cap}"));
        }
        let unattended_done = self.options.frames.is_some_and(|n| frames.mean.count() >= n);
        let renderer = (update.render && !unattended_done).then(|| frames.shared_renderer());
        self.ask_for_photons();
        Ok(renderer)
    }

    /// Whether this frame is the timed one: every 2 s while the panel
    /// shows, as in the native viewer, and at most one in `TIMED_EVERY`
    /// frames (a timed frame waits for each pass, and where frames take
    /// seconds, as on a software adapter, every frame would be timed).
    /// Not the first two frames: they include compiling the pipelines.
    fn timing_due(&mut self) -> bool {
        const TIMED_EVERY: u32 = 8;
        let visible = self.gpu.as_ref().is_some_and(|g| g.panel.visible);
        let due = visible
            && match self.last_timing {
                None => self.frames_since_timing >= 2,
                Some(t) => t.elapsed().as_secs_f64() > 2.0 && self.frames_since_timing >= TIMED_EVERY,
            };
        self.frames_since_timing += 1;
        if due {
            self.last_timing = Some(Instant::now());
            self.frames_since_timing = 0;
        }
        due
    }

    /// The mean's noise estimate to read back, at the frames it is due.
    fn noise_reading(&self) -> Option<(GpuContext, NoiseReading)> {
        let gpu = self.gpu.as_ref()?;
        let mean = &gpu.frames.as_ref()?.mean;
        mean.noise_due().then(|| (gpu.ctx.clone(), mean.noise_reading()))
    }

    /// Adds the rendered frame (if one was) to the mean and presents the
    /// mean with the panel; where frames go through a 2D canvas, returns
    /// the target to read back into it.
    fn finish(&mut self, rendered: bool) -> Result<Option<(GpuContext, wgpu::Texture)>, GpuError> {
        let Some(gpu) = &mut self.gpu else { return Ok(None) };
        let Some(frames) = &mut gpu.frames else { return Ok(None) };
        let ctx = &gpu.ctx;
        if rendered {
            frames.accumulate(&mut self.readouts);
        }
        // The rates, before the panel shows them. Frame rate counts rendered
        // frames: a frame that only presents the mean again (its photon set
        // not traced yet) is not one.
        let now = Instant::now();
        if rendered {
            if let Some(last) = self.last_frame {
                self.stats.push((now - last).as_secs_f64());
            }
            self.last_frame = Some(now);
        }
        self.started.get_or_insert(now);
        if self.stats.frames() > 0 {
            self.readouts.fps = self.stats.mean_fps();
        }
        // Photon sets traced a second since the first frame, as the native
        // viewer counts them.
        let elapsed = self.started.map_or(0.0, |s| (now - s).as_secs_f64());
        let received = self.tracing.as_ref().map_or(0, |t| t.received);
        self.readouts.sets_per_second = if elapsed > 0.0 { received as f64 / elapsed } else { 0.0 };
        let mut asked = None;
        let scene_name = self.scene_name.clone();
        let error = self.error.clone();
        let page_rects = &mut self.page_rects;
        let widgets = |ui: &mut egui::Ui| asked = page_widgets(ui, &scene_name, error.as_deref(), page_rects);
        let (present, panel, window) = (&mut gpu.present, &mut gpu.panel, &gpu.window);
        let mut copy = None;
        if let Some(surface) = &gpu.surface {
            let Some(texture) = next_frame(surface, &ctx.device, &gpu.config)? else { return Ok(None) };
            frames.present(texture, present, panel, window, &mut self.controls, &mut self.readouts, widgets)?;
        } else if let Some(canvas) = &gpu.copy {
            frames.draw(&canvas.target, present, panel, window, &mut self.controls, &mut self.readouts, widgets)?;
            copy = Some((ctx.clone(), canvas.target.clone()));
        }
        ctx.check()?;
        self.actions.extend(asked);
        Ok(copy)
    }

    /// The device was lost while frames went to the canvas's WebGPU
    /// surface: where that is the browser failing to present one (see
    /// `canvas_copy`), the page starts again with a new device, its frames
    /// copied into a 2D canvas. Whether it was is not told (the browser
    /// gives no reason), so any first loss does; a loss after that is an
    /// error on the page. Returns whether the page starts again.
    fn start_again_without_surface(&mut self, viewer: &Shared) -> bool {
        let Some(gpu) = &self.gpu else { return false };
        let lost = gpu.ctx.check().err().is_some_and(|e| e.to_string().contains("device lost"));
        if gpu.surface.is_none() || !lost {
            return false;
        }
        let window = gpu.window.clone();
        web_sys::console::log_1(
            &format!("hikari: the WebGPU canvas lost its device; {}", crate::canvas_copy::NOTE).into(),
        );
        self.gpu = None;
        self.tracing = None;
        self.requested = None;
        self.rebuild = true;
        self.frame_in_flight = false;
        let viewer = viewer.clone();
        wasm_bindgen_futures::spawn_local(async move {
            if let Err(e) = open_gpu(viewer.clone(), window, Output::Copy).await {
                page::set_status("");
                viewer.borrow_mut().show_error(e);
            }
        });
        true
    }

    /// Reads the mean back and offers it as a PNG download (tone-mapped
    /// at the panel's exposure, as shown).
    fn save_png(&mut self) {
        let Some((ctx, texture)) = self.mean_texture() else { return };
        let (exposure, name) = (self.controls.exposure, self.scene_name.clone());
        let me = VIEWER.with(|v| v.borrow().clone());
        wasm_bindgen_futures::spawn_local(async move {
            let result = async {
                let pixels = hikari_gpu::readback::read_rgba_async(&ctx, &texture).await.map_err(|e| e.to_string())?;
                let png = png_bytes(texture.width(), texture.height(), &pixels, exposure)?;
                let stem = name.split([',', '.']).next().unwrap_or("hikari").trim().to_string();
                page::download(&format!("{stem}.png"), &png, "image/png").map_err(|e| format!("{e:?}"))
            }
            .await;
            match result {
                Ok(()) => {
                    if let Some(viewer) = me.upgrade() {
                        viewer.borrow_mut().saved_pngs += 1;
                    }
                }
                Err(e) => page::show_error(&format!("cannot save the PNG: {e}")),
            }
        });
    }

    /// The device and the mean's texture, for reading it back.
    pub fn mean_texture(&self) -> Option<(GpuContext, wgpu::Texture)> {
        let gpu = self.gpu.as_ref()?;
        Some((gpu.ctx.clone(), gpu.frames.as_ref()?.mean.mean.clone()))
    }

    fn resized(&mut self, width: u32, height: u32) {
        let Some(gpu) = &mut self.gpu else { return };
        if width == 0 || height == 0 || (width, height) == (gpu.config.width, gpu.config.height) {
            return;
        }
        gpu.config.width = width;
        gpu.config.height = height;
        if let Some(surface) = &gpu.surface {
            surface.configure(&gpu.ctx.device, &gpu.config);
        }
        if let Some(copy) = &mut gpu.copy {
            copy.resize(&gpu.ctx.device, width, height);
        }
        // The renderer's targets are of the canvas's size: made anew from
        // the set on screen.
        if let Some(frames) = &mut gpu.frames
            && let Err(e) = frames.resize(self.orbit.camera(width, height), &mut self.readouts)
        {
            page::show_error(&e.to_string());
        }
    }
}

/// The page's own widgets at the top of the panel: the scene menu, the
/// file dialog, the PNG download.
fn page_widgets(
    ui: &mut egui::Ui,
    scene_name: &str,
    error: Option<&str>,
    rects: &mut Vec<(String, [f32; 4])>,
) -> Option<Action> {
    let mut asked = None;
    rects.clear();
    ui.horizontal(|ui| {
        ui.label("scene");
        egui::ComboBox::from_id_salt("scene").selected_text(scene_name).show_ui(ui, |ui| {
            for name in builtin::NAMES {
                if ui.selectable_label(scene_name == *name, *name).clicked() {
                    asked = Some(Action::Builtin(name.to_string()));
                }
            }
        });
    });
    ui.horizontal(|ui| {
        let open = ui.button("open .glb / .gltf / .toml…");
        if open.clicked() {
            page::open_file_dialog();
        }
        let save = ui.button("save PNG");
        if save.clicked() {
            asked = Some(Action::SavePng);
        }
        rects.push(("open".into(), rect_of(&open)));
        rects.push(("save PNG".into(), rect_of(&save)));
    });
    ui.label("or drop a .glb (or a .gltf or .toml with its files) onto the page");
    if let Some(error) = error {
        ui.colored_label(egui::Color32::LIGHT_RED, error);
    }
    ui.separator();
    asked
}

/// `pixels` (RGBA, linear) tone-mapped to an sRGB PNG.
fn png_bytes(width: u32, height: u32, pixels: &[glam::Vec4], exposure: f32) -> Result<Vec<u8>, String> {
    let mut image = hikari_core::render::Image::new(width, height);
    for (pixel, value) in image.pixels.iter_mut().zip(pixels) {
        let v = value.truncate();
        *pixel = if v.is_finite() { v } else { glam::Vec3::ZERO };
    }
    let rgb = hikari_core::output::tone_map(&image, exposure);
    let mut png = Vec::new();
    image::ImageEncoder::write_image(
        image::codecs::png::PngEncoder::new(&mut png),
        &rgb,
        width,
        height,
        image::ExtendedColorType::Rgb8,
    )
    .map_err(|e| e.to_string())?;
    Ok(png)
}

/// Renders one frame of `viewer`: see the module's comment.
async fn frame(viewer: Shared) {
    let prepared = viewer.borrow_mut().prepare();
    let outcome = async {
        let rendered = match prepared? {
            Some(renderer) => {
                if viewer.borrow_mut().timing_due() {
                    let (times, timestamps) = renderer.render_timed_async().await?;
                    let readouts = &mut viewer.borrow_mut().readouts;
                    readouts.passes = times.iter().map(|(stage, t)| (stage.name(), t * 1e3)).collect();
                    readouts.timestamps = timestamps;
                } else {
                    renderer.render_async().await?;
                }
                true
            }
            None => false,
        };
        let copy = viewer.borrow_mut().finish(rendered)?;
        if let Some((ctx, target)) = copy {
            let pixels = hikari_gpu::readback::read_rgba8_async(&ctx, &target).await?;
            let v = viewer.borrow();
            if let Some(canvas) = v.gpu.as_ref().and_then(|g| g.copy.as_ref()) {
                canvas.show(target.width(), pixels).map_err(GpuError::Failed)?;
            }
        }
        // The noise estimate, when the mean asks for one (read back
        // without holding the viewer: input goes on meanwhile).
        let reading = if rendered { viewer.borrow().noise_reading() } else { None };
        if let Some((ctx, reading)) = reading {
            let noise = reading.read_async(&ctx).await?;
            viewer.borrow_mut().readouts.noise = noise;
        }
        Ok::<(), GpuError>(())
    }
    .await;
    let mut v = viewer.borrow_mut();
    v.frame_in_flight = false;
    if let Err(e) = outcome {
        if v.start_again_without_surface(&viewer) {
            return;
        }
        // A GPU error stops the frames (never a silently wrong image).
        v.show_error(format!("{e}"));
        return;
    }
    if let Some(gpu) = &v.gpu {
        gpu.window.request_redraw();
    }
}

/// Windows narrower than this (CSS pixels) open with the panel folded.
const PHONE_WIDTH: f32 = 600.0;

/// Where the page's frames go.
#[derive(Clone, Copy, PartialEq)]
enum Output {
    /// The canvas's WebGPU surface.
    Surface,
    /// A 2D canvas, each frame read back into it (`canvas_copy`).
    Copy,
}

/// Opens WebGPU for frames to `output`.
async fn open_gpu(viewer: Shared, window: Arc<Window>, output: Output) -> Result<(), String> {
    use winit::platform::web::WindowExtWebSys;
    page::set_status("opening WebGPU…");
    let instance = wgpu::Instance::new(wgpu::InstanceDescriptor::new_without_display_handle());
    let surface = match output {
        Output::Surface => {
            Some(instance.create_surface(window.clone()).map_err(|e| format!("cannot draw in the canvas: {e}"))?)
        }
        Output::Copy => None,
    };
    let opened = match &surface {
        Some(surface) => GpuContext::for_surface_async(&instance, surface).await,
        None => open_after_loss().await,
    };
    let ctx = match opened {
        Ok(ctx) => ctx,
        // `navigator.gpu` without an adapter (WebGPU switched off, or a
        // blocklisted GPU): as good as no WebGPU.
        Err(GpuError::NoAdapter(_)) => {
            page::show_no_webgpu();
            return Ok(());
        }
        Err(e) => return Err(format!("{e} (WebGPU is present, but its adapter cannot run hikari)")),
    };
    let size = window.inner_size();
    let (width, height) = (size.width.max(1), size.height.max(1));
    let (format, copy) = match &surface {
        Some(surface) => {
            let format = surface
                .get_capabilities(&ctx.adapter)
                .formats
                .first()
                .copied()
                .ok_or_else(|| format!("the canvas offers no surface format on {}", ctx.describe()))?;
            (format, None)
        }
        None => {
            let canvas = window.canvas().ok_or("the page's canvas is gone")?;
            (CanvasCopy::FORMAT, Some(CanvasCopy::new(&ctx.device, &canvas, width, height)?))
        }
    };
    let config = hikari_viewer::surface::surface_config(format, width, height);
    if let Some(surface) = &surface {
        surface.configure(&ctx.device, &config);
    }
    let present = PresentPass::new(&ctx.device, format);
    let mut panel = Panel::new(&window, &ctx.device, format);
    let mut v = viewer.borrow_mut();
    panel.visible = v.options.panel;
    // On a phone-sized window the panel would hide the image: folded.
    panel.start_folded = window.inner_size().to_logical::<f32>(window.scale_factor()).width < PHONE_WIDTH;
    v.readouts.adapter = ctx.describe();
    web_sys::console::log_1(&format!("hikari: {} on {}", v.scene_name, ctx.describe()).into());
    page::set_status(&format!("tracing photons of {} on {}…", v.scene_name, ctx.describe()));
    v.gpu = Some(Gpu { window: window.clone(), surface, copy, config, ctx, present, panel, frames: None });
    window.request_redraw();
    Ok(())
}

/// A new device after the canvas's was lost. Chromium's GPU process may
/// still be restarting then: its adapter request answers none ("A valid
/// external Instance reference no longer exists") for a moment, so the
/// request is made again a few times, waiting longer each time (up to
/// about 12 s in all), before the page says there is no WebGPU.
async fn open_after_loss() -> Result<GpuContext, GpuError> {
    let mut wait_ms = 100;
    loop {
        match GpuContext::new_async().await {
            Err(GpuError::NoAdapter(why)) if wait_ms <= 6_400 => {
                web_sys::console::log_1(
                    &format!("hikari: no adapter yet ({why}); asking again in {wait_ms} ms").into(),
                );
                page::sleep(wait_ms).await;
                wait_ms *= 2;
            }
            other => return other,
        }
    }
}

/// winit's handler: the canvas's events and redraws.
struct Page {
    viewer: Shared,
}

impl ApplicationHandler for Page {
    fn resumed(&mut self, event_loop: &ActiveEventLoop) {
        if self.viewer.borrow().gpu.is_some() {
            return;
        }
        let canvas = page::document()
            .get_element_by_id("hikari-canvas")
            .and_then(|e| e.dyn_into::<web_sys::HtmlCanvasElement>().ok());
        let attributes = Window::default_attributes()
            .with_title("hikari")
            .with_canvas(canvas)
            .with_append(true)
            .with_focusable(true)
            .with_prevent_default(true);
        let window = match event_loop.create_window(attributes) {
            Ok(window) => Arc::new(window),
            Err(e) => return page::show_error(&format!("cannot use the canvas: {e}")),
        };
        let viewer = self.viewer.clone();
        wasm_bindgen_futures::spawn_local(async move {
            if let Err(e) = open_gpu(viewer.clone(), window, Output::Surface).await {
                page::set_status("");
                viewer.borrow_mut().show_error(e);
            }
        });
    }

    fn window_event(&mut self, _: &ActiveEventLoop, _: WindowId, event: WindowEvent) {
        let mut v = self.viewer.borrow_mut();
        let v = &mut *v;
        let Some(gpu) = &mut v.gpu else { return };
        let input = matches!(
            event,
            WindowEvent::MouseInput { .. }
                | WindowEvent::CursorMoved { .. }
                | WindowEvent::MouseWheel { .. }
                | WindowEvent::KeyboardInput { .. }
                | WindowEvent::Touch(_)
        );
        if gpu.panel.on_event(&gpu.window, &event) && input {
            return;
        }
        if let WindowEvent::KeyboardInput { event: key, .. } = &event {
            use winit::keyboard::{Key, NamedKey};
            match key.logical_key {
                Key::Named(NamedKey::F1) if key.state.is_pressed() => gpu.panel.visible = !gpu.panel.visible,
                Key::Named(NamedKey::Home) if key.state.is_pressed() => v.orbit.reset(),
                _ => {}
            }
        }
        match event {
            WindowEvent::Resized(size) => v.resized(size.width, size.height),
            WindowEvent::RedrawRequested => {
                if !v.frame_in_flight {
                    v.frame_in_flight = true;
                    wasm_bindgen_futures::spawn_local(frame(self.viewer.clone()));
                }
            }
            other => {
                let size = [gpu.config.width, gpu.config.height];
                v.input.event(&mut v.orbit, &other, size);
            }
        }
    }
}

impl Viewer {
    /// Where the panel last drew the widget named `name`.
    pub fn widget_rect(&self, name: &str) -> Option<[f32; 4]> {
        let panel = self.gpu.as_ref().map(|g| g.panel.widget_rects.iter()).into_iter().flatten();
        panel.chain(&self.page_rects).find(|(n, _)| n == name).map(|(_, r)| *r)
    }

    /// The terms switched on, by name.
    pub fn terms(&self) -> String {
        let t = &self.controls.terms;
        [
            (t.direct, "direct"),
            (t.indirect, "indirect"),
            (t.caustic, "caustic"),
            (t.volume, "volume"),
            (t.specular, "specular"),
        ]
        .iter()
        .filter(|(on, _)| *on > 0.0)
        .map(|(_, name)| *name)
        .collect::<Vec<_>>()
        .join(",")
    }
}

//! The viewer's panel (egui, drawn over the frame): frame rate and per-pass
//! GPU times, photon counts, the terms of the image, radii, LOD, exposure,
//! photons per set, the animation clock, the lights and named objects, and
//! debug views. F1 hides it.

use glam::Vec3;
use hikari_core::light::Light;
use hikari_core::lod::LodSettings;
use hikari_gpu::present::PresentMode;
use hikari_gpu::resolve::Terms;
use winit::window::Window;

/// What the panel shows and edits; the viewer applies the edits.
#[derive(Clone, Debug, PartialEq)]
pub struct Controls {
    pub exposure: f32,
    pub global_radius: f32,
    pub caustic_radius: f32,
    pub terms: Terms,
    pub lod: Option<LodSettings>,
    pub mode: PresentMode,
    pub volume_radius: f32,
    /// Depth slices of the media regions' optical depth (rebuilds the renderer).
    pub volume_slices: u32,
    /// Photon paths per set (chosen by the budget while `trace_every_frame`).
    pub photons: u64,
    pub trace_every_frame: bool,
    /// While still, frames shrink the radii and jitter the pixel samples
    /// pass by pass (progressive photon mapping), so the mean converges.
    pub progressive: bool,
    /// Whether the scene's animations play.
    pub playing: bool,
    /// The lights as edited (before their animations), and an offset per
    /// surface (named objects are edited): `Pose::lights`, `Pose::offsets`.
    pub lights: Vec<Light>,
    pub offsets: Vec<Vec3>,
}

/// Read-outs, refreshed by the viewer.
#[derive(Clone, Debug, Default)]
pub struct Readouts {
    pub adapter: String,
    pub fps: f64,
    pub frames_in_mean: u32,
    /// The mean's noise as its frames estimate it (relative to its mean).
    pub noise: Option<f64>,
    pub photon_sets: u64,
    pub photons_per_set: u64,
    pub stored: [usize; 3],
    /// Photons the last timed frame drew (after LOD), per map.
    pub drawn: Option<[u32; 3]>,
    /// (pass, milliseconds) of the last timed frame, and whether from GPU timestamps.
    pub passes: Vec<(&'static str, f64)>,
    pub timestamps: bool,
    pub reload_error: Option<String>,
    /// The scene diagonal, for the radius sliders' range.
    pub diagonal: f32,
    pub has_media: bool,
    pub has_regions: bool,
    /// Names of the lights (`None`: unnamed) and the named objects' surfaces.
    pub light_names: Vec<Option<String>>,
    pub objects: Vec<(String, u32)>,
    /// The animation time, when the scene is animated.
    pub time: Option<f32>,
    /// Photon sets traced per second, mean seconds per set, and the mean
    /// latency from a scene edit to the screen (ms).
    pub sets_per_second: f64,
    pub trace_ms: f64,
    pub edit_latency_ms: Option<f64>,
    /// The last thing the viewer had to refuse (a photon set too large).
    pub warning: Option<String>,
}

pub struct Panel {
    ctx: egui::Context,
    state: egui_winit::State,
    renderer: egui_wgpu::Renderer,
    pub visible: bool,
    /// Whether the panel starts folded to its title bar (a phone-sized
    /// window, where it would cover the image); a tap on the title opens it.
    pub start_folded: bool,
    /// Where the last frame drew the term checkboxes, by term name, as
    /// [left, top, right, bottom] in points (CSS pixels in a browser):
    /// the web page's tests click them.
    pub widget_rects: Vec<(String, [f32; 4])>,
    /// egui's clock at the last frame's input (seconds), for
    /// `allow_clicks_across_frames`.
    last_input_time: Option<f64>,
}

/// egui's own limit on how long a click may be held (seconds).
const MAX_CLICK_HOLD: f64 = 0.8;

/// egui stamps a press and a release with the time of the frame that
/// takes them, so a click whose press and release fall on two sides of a
/// frame boundary seems held for a whole frame. On a software adapter a
/// frame takes seconds, past egui's 0.8 s, and such a click was dropped
/// (a checkbox that ignores clicks now and then). The limit grows by the
/// time between the last two frames' input.
fn allow_clicks_across_frames(ctx: &egui::Context, last_input_time: Option<f64>, now: Option<f64>) {
    let frame_gap = match (last_input_time, now) {
        (Some(last), Some(now)) if now > last => now - last,
        _ => 0.0,
    };
    ctx.options_mut(|o| o.input_options.max_click_duration = MAX_CLICK_HOLD + frame_gap);
}

impl Panel {
    pub fn new(window: &Window, device: &wgpu::Device, format: wgpu::TextureFormat) -> Self {
        let ctx = egui::Context::default();
        let state = egui_winit::State::new(ctx.clone(), egui::ViewportId::ROOT, window, None, None, None);
        let renderer = egui_wgpu::Renderer::new(device, format, egui_wgpu::RendererOptions::default());
        Panel {
            ctx,
            state,
            renderer,
            visible: true,
            start_folded: false,
            widget_rects: Vec::new(),
            last_input_time: None,
        }
    }

    /// Passes a window event to egui; true when egui used it (a click on
    /// the panel is not a camera drag).
    pub fn on_event(&mut self, window: &Window, event: &winit::event::WindowEvent) -> bool {
        self.visible && self.state.on_window_event(window, event).consumed
    }

    /// Lays out the panel, letting it edit `controls`, and draws it into
    /// `target`; `front_end` adds widgets of its own at the top.
    #[allow(clippy::too_many_arguments)]
    pub fn draw(
        &mut self,
        window: &Window,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        encoder: &mut wgpu::CommandEncoder,
        target: &wgpu::TextureView,
        size: [u32; 2],
        controls: &mut Controls,
        readouts: &Readouts,
        front_end: impl FnOnce(&mut egui::Ui),
    ) {
        if !self.visible {
            return;
        }
        let input = self.state.take_egui_input(window);
        allow_clicks_across_frames(&self.ctx, self.last_input_time, input.time);
        self.last_input_time = input.time;
        let mut front_end = Some(front_end);
        let rects = &mut self.widget_rects;
        rects.clear();
        let open = !self.start_folded;
        let output = self.ctx.run_pass(input, |ctx| {
            let shown = egui::Window::new("hikari").default_width(260.0).default_open(open).show(ctx, |ui| {
                // The front end's own widgets first (the web page's scene menu).
                if let Some(widgets) = front_end.take() {
                    widgets(ui);
                }
                layout(ui, controls, readouts, rects)
            });
            // The whole panel, its title bar alone when folded.
            if let Some(shown) = shown {
                rects.push(("panel".into(), rect_of(&shown.response)));
            }
        });
        let egui::FullOutput { platform_output, mut textures_delta, shapes, pixels_per_point, .. } = output;
        self.state.handle_platform_output(window, platform_output);
        let jobs = self.ctx.tessellate(shapes, pixels_per_point);
        for (id, deltas) in &textures_delta.set {
            for delta in deltas {
                self.renderer.update_texture(device, queue, *id, delta);
            }
        }
        let screen = egui_wgpu::ScreenDescriptor { size_in_pixels: size, pixels_per_point };
        let extra = self.renderer.update_buffers(device, queue, encoder, &jobs, &screen);
        if !extra.is_empty() {
            queue.submit(extra);
        }
        let pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("panel"),
            color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                view: target,
                depth_slice: None,
                resolve_target: None,
                ops: wgpu::Operations { load: wgpu::LoadOp::Load, store: wgpu::StoreOp::Store },
            })],
            depth_stencil_attachment: None,
            timestamp_writes: None,
            occlusion_query_set: None,
            multiview_mask: None,
        });
        self.renderer.render(&mut pass.forget_lifetime(), &jobs, &screen);
        for id in &textures_delta.free {
            self.renderer.free_texture(id);
        }
        // Applied: egui checks that no texture update is dropped unseen.
        textures_delta.clear();
    }
}

/// A rate per second with two significant digits below 10, so that the
/// slow rates of a software adapter (a frame every few seconds) read as
/// such and not as "0.0"; a dash until there is one (the first frames).
fn rate(per_second: f64) -> String {
    if per_second <= 0.0 {
        return "–".into();
    }
    let decimals = if per_second >= 10.0 {
        0
    } else if per_second >= 1.0 {
        1
    } else if per_second >= 0.1 {
        2
    } else {
        3
    };
    format!("{per_second:.decimals$}")
}

fn layout(ui: &mut egui::Ui, c: &mut Controls, r: &Readouts, rects: &mut Vec<(String, [f32; 4])>) {
    ui.label(&r.adapter);
    ui.label(format!("{} fps; mean of {} frames ({} photon sets)", rate(r.fps), r.frames_in_mean, r.photon_sets));
    if let Some(noise) = r.noise {
        ui.label(format!("noise ≈ {:.1}% (of the mean, from odd and even frames)", 100.0 * noise));
    }
    ui.label(format!(
        "photons: {} per set; stored {} global, {} caustic, {} volume",
        r.photons_per_set, r.stored[0], r.stored[1], r.stored[2]
    ));
    if let Some([g, c, v]) = r.drawn {
        ui.label(format!("drawn: {g} global, {c} caustic, {v} volume"));
    }
    ui.label(format!("tracing: {} sets/s, {:.1} ms per set", rate(r.sets_per_second), r.trace_ms));
    if let Some(ms) = r.edit_latency_ms {
        ui.label(format!("scene edit to screen: {ms:.0} ms (mean)"));
    }
    for error in [&r.reload_error, &r.warning].into_iter().flatten() {
        ui.colored_label(egui::Color32::LIGHT_RED, error);
    }
    egui::CollapsingHeader::new("GPU passes").default_open(false).show(ui, |ui| {
        let how = if r.timestamps { "GPU timestamps" } else { "wall clock" };
        ui.label(format!("per pass ({how}), every 2 s:"));
        for (name, ms) in &r.passes {
            ui.label(format!("{name}: {ms:.2} ms"));
        }
    });
    ui.separator();
    ui.label("terms");
    ui.horizontal_wrapped(|ui| {
        let mut toggle = |ui: &mut egui::Ui, value: &mut f32, name: &str| {
            let mut on = *value > 0.0;
            let response = ui.checkbox(&mut on, name);
            if response.changed() {
                *value = on as u32 as f32;
            }
            rects.push((name.to_string(), rect_of(&response)));
        };
        toggle(ui, &mut c.terms.direct, "direct");
        toggle(ui, &mut c.terms.indirect, "indirect");
        toggle(ui, &mut c.terms.caustic, "caustic");
        toggle(ui, &mut c.terms.volume, "volume");
        toggle(ui, &mut c.terms.specular, "specular");
    });
    let range = (r.diagonal * 1e-3)..=(r.diagonal * 0.2);
    ui.add(egui::Slider::new(&mut c.global_radius, range.clone()).logarithmic(true).text("global radius"));
    ui.add(egui::Slider::new(&mut c.caustic_radius, range.clone()).logarithmic(true).text("caustic radius"));
    if r.has_media {
        ui.add(egui::Slider::new(&mut c.volume_radius, range).logarithmic(true).text("volume radius"));
    }
    if r.has_regions {
        ui.add(egui::Slider::new(&mut c.volume_slices, 1..=64).text("volume slices"));
    }
    ui.add_enabled(
        !c.trace_every_frame,
        egui::Slider::new(&mut c.photons, 1_000..=10_000_000).logarithmic(true).text("photons per set"),
    );
    ui.checkbox(&mut c.trace_every_frame, "trace every frame (photons to keep up)");
    ui.checkbox(&mut c.progressive, "converge: shrink radii while still");
    ui.add(egui::Slider::new(&mut c.exposure, -8.0..=8.0).text("exposure (stops)"));
    let mut lod_on = c.lod.is_some();
    ui.checkbox(&mut lod_on, "level of detail");
    if lod_on {
        let lod = c.lod.get_or_insert(LodSettings { near: r.diagonal * 1.5, far: r.diagonal * 0.5, groups: 20 });
        ui.add(egui::Slider::new(&mut lod.near, 0.0..=r.diagonal * 4.0).text("near"));
        ui.add(egui::Slider::new(&mut lod.far, 0.0..=r.diagonal * 4.0).text("far"));
        ui.add(egui::Slider::new(&mut lod.groups, 1..=100).text("groups"));
    } else {
        c.lod = None;
    }
    if let Some(time) = r.time {
        ui.checkbox(&mut c.playing, format!("animate (t = {time:.2} s; Space)"));
    }
    scene_edits(ui, c, r);
    ui.horizontal(|ui| {
        ui.label("show");
        ui.radio_value(&mut c.mode, PresentMode::Radiance, "image");
        ui.radio_value(&mut c.mode, PresentMode::Normals, "normals");
        ui.radio_value(&mut c.mode, PresentMode::Albedo, "albedo");
    });
    ui.horizontal(|ui| {
        ui.label("photons");
        ui.radio_value(&mut c.mode, PresentMode::Photons, "as points");
        ui.radio_value(&mut c.mode, PresentMode::DetailLevels, "LOD level");
    });
}

/// A widget's place as [left, top, right, bottom] in points.
pub fn rect_of(response: &egui::Response) -> [f32; 4] {
    let r = response.rect;
    [r.min.x, r.min.y, r.max.x, r.max.y]
}

/// Three drag fields for a point or vector; true when one changed.
fn drag_vec3(ui: &mut egui::Ui, label: &str, v: &mut Vec3, speed: f32) -> bool {
    ui.horizontal(|ui| {
        ui.label(label);
        let mut changed = false;
        for x in [&mut v.x, &mut v.y, &mut v.z] {
            changed |= ui.add(egui::DragValue::new(x).speed(speed).max_decimals(3)).changed();
        }
        changed
    })
    .inner
}

/// The lights (position, a spot's direction, colour and strength) and the
/// named objects (an offset from their place).
fn scene_edits(ui: &mut egui::Ui, c: &mut Controls, r: &Readouts) {
    let speed = r.diagonal * 0.002;
    egui::CollapsingHeader::new("lights").default_open(false).show(ui, |ui| {
        for (i, light) in c.lights.iter_mut().enumerate() {
            let kind = match light {
                Light::Point { .. } => "point",
                Light::Spot { .. } => "spot",
                Light::Sphere { .. } => "sphere",
                Light::Quad { .. } => "quad",
                Light::Directional { .. } => "directional",
                Light::Environment { .. } => "environment",
                Light::Mesh(_) => "emissive mesh",
            };
            let name = r.light_names.get(i).cloned().flatten().unwrap_or_else(|| format!("light #{}", i + 1));
            ui.label(format!("{name} ({kind})"));
            let mut anchor = light.anchor();
            if drag_vec3(ui, "position", &mut anchor, speed) {
                *light = light.with_anchor(anchor);
            }
            if let Light::Spot { axis, .. } = light {
                let mut direction = *axis;
                if drag_vec3(ui, "direction", &mut direction, 0.01) {
                    if let Some(unit) = direction.try_normalize() {
                        *axis = unit;
                    }
                }
            }
            let emission = light.emission();
            let mut strength = emission.max_element();
            let mut colour = (emission / strength.max(f32::MIN_POSITIVE)).to_array();
            let changed = ui
                .horizontal(|ui| {
                    let c = ui.color_edit_button_rgb(&mut colour).changed();
                    c | ui
                        .add(egui::Slider::new(&mut strength, 1e-3..=1e6).logarithmic(true).text("strength"))
                        .changed()
                })
                .inner;
            // A black colour would leave no power to emit photons with.
            if changed && colour.iter().copied().fold(0.0, f32::max) >= 1e-3 {
                *light = light.with_emission(Vec3::from(colour) * strength);
            }
        }
    });
    if !r.objects.is_empty() {
        egui::CollapsingHeader::new("objects").default_open(false).show(ui, |ui| {
            for (name, surface) in &r.objects {
                if let Some(offset) = c.offsets.get_mut(*surface as usize) {
                    drag_vec3(ui, name, offset, speed);
                }
            }
        });
    }
}

#[cfg(test)]
mod tests {
    use super::{allow_clicks_across_frames, rate};

    /// One frame of a panel holding one checkbox, with `events` as its
    /// input at `time` seconds; where the box was drawn.
    fn checkbox_frame(ctx: &egui::Context, ticked: &mut bool, time: f64, events: Vec<egui::Event>) -> egui::Pos2 {
        let input = egui::RawInput {
            time: Some(time),
            events,
            screen_rect: Some(egui::Rect::from_min_size(egui::Pos2::ZERO, egui::vec2(200.0, 100.0))),
            ..Default::default()
        };
        let mut centre = egui::Pos2::ZERO;
        let mut output = ctx.run_ui(input, |ui| centre = ui.checkbox(ticked, "term").rect.center());
        // Nothing is drawn here; egui asks that dropping its textures be said.
        output.textures_delta.clear();
        centre
    }

    fn button(pos: egui::Pos2, pressed: bool) -> egui::Event {
        egui::Event::PointerButton { pos, button: egui::PointerButton::Primary, pressed, modifiers: Default::default() }
    }

    /// A click pressed in one slow frame (3 s apart) and released in the
    /// next ticks the box with the limit stretched, and not without it
    /// (the second half shows the test can fail).
    #[test]
    fn a_click_split_across_slow_frames_still_clicks() {
        for stretched in [true, false] {
            let ctx = egui::Context::default();
            let mut ticked = false;
            let mut last = None;
            let mut at = egui::Pos2::ZERO;
            for (frame, time) in [0.0, 3.0, 6.0].into_iter().enumerate() {
                if stretched {
                    allow_clicks_across_frames(&ctx, last, Some(time));
                }
                last = Some(time);
                let events = match frame {
                    0 => vec![],
                    1 => vec![egui::Event::PointerMoved(at), button(at, true)],
                    _ => vec![button(at, false)],
                };
                at = checkbox_frame(&ctx, &mut ticked, time, events);
            }
            assert_eq!(ticked, stretched, "stretched limit: {stretched}");
        }
    }

    /// Slow rates keep two significant digits; fast ones drop the noise.
    #[test]
    fn rates_read_with_their_leading_digits() {
        assert_eq!(rate(0.067), "0.067");
        assert_eq!(rate(0.25), "0.25");
        assert_eq!(rate(1.92), "1.9");
        assert_eq!(rate(59.6), "60");
        assert_eq!(rate(0.0), "–");
    }
}

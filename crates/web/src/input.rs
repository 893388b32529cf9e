//! Mouse, touch and keys to camera moves, as in `hikari view`: left drag
//! orbits, middle or shift + left drag pans, the wheel zooms, right drag
//! turns in place and WASD/QE fly; on a touch screen one finger orbits and
//! two pinch to zoom and move together to pan.

use glam::Vec2;
use hikari_viewer::orbit::Orbit;
use web_time::Instant;
use winit::event::{ElementState, MouseButton, MouseScrollDelta, Touch, TouchPhase, WindowEvent};
use winit::keyboard::Key;

pub struct CameraInput {
    cursor: Vec2,
    dragging: Option<MouseButton>,
    shift: bool,
    /// Fly keys held (W, S, D, A, E, Q), the speed (scene units/s) and
    /// when the keys were last applied.
    flying: [bool; 6],
    fly_speed: f32,
    last_fly: Option<Instant>,
    /// Fingers on the screen: (id, where).
    touches: Vec<(u64, Vec2)>,
}

impl CameraInput {
    pub fn new(diagonal: f32) -> Self {
        CameraInput {
            cursor: Vec2::ZERO,
            dragging: None,
            shift: false,
            flying: [false; 6],
            fly_speed: 0.25 * diagonal,
            last_fly: None,
            touches: Vec::new(),
        }
    }

    /// Applies `event` to `orbit`; true when the camera moved. `size` is
    /// the canvas's, in pixels (pans follow the cursor).
    pub fn event(&mut self, orbit: &mut Orbit, event: &WindowEvent, size: [u32; 2]) -> bool {
        match event {
            WindowEvent::ModifiersChanged(m) => {
                self.shift = m.state().shift_key();
                false
            }
            WindowEvent::MouseInput { state, button, .. } => {
                self.dragging = (*state == ElementState::Pressed).then_some(*button);
                false
            }
            WindowEvent::CursorMoved { position, .. } => {
                let at = Vec2::new(position.x as f32, position.y as f32);
                let d = at - self.cursor;
                self.cursor = at;
                match self.dragging {
                    Some(MouseButton::Left) if self.shift => orbit.pan(d.x, d.y, size),
                    Some(MouseButton::Middle) => orbit.pan(d.x, d.y, size),
                    Some(MouseButton::Left) => orbit.rotate(d.x, d.y),
                    Some(MouseButton::Right) => orbit.look(d.x, d.y),
                    _ => return false,
                }
                true
            }
            WindowEvent::MouseWheel { delta, .. } => {
                let lines = match delta {
                    MouseScrollDelta::LineDelta(_, y) => *y,
                    MouseScrollDelta::PixelDelta(p) => p.y as f32 / 40.0,
                };
                if self.dragging == Some(MouseButton::Right) {
                    self.fly_speed = (self.fly_speed * 1.25f32.powf(lines)).clamp(1e-6, 1e7);
                    false
                } else {
                    orbit.zoom(lines);
                    true
                }
            }
            WindowEvent::KeyboardInput { event, .. } => {
                let pressed = event.state == ElementState::Pressed;
                let mut moved = false;
                if let Key::Character(c) = &event.logical_key {
                    if let Some(i) = "wsdaeq".find(c.to_ascii_lowercase().as_str()).filter(|_| c.len() == 1) {
                        // Up to now with the keys held until now.
                        moved = self.fly(orbit);
                        self.flying[i] = pressed;
                    }
                }
                moved
            }
            WindowEvent::Touch(touch) => self.touch(orbit, touch, size),
            _ => false,
        }
    }

    fn touch(&mut self, orbit: &mut Orbit, touch: &Touch, size: [u32; 2]) -> bool {
        let at = Vec2::new(touch.location.x as f32, touch.location.y as f32);
        let before = self.touches.clone();
        match touch.phase {
            TouchPhase::Started => self.touches.push((touch.id, at)),
            TouchPhase::Moved => {
                if let Some(t) = self.touches.iter_mut().find(|t| t.0 == touch.id) {
                    t.1 = at;
                }
            }
            TouchPhase::Ended | TouchPhase::Cancelled => self.touches.retain(|t| t.0 != touch.id),
        }
        if touch.phase != TouchPhase::Moved {
            return false;
        }
        match (before.as_slice(), self.touches.as_slice()) {
            ([(a, from)], [(b, to)]) if a == b => {
                let d = *to - *from;
                orbit.rotate(d.x, d.y);
                true
            }
            ([(_, a0), (_, b0)], [(_, a1), (_, b1)]) => {
                let (spread0, spread1) = (a0.distance(*b0), a1.distance(*b1));
                if spread0 > 1.0 {
                    orbit.pinch(spread1 / spread0);
                }
                let d = (*a1 + *b1 - *a0 - *b0) * 0.5;
                orbit.pan(d.x, d.y, size);
                true
            }
            _ => false,
        }
    }

    /// Moves the eye for the fly keys held since the last call (each frame
    /// and each fly key's press and release); true when it moved. At most
    /// a second counts, so a stall does not throw the eye across the scene.
    pub fn fly(&mut self, orbit: &mut Orbit) -> bool {
        let now = Instant::now();
        let dt = self.last_fly.map_or(0.0, |t| (now - t).as_secs_f32().min(1.0));
        self.last_fly = Some(now);
        let [w, s, d, a, e, q] = self.flying.map(|held| held as i32 as f32);
        if w + s + d + a + e + q == 0.0 {
            return false;
        }
        let step = self.fly_speed * dt;
        orbit.fly((w - s) * step, (d - a) * step, (e - q) * step);
        true
    }
}

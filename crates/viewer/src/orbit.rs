//! The viewer's camera: orbit around a target (left drag), pan (middle or
//! shift drag), zoom (wheel), fly (turn in place with right drag, move with
//! WASD/QE), reset (Home), and the current view as a `[camera]` block for
//! a scene file.

use glam::Vec3;
use hikari_core::camera::Camera;

/// Radians per pixel dragged.
const ORBIT_SPEED: f32 = 0.005;
/// Distance factor per wheel line.
const ZOOM_STEP: f32 = 0.9;
/// Keeps the view off the poles, where `up` and the view would be parallel.
const MAX_PITCH: f32 = 1.55;

#[derive(Clone, Debug)]
pub struct Orbit {
    pub target: Vec3,
    pub distance: f32,
    /// Around `up`, from +z toward +x.
    pub yaw: f32,
    /// Above the plane normal to `up`.
    pub pitch: f32,
    up: Vec3,
    fov_y: f32,
    /// The scene's camera, for `reset`.
    home: Camera,
}

impl Orbit {
    /// The orbit that sees what `camera` sees.
    pub fn new(camera: &Camera) -> Self {
        let up = camera.up.normalize();
        let offset = camera.position - camera.look_at;
        let distance = offset.length();
        let (side, forward) = frame(up);
        let d = offset / distance;
        let pitch = d.dot(up).clamp(-1.0, 1.0).asin().clamp(-MAX_PITCH, MAX_PITCH);
        let yaw = d.dot(side).atan2(d.dot(forward));
        Orbit { target: camera.look_at, distance, yaw, pitch, up, fov_y: camera.fov_y, home: camera.clone() }
    }

    pub fn reset(&mut self) {
        *self = Orbit::new(&self.home);
    }

    /// The eye position.
    pub fn position(&self) -> Vec3 {
        let (side, forward) = frame(self.up);
        let (sp, cp) = self.pitch.sin_cos();
        let (sy, cy) = self.yaw.sin_cos();
        self.target + self.distance * (self.up * sp + cp * (forward * cy + side * sy))
    }

    /// The camera for an image of `width × height`.
    pub fn camera(&self, width: u32, height: u32) -> Camera {
        Camera::new(self.position(), self.target, self.up, self.fov_y_for(width, height), width, height)
            .expect("an orbit keeps the eye off the target and off the up axis")
    }

    /// The vertical field of view (degrees) for an image of `width ×
    /// height`: the scene camera's, unless the image is narrower than the
    /// scene's own (a phone held upright); then it widens so the image
    /// still spans the scene camera's horizontal view, which would
    /// otherwise be cut at the sides (tan(fov/2) grows by the ratio of
    /// the aspects).
    fn fov_y_for(&self, width: u32, height: u32) -> f32 {
        let aspect = width.max(1) as f32 / height.max(1) as f32;
        let home_aspect = self.home.aspect();
        if aspect >= home_aspect {
            return self.fov_y;
        }
        let tan_half = (self.fov_y.to_radians() * 0.5).tan() * home_aspect / aspect;
        let widest = hikari_core::scene::limits::FOV_Y.1 - 1.0;
        (2.0 * tan_half.atan()).to_degrees().min(widest)
    }

    /// A drag of (dx, dy) pixels turns the eye around the target.
    pub fn rotate(&mut self, dx: f32, dy: f32) {
        self.yaw -= dx * ORBIT_SPEED;
        self.pitch = (self.pitch + dy * ORBIT_SPEED).clamp(-MAX_PITCH, MAX_PITCH);
    }

    /// A right drag of (dx, dy) pixels turns the view with the eye fixed.
    pub fn look(&mut self, dx: f32, dy: f32) {
        let eye = self.position();
        self.rotate(dx, dy);
        self.target += eye - self.position();
    }

    /// Moves eye and target by `forward`, `right` and `up` scene units
    /// along the view's axes.
    pub fn fly(&mut self, forward: f32, right: f32, up: f32) {
        let camera = self.camera(1, 1);
        let (f, r, u, _) = camera.basis();
        self.target += f * forward + r * right + u * up;
    }

    /// A drag of (dx, dy) pixels over a `size` = [width, height] image
    /// moves target and eye across the view, by about the distance a
    /// point at the target moves on screen.
    pub fn pan(&mut self, dx: f32, dy: f32, size: [u32; 2]) {
        let [width, height] = size.map(|n| n.max(1));
        let camera = self.camera(width, height);
        let (_, right, up, tan_half_fov) = camera.basis();
        let per_pixel = 2.0 * self.distance * tan_half_fov / height as f32;
        self.target += (-dx * right + dy * up) * per_pixel;
    }

    /// `lines` wheel lines toward the target (negative: away).
    pub fn zoom(&mut self, lines: f32) {
        self.distance = (self.distance * ZOOM_STEP.powf(lines)).clamp(1e-4, 1e7);
    }

    /// Two fingers spread `ratio` times as far apart as before: the eye
    /// comes that many times closer to the target (a pinch on a touch screen).
    pub fn pinch(&mut self, ratio: f32) {
        if ratio.is_finite() && ratio > 0.0 {
            self.distance = (self.distance / ratio).clamp(1e-4, 1e7);
        }
    }

    /// The view as a scene file's `[camera]` table.
    pub fn toml(&self, width: u32, height: u32) -> String {
        let v = |p: Vec3| format!("[{}, {}, {}]", p.x, p.y, p.z);
        format!(
            "[camera]\nposition = {}\nlook_at = {}\nup = {}\nfov_y = {}\nresolution = [{width}, {height}]\n",
            v(self.position()),
            v(self.target),
            v(self.up),
            self.fov_y_for(width, height)
        )
    }
}

/// Two unit vectors perpendicular to `up` and to each other.
fn frame(up: Vec3) -> (Vec3, Vec3) {
    let forward = up.any_orthonormal_vector();
    (up.cross(forward), forward)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn camera() -> Camera {
        Camera::new(Vec3::new(0.3, 0.4, 3.5), Vec3::new(0.0, 0.1, 0.0), Vec3::Y, 40.0, 64, 48).unwrap()
    }

    /// A window narrower than the scene's image (a phone upright) still
    /// spans the scene camera's horizontal view: the rays through its left
    /// and right edges are the scene camera's; a wider window keeps the
    /// vertical field of view.
    #[test]
    fn a_narrow_window_keeps_the_scenes_width_in_view() {
        let scene = camera();
        let orbit = Orbit::new(&scene);
        let edge = |c: &Camera, x: f32| c.ray(glam::Vec2::new(x, c.height as f32 * 0.5)).dir;
        for (w, h) in [(39, 84), (48, 48), (30, 90)] {
            let narrow = orbit.camera(w, h);
            assert!(narrow.fov_y > scene.fov_y, "{w}x{h}");
            for (x_narrow, x_scene) in [(0.0, 0.0), (w as f32, scene.width as f32)] {
                let (a, b) = (edge(&narrow, x_narrow), edge(&scene, x_scene));
                assert!((a - b).length() < 1e-5, "{w}x{h}: {a} vs {b}");
            }
        }
        for (w, h) in [(64, 48), (128, 48)] {
            assert_eq!(orbit.camera(w, h).fov_y, scene.fov_y);
        }
        assert!(orbit.toml(39, 84).contains(&format!("fov_y = {}", orbit.camera(39, 84).fov_y)));
    }

    #[test]
    fn the_orbit_starts_at_the_scene_camera() {
        let orbit = Orbit::new(&camera());
        assert!((orbit.position() - camera().position).length() < 1e-5, "{}", orbit.position());
        let c = orbit.camera(64, 48);
        assert!((c.look_at - camera().look_at).length() < 1e-6);
    }

    #[test]
    fn rotating_keeps_the_distance_and_reset_returns() {
        let mut orbit = Orbit::new(&camera());
        let d = orbit.distance;
        orbit.rotate(120.0, -40.0);
        assert!(((orbit.position() - orbit.target).length() - d).abs() < 1e-4);
        assert!((orbit.position() - camera().position).length() > 0.1);
        orbit.rotate(0.0, 1e6);
        assert!(orbit.pitch <= MAX_PITCH);
        orbit.camera(64, 48); // still a valid camera at the pole limit
        orbit.reset();
        assert!((orbit.position() - camera().position).length() < 1e-5);
    }

    #[test]
    fn looking_keeps_the_eye_and_flying_keeps_the_view() {
        let mut orbit = Orbit::new(&camera());
        let eye = orbit.position();
        orbit.look(50.0, 20.0);
        assert!((orbit.position() - eye).length() < 1e-4);
        assert!((orbit.target - camera().look_at).length() > 0.1);
        let forward = orbit.camera(64, 48).basis().0;
        orbit.fly(0.5, 0.0, 0.0);
        assert!((orbit.position() - (eye + forward * 0.5)).length() < 1e-4);
        assert!((orbit.camera(64, 48).basis().0 - forward).length() < 1e-5);
    }

    #[test]
    fn a_pinch_scales_the_distance() {
        let mut orbit = Orbit::new(&camera());
        let before = orbit.distance;
        orbit.pinch(2.0);
        assert!((orbit.distance - before / 2.0).abs() < 1e-5 * before);
        orbit.pinch(0.0);
        orbit.pinch(f32::NAN);
        assert!((orbit.distance - before / 2.0).abs() < 1e-5 * before);
    }

    #[test]
    fn zoom_and_pan_move_as_asked() {
        let mut orbit = Orbit::new(&camera());
        let d = orbit.distance;
        orbit.zoom(2.0);
        assert!((orbit.distance - d * 0.81).abs() < 1e-5);
        let target = orbit.target;
        orbit.pan(10.0, 0.0, [64, 48]);
        let right = orbit.camera(64, 48).basis().1;
        // Dragging right moves the scene right: the target moves left.
        assert!((orbit.target - target).dot(right) < 0.0);
    }

    /// A pan drags the point at the target with the cursor, in a window
    /// as wide as the scene's image and in one narrower (wider field).
    #[test]
    fn a_pan_moves_the_target_with_the_cursor() {
        for size in [[64, 48], [30, 90]] {
            let mut orbit = Orbit::new(&camera());
            let target = orbit.target;
            orbit.pan(7.0, -3.0, size);
            let seen = orbit.camera(size[0], size[1]).raster(target).unwrap();
            let centre = glam::Vec2::new(size[0] as f32, size[1] as f32) * 0.5;
            assert!((seen - centre - glam::Vec2::new(7.0, -3.0)).length() < 1e-3, "{size:?}: {seen}");
        }
    }

    #[test]
    fn the_printed_camera_loads_back() {
        let mut orbit = Orbit::new(&camera());
        orbit.rotate(33.0, 12.0);
        let text = format!(
            "{}\n[[material]]\nname = \"w\"\ntype = \"diffuse\"\nalbedo = [0.5, 0.5, 0.5]\n\n[[object]]\nshape = \"sphere\"\ncenter = [0.0, 0.0, 0.0]\nradius = 1.0\nmaterial = \"w\"\n\n[[light]]\ntype = \"point\"\nposition = [0.0, 2.0, 2.0]\nintensity = [1.0, 1.0, 1.0]\n",
            orbit.toml(64, 48)
        );
        let scene = hikari_core::scene::Scene::from_toml(&text, "printed", None).unwrap();
        assert!((scene.camera.position - orbit.position()).length() < 1e-5);
        assert_eq!((scene.camera.width, scene.camera.height), (64, 48));
    }
}

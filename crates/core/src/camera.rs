//! Pinhole camera. Right-handed, +y up; pixel (0,0) is the top-left corner and
//! pixel coordinates are continuous, pixel (i,j) covering [i,i+1)×[j,j+1).

use crate::geometry::Ray;
use crate::scene::limits;
use glam::{Mat4, Vec2, Vec3, Vec4};

#[derive(Clone, Debug)]
pub struct Camera {
    pub position: Vec3,
    pub look_at: Vec3,
    pub up: Vec3,
    /// Full vertical field of view, degrees.
    pub fov_y: f32,
    pub width: u32,
    pub height: u32,
    /// A sub-pixel offset (pixels, each component in [−0.5, 0.5]) of every
    /// sample: the ray "through pixel p" goes through p + jitter, and the
    /// projection moves the image by −jitter to match. Progressive GPU
    /// passes change it each pass, so their mean covers each pixel's square
    /// as the CPU's samples do (antialiasing); zero otherwise.
    pub jitter: Vec2,
    forward: Vec3,
    right: Vec3,
    true_up: Vec3,
    tan_half_fov: f32,
}

impl Camera {
    /// Fails with a reason if the camera is degenerate.
    pub fn new(position: Vec3, look_at: Vec3, up: Vec3, fov_y: f32, width: u32, height: u32) -> Result<Self, String> {
        let forward = (look_at - position).normalize_or_zero();
        if forward == Vec3::ZERO {
            return Err("camera position and look_at coincide".into());
        }
        let right = forward.cross(up).normalize_or_zero();
        if right == Vec3::ZERO || forward.cross(up.normalize_or_zero()).length() < 1e-4 {
            return Err("camera up is zero or parallel to the viewing direction".into());
        }
        let (fov_min, fov_max) = limits::FOV_Y;
        if !(fov_y >= fov_min && fov_y <= fov_max) {
            return Err(format!("fov_y = {fov_y} must lie between {fov_min} and {fov_max} degrees"));
        }
        if width == 0 || height == 0 {
            return Err(format!("resolution {width}x{height} has a zero side"));
        }
        if width > limits::MAX_SIDE || height > limits::MAX_SIDE {
            return Err(format!("resolution {width}x{height}: each side must be at most {}", limits::MAX_SIDE));
        }
        if width as u64 * height as u64 > limits::MAX_PIXELS {
            return Err(format!("resolution {width}x{height} has more than {} pixels (8192x8192)", limits::MAX_PIXELS));
        }
        Ok(Camera {
            position,
            look_at,
            up,
            fov_y,
            width,
            height,
            jitter: Vec2::ZERO,
            forward,
            right,
            true_up: right.cross(forward),
            tan_half_fov: (fov_y.to_radians() * 0.5).tan(),
        })
    }

    pub fn with_resolution(&self, width: u32, height: u32) -> Result<Self, String> {
        Camera::new(self.position, self.look_at, self.up, self.fov_y, width, height)
    }

    pub fn aspect(&self) -> f32 {
        self.width as f32 / self.height as f32
    }

    /// Primary ray through continuous pixel coordinates `pixel`.
    pub fn ray(&self, pixel: Vec2) -> Ray {
        let pixel = pixel + self.jitter;
        let x = (2.0 * pixel.x / self.width as f32 - 1.0) * self.tan_half_fov * self.aspect();
        let y = (1.0 - 2.0 * pixel.y / self.height as f32) * self.tan_half_fov;
        Ray::new(self.position, (self.forward + self.right * x + self.true_up * y).normalize())
    }

    pub fn forward(&self) -> Vec3 {
        self.forward
    }

    /// The distance, in pixels, from the eye to an image plane whose pixels
    /// are one unit square: a ray at angle θ off the axis then crosses
    /// solid angle cos³θ / D² per pixel, what light tracing divides by.
    pub fn image_plane_distance(&self) -> f32 {
        self.height as f32 / (2.0 * self.tan_half_fov)
    }

    /// The continuous pixel coordinates `ray` would take to pass through
    /// world point `p` (jitter included), or None for points behind the
    /// eye or outside the image.
    pub fn raster(&self, p: Vec3) -> Option<Vec2> {
        let d = p - self.position;
        let z = d.dot(self.forward);
        if z <= 0.0 {
            return None;
        }
        let x = d.dot(self.right) / (z * self.tan_half_fov * self.aspect());
        let y = d.dot(self.true_up) / (z * self.tan_half_fov);
        let pixel = Vec2::new((x + 1.0) * 0.5 * self.width as f32, (1.0 - y) * 0.5 * self.height as f32) - self.jitter;
        let inside = pixel.x >= 0.0 && pixel.y >= 0.0 && pixel.x < self.width as f32 && pixel.y < self.height as f32;
        inside.then_some(pixel)
    }

    /// (forward, right, up, tan(fov_y/2)): what `ray` builds directions from,
    /// for shaders that cast the same primary rays.
    pub fn basis(&self) -> (Vec3, Vec3, Vec3, f32) {
        (self.forward, self.right, self.true_up, self.tan_half_fov)
    }

    /// World-to-view transform: view space is right-handed, looking down −z.
    pub fn view_from_world(&self) -> Mat4 {
        view_from_world(self.position, self.forward, self.true_up)
    }

    /// Perspective projection to wgpu clip space (depth 0 at `near`, 1 at
    /// `far`), matching `ray`: the ray through a pixel centre projects there.
    /// With a `jitter`, the image moves by −jitter pixels, so the pixel
    /// centre p sees what p + jitter sees unjittered, as `ray` does.
    pub fn clip_from_view(&self, near: f32, far: f32) -> Mat4 {
        let shift = Vec3::new(-2.0 * self.jitter.x / self.width as f32, 2.0 * self.jitter.y / self.height as f32, 0.0);
        Mat4::from_translation(shift) * clip_from_view(self.fov_y.to_radians(), self.aspect(), near, far)
    }
}

/// World-to-view transform for an eye at `position` looking along unit
/// `forward`, with `up` (not parallel to it) giving the vertical.
pub fn view_from_world(position: Vec3, forward: Vec3, up: Vec3) -> Mat4 {
    let r = forward.cross(up).normalize();
    let u = r.cross(forward);
    let f = forward;
    Mat4::from_cols(
        Vec4::new(r.x, u.x, -f.x, 0.0),
        Vec4::new(r.y, u.y, -f.y, 0.0),
        Vec4::new(r.z, u.z, -f.z, 0.0),
        Vec4::new(-r.dot(position), -u.dot(position), f.dot(position), 1.0),
    )
}

/// Right-handed perspective projection to wgpu clip space: vertical field
/// `fov_y` (radians), depth 0 at `near` and 1 at `far`.
pub fn clip_from_view(fov_y: f32, aspect: f32, near: f32, far: f32) -> Mat4 {
    let fy = 1.0 / (fov_y * 0.5).tan();
    let fx = fy / aspect;
    let a = far / (near - far);
    Mat4::from_cols(
        Vec4::new(fx, 0.0, 0.0, 0.0),
        Vec4::new(0.0, fy, 0.0, 0.0),
        Vec4::new(0.0, 0.0, a, -1.0),
        Vec4::new(0.0, 0.0, a * near, 0.0),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `raster` inverts `ray`, and the image-plane distance gives each
    /// pixel the solid angle its rays span.
    #[test]
    fn raster_inverts_ray() {
        let camera = Camera::new(Vec3::new(0.3, 0.2, 4.0), Vec3::ZERO, Vec3::Y, 40.0, 64, 48).unwrap();
        for pixel in [Vec2::new(0.5, 0.5), Vec2::new(63.9, 20.25), Vec2::new(31.0, 47.5), Vec2::new(10.0, 0.1)] {
            let ray = camera.ray(pixel);
            let back = camera.raster(ray.at(2.5)).unwrap();
            assert!((back - pixel).length() < 1e-3, "{pixel} -> {back}");
        }
        assert_eq!(camera.raster(camera.position - camera.forward()), None);
        assert_eq!(camera.raster(camera.ray(Vec2::new(-0.5, 3.0)).at(1.0)), None);
        // The centre pixel spans about 1/D² sr.
        let d = camera.image_plane_distance();
        let (a, b) = (camera.ray(Vec2::new(32.0, 24.0)), camera.ray(Vec2::new(33.0, 24.0)));
        let angle = a.dir.angle_between(b.dir);
        assert!((angle * d - 1.0).abs() < 1e-3, "{angle} rad per pixel, D = {d}");
    }

    #[test]
    fn centre_ray_looks_at_target_and_top_left_is_up_left() {
        let cam = Camera::new(Vec3::new(0.0, 0.0, 4.0), Vec3::ZERO, Vec3::Y, 40.0, 64, 32).unwrap();
        let c = cam.ray(Vec2::new(32.0, 16.0));
        assert!((c.dir - Vec3::NEG_Z).length() < 1e-6);
        let tl = cam.ray(Vec2::ZERO);
        assert!(tl.dir.x < 0.0 && tl.dir.y > 0.0);
        let top = cam.ray(Vec2::new(32.0, 0.0));
        assert!((top.dir.y.atan2(-top.dir.z).to_degrees() - 20.0).abs() < 1e-3);
    }

    #[test]
    fn projection_matches_primary_rays() {
        let mut cam = Camera::new(Vec3::new(0.3, 0.2, 4.0), Vec3::new(0.1, -0.1, 0.0), Vec3::Y, 40.0, 64, 48).unwrap();
        projection_matches(&cam);
        // Jittered: the ray through p goes through p + jitter, and projects back to p.
        let straight = cam.ray(Vec2::new(10.75, 40.25));
        cam.jitter = Vec2::new(0.25, -0.25);
        assert!((cam.ray(Vec2::new(10.5, 40.5)).dir - straight.dir).length() < 1e-6);
        projection_matches(&cam);
    }

    fn projection_matches(cam: &Camera) {
        let clip_from_world = cam.clip_from_view(0.1, 100.0) * cam.view_from_world();
        for pixel in [Vec2::new(0.5, 0.5), Vec2::new(10.5, 40.5), Vec2::new(63.5, 0.5)] {
            let p = cam.ray(pixel).at(3.7);
            let clip = clip_from_world * p.extend(1.0);
            let ndc = clip.truncate() / clip.w;
            let back = Vec2::new((ndc.x + 1.0) * 0.5 * 64.0, (1.0 - ndc.y) * 0.5 * 48.0);
            assert!((back - pixel).length() < 1e-3, "{pixel} -> {back}");
            assert!(ndc.z > 0.0 && ndc.z < 1.0);
        }
    }

    #[test]
    fn degenerate_cameras_are_rejected() {
        assert!(Camera::new(Vec3::ONE, Vec3::ONE, Vec3::Y, 40.0, 8, 8).is_err());
        assert!(Camera::new(Vec3::ZERO, Vec3::Y, Vec3::Y, 40.0, 8, 8).is_err());
        assert!(Camera::new(Vec3::ZERO, Vec3::Z, Vec3::Y, 180.0, 8, 8).is_err());
        assert!(Camera::new(Vec3::ZERO, Vec3::Z, Vec3::Y, 40.0, 0, 8).is_err());
    }

    #[test]
    fn field_of_view_and_resolution_are_bounded() {
        let cam = |fov, w, h| Camera::new(Vec3::ZERO, Vec3::Z, Vec3::Y, fov, w, h);
        for fov in [0.009, 179.5, 1e30] {
            assert!(cam(fov, 8, 8).unwrap_err().contains("fov_y"), "{fov}");
        }
        assert!(cam(0.01, 8, 8).is_ok() && cam(179.0, 8, 8).is_ok());
        assert!(cam(40.0, 16385, 1).unwrap_err().contains("at most 16384"));
        assert!(cam(40.0, 16384, 4096).is_ok());
        assert!(cam(40.0, 16384, 4097).unwrap_err().contains("pixels"));
        assert!(cam(40.0, 100_000, 100_000).is_err());
    }
}

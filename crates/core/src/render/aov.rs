//! The auxiliary images denoisers take beside the colour (Blender's
//! "Denoising Albedo", "Denoising Normal" and "Depth", OIDN's albedo and
//! normal): what the eye sees, not how light reached it, so one pass of
//! camera rays makes them for every renderer. Through mirrors and smooth
//! glass the eye sees the first surface that is not a perfect specular one
//! (glass refracts, or reflects where light cannot leave it).

use super::Image;
use crate::geometry::Ray;
use crate::material::{Material, dielectric_split, reflect};
use crate::scene::Scene;
use glam::{Vec2, Vec3};
use rayon::prelude::*;

/// Sample positions per pixel side: 4 × 4 stratified samples, the same in
/// every pixel and every run (no random numbers: the images are exact).
const SIDE: u32 = 4;
/// Mirrors and glass followed at most this many times.
const MAX_SPECULAR: u32 = 16;

/// The three images, each `width` × `height`, row-major, row 0 at the top.
#[derive(Clone, Debug, PartialEq)]
pub struct Aovs {
    /// The reflectance of the first non-specular surface seen (a diffuse
    /// albedo plus its specular tint; a glTF material's base colour with
    /// its textures), averaged over the pixel; black where nothing is hit
    /// and on emitters.
    pub albedo: Image,
    /// That surface's shading normal in world space, facing the ray that
    /// found it, averaged over the pixel and made unit length (zero where
    /// nothing is hit).
    pub normal: Image,
    /// The distance along the camera ray through the pixel's centre to the
    /// first surface it hits; infinity where it hits nothing.
    pub depth: Vec<f32>,
}

/// What one camera ray sees.
struct Seen {
    albedo: Vec3,
    normal: Vec3,
}

/// The AOVs of `scene` through its camera (its jitter included).
pub fn render_aovs(scene: &Scene) -> Aovs {
    let camera = &scene.camera;
    let (w, h) = (camera.width, camera.height);
    let pixels: Vec<(Vec3, Vec3, f32)> = (0..w * h)
        .into_par_iter()
        .map(|i| {
            let (x, y) = ((i % w) as f32, (i / w) as f32);
            let mut albedo = Vec3::ZERO;
            let mut normal = Vec3::ZERO;
            for s in 0..SIDE * SIDE {
                let offset = Vec2::new((s % SIDE) as f32 + 0.5, (s / SIDE) as f32 + 0.5) / SIDE as f32;
                if let Some(seen) = see(scene, camera.ray(Vec2::new(x, y) + offset)) {
                    albedo += seen.albedo;
                    normal += seen.normal;
                }
            }
            let depth =
                scene.accel.intersect(&camera.ray(Vec2::new(x + 0.5, y + 0.5))).map_or(f32::INFINITY, |hit| hit.t);
            (albedo / (SIDE * SIDE) as f32, normal.normalize_or_zero(), depth)
        })
        .collect();
    let image =
        |f: fn(&(Vec3, Vec3, f32)) -> Vec3| Image { width: w, height: h, pixels: pixels.iter().map(f).collect() };
    Aovs { albedo: image(|p| p.0), normal: image(|p| p.1), depth: pixels.iter().map(|p| p.2).collect() }
}

/// The first non-specular surface along `ray`, through mirrors and glass.
fn see(scene: &Scene, mut ray: Ray) -> Option<Seen> {
    for _ in 0..=MAX_SPECULAR {
        let hit = scene.accel.intersect(&ray)?;
        let facing = if ray.dir.dot(hit.geometric_normal) < 0.0 { 1.0 } else { -1.0 };
        let normal = scene.shading_normal_at(&hit, ray.dir) * facing;
        let next = match scene.material_at(&hit).into_owned() {
            Material::Diffuse { albedo, specular } => return Some(Seen { albedo: albedo + specular, normal }),
            Material::Pbr(bsdf) => return Some(Seen { albedo: bsdf.base_color, normal }),
            Material::Emitter => return Some(Seen { albedo: Vec3::ZERO, normal }),
            Material::Mirror { .. } => reflect(ray.dir, normal),
            Material::Glass(glass) => {
                let split = dielectric_split(ray.dir, hit.geometric_normal, glass.ior);
                split.refracted.unwrap_or(split.reflected)
            }
        };
        ray = Ray::new(hit.point, next);
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;

    fn scene(text: &str) -> Scene {
        Scene::from_toml(text, "aov-test.toml", None).unwrap()
    }

    const CAMERA: &str = "[camera]\nposition = [0.0, 0.0, 5.0]\nlook_at = [0.0, 0.0, 0.0]\nfov_y = 20.0\nresolution = [8, 8]\n\
        [[light]]\ntype = \"point\"\nposition = [0.0, 3.0, 3.0]\nintensity = [1.0, 1.0, 1.0]\n";

    /// A diffuse wall facing the camera 5 units away fills the view: its
    /// albedo, its normal toward the eye, and the distance along each
    /// centre ray, 5 / cos of the ray's angle to the axis.
    #[test]
    fn a_wall_facing_the_eye() {
        let s = scene(&format!(
            "{CAMERA}[[material]]\nname = \"w\"\ntype = \"diffuse\"\nalbedo = [0.2, 0.4, 0.6]\n\
             [[object]]\nshape = \"quad\"\ncorner = [-5.0, -5.0, 0.0]\nedge_u = [10.0, 0.0, 0.0]\nedge_v = [0.0, 10.0, 0.0]\nmaterial = \"w\"\n"
        ));
        let aovs = render_aovs(&s);
        for (i, ((albedo, normal), depth)) in
            aovs.albedo.pixels.iter().zip(&aovs.normal.pixels).zip(&aovs.depth).enumerate()
        {
            assert!((*albedo - Vec3::new(0.2, 0.4, 0.6)).abs().max_element() < 1e-6, "{albedo}");
            assert!((*normal - Vec3::Z).abs().max_element() < 1e-6, "{normal}");
            let (x, y) = ((i % 8) as f32 + 0.5, (i / 8) as f32 + 0.5);
            let dir = s.camera.ray(Vec2::new(x, y)).dir;
            let expected = 5.0 / dir.dot(Vec3::NEG_Z);
            assert!((depth - expected).abs() < 1e-4 * expected, "{depth} {expected}");
        }
    }

    /// Nothing in view: black albedo, zero normal, infinite depth.
    #[test]
    fn nothing_hit() {
        let aovs = render_aovs(&scene(CAMERA));
        assert!(aovs.albedo.pixels.iter().all(|p| *p == Vec3::ZERO));
        assert!(aovs.normal.pixels.iter().all(|p| *p == Vec3::ZERO));
        assert!(aovs.depth.iter().all(|d| *d == f32::INFINITY));
    }

    /// Through a mirror the eye sees the wall behind it: the wall's albedo
    /// and normal, and the depth of the mirror itself.
    #[test]
    fn through_a_mirror() {
        let s = scene(&format!(
            "{CAMERA}[[material]]\nname = \"m\"\ntype = \"mirror\"\nreflectance = [1.0, 1.0, 1.0]\n\
             [[material]]\nname = \"w\"\ntype = \"diffuse\"\nalbedo = [0.5, 0.25, 0.125]\n\
             [[object]]\nshape = \"quad\"\ncorner = [-5.0, -5.0, 0.0]\nedge_u = [10.0, 0.0, 0.0]\nedge_v = [0.0, 10.0, 0.0]\nmaterial = \"m\"\n\
             [[object]]\nshape = \"quad\"\ncorner = [-50.0, -50.0, 10.0]\nedge_u = [0.0, 100.0, 0.0]\nedge_v = [100.0, 0.0, 0.0]\nmaterial = \"w\"\n"
        ));
        let aovs = render_aovs(&s);
        let centre = 4 * 8 + 4;
        assert!((aovs.albedo.pixels[centre] - Vec3::new(0.5, 0.25, 0.125)).abs().max_element() < 1e-6);
        assert!(
            (aovs.normal.pixels[centre] - Vec3::NEG_Z).abs().max_element() < 1e-3,
            "{}",
            aovs.normal.pixels[centre]
        );
        assert!(aovs.depth[centre] < 5.1, "the mirror's depth, {}", aovs.depth[centre]);
    }
}

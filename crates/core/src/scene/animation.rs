//! Moving lights and objects: the scene file's `[[animation]]` entries and
//! the viewer's edits, applied to a scene as loaded to give the scene at one
//! moment (`Scene::posed`).
//!
//! Every motion but a glTF file's deformed meshes is rigid (a rotation and
//! a translation; keyframes may also scale), so a posed scene is as valid
//! as the scene it came from: no radius changes, and only a skin or morph
//! target can squeeze a triangle flat (it then has no area and is missed).
//! Posing is a pure function of the loaded scene and the `Pose`, so
//! the same time (and edits) gives the same scene, bit for bit, and with the
//! same seed the same photon maps.

use super::{Scene, Surface};
use crate::geometry::{Accel, Sphere, Triangle, TriangleNormals};
use crate::light::Light;
use glam::{Affine3A, Vec3};
use std::f32::consts::TAU;

/// What an animation moves.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Target {
    /// A `[[object]]`, by its surface id.
    Object(u32),
    /// A `[[light]]`, by its index in `Scene::lights`.
    Light(u32),
}

/// A periodic motion: rigid for `Rotate` and `Move`; a glTF animation's
/// keyframes may also scale.
#[derive(Clone, Debug, PartialEq)]
pub enum Motion {
    /// A full turn about the line through `center` along the unit `axis`
    /// every `period` seconds (counter-clockwise looking down the axis): a
    /// light away from the line orbits it; an object on it spins.
    Rotate { center: Vec3, axis: Vec3, period: f32 },
    /// From the rest place to `offset` away and back every `period` seconds,
    /// easing in and out: displacement `offset · (1 − cos 2πt/T) / 2`.
    Move { offset: Vec3, period: f32 },
    /// A glTF file's node animation, looping.
    Keyframed(std::sync::Arc<super::keyframes::Keyframes>),
    /// A glTF mesh whose skin's joints or morph weights the file's
    /// animations move: its triangles are reshaped at each time
    /// (`DeformedMesh::triangles_at`), not moved rigidly (its transform here
    /// is the identity).
    Deformed(std::sync::Arc<super::deformation::DeformedMesh>),
}

impl Motion {
    /// The motion's transform at `time` seconds.
    pub fn at(&self, time: f32) -> Affine3A {
        match *self {
            Motion::Rotate { center, axis, period } => {
                // The phase is reduced first so long times keep their precision.
                let angle = TAU * (time / period).rem_euclid(1.0);
                Affine3A::from_translation(center)
                    * Affine3A::from_axis_angle(axis, angle)
                    * Affine3A::from_translation(-center)
            }
            Motion::Move { offset, period } => {
                let phase = TAU * (time / period).rem_euclid(1.0);
                Affine3A::from_translation(offset * (0.5 - 0.5 * phase.cos()))
            }
            Motion::Keyframed(ref keys) => keys.at(time),
            Motion::Deformed(_) => Affine3A::IDENTITY,
        }
    }
}

#[derive(Clone, Debug, PartialEq)]
pub struct Animation {
    pub target: Target,
    pub motion: Motion,
}

/// The names given to objects and lights in the scene file.
#[derive(Clone, Debug, Default)]
pub struct Names {
    /// Named objects and their surface ids, in file order.
    pub objects: Vec<(String, u32)>,
    /// Each light's name, if it has one (indexed like `Scene::lights`).
    pub lights: Vec<Option<String>>,
    /// Each material's name, if it has one (indexed like `Scene::materials`:
    /// a TOML material's `name`, a glTF material's).
    pub materials: Vec<Option<String>>,
}

/// One moment of a scene: the animation time and the user's edits (lights
/// as edited, before their animations; an offset per surface).
#[derive(Clone, Debug, PartialEq)]
pub struct Pose {
    pub time: f32,
    /// One per light of the scene, of the same kind; an edit may move the
    /// anchor, turn a spot's axis and change the emission.
    pub lights: Vec<Light>,
    /// A translation per surface (objects and area lights), applied before
    /// the animations. Area lights move with their `lights` entry instead.
    pub offsets: Vec<Vec3>,
}

impl Scene {
    /// The pose that leaves the scene as loaded: time 0, no edits.
    pub fn rest_pose(&self) -> Pose {
        Pose { time: 0.0, lights: self.lights.clone(), offsets: vec![Vec3::ZERO; self.surfaces.len()] }
    }

    /// Whether the scene moves by itself (has animations).
    pub fn is_animated(&self) -> bool {
        !self.animations.is_empty()
    }

    /// The scene at `time` seconds of its animations, without edits.
    pub fn at_time(&self, time: f32) -> Scene {
        self.posed(&Pose { time, ..self.rest_pose() })
    }

    /// The scene in `pose`. `self` is the scene as loaded (a posed scene
    /// posed again would move twice). Its BVH is built afresh on first use,
    /// the best tree for a render.
    pub fn posed(&self, pose: &Pose) -> Scene {
        self.posed_with(pose, false)
    }

    /// The scene in `pose` for one frame of an interactive view: as
    /// [`Scene::posed`], but its BVH is the loaded scene's refitted to the
    /// pose where that costs traversals little (`Accel::build_moved`): a
    /// linear pass instead of a build (a 100,000-triangle character: ~25 ms
    /// less per pose on one core).
    pub fn posed_for_frame(&self, pose: &Pose) -> Scene {
        self.posed_with(pose, true)
    }

    fn posed_with(&self, pose: &Pose, refit: bool) -> Scene {
        assert_eq!(pose.lights.len(), self.lights.len(), "a pose has one light per scene light");
        assert_eq!(pose.offsets.len(), self.surfaces.len(), "a pose has one offset per surface");
        let motion_of = |target: Target| {
            self.animations
                .iter()
                .filter(|a| a.target == target)
                .fold(Affine3A::IDENTITY, |m, a| a.motion.at(pose.time) * m)
        };
        let mut lights: Vec<Light> =
            pose.lights.iter().enumerate().map(|(i, light)| light.moved(&motion_of(Target::Light(i as u32)))).collect();
        // Per surface: the edit's translation, then the animations.
        let surface_motion: Vec<Affine3A> = self
            .surfaces
            .iter()
            .enumerate()
            .map(|(s, surface): (usize, &Surface)| match surface.emitter {
                Some(l) => {
                    let shift = pose.lights[l as usize].anchor() - self.lights[l as usize].anchor();
                    motion_of(Target::Light(l)) * Affine3A::from_translation(shift)
                }
                None => motion_of(Target::Object(s as u32)) * Affine3A::from_translation(pose.offsets[s]),
            })
            .collect();
        let moved = |s: u32| &surface_motion[s as usize];
        let (mut triangles, triangle_surfaces): (Vec<Triangle>, Vec<u32>) = self
            .accel
            .triangles()
            .map(|(t, s)| {
                let m = moved(s);
                let v = t.v.map(|p| m.transform_point3(p));
                let normals =
                    t.normals.map(|TriangleNormals(n)| TriangleNormals(n.map(|x| m.transform_vector3(x).normalize())));
                (Triangle { v, normals }, s)
            })
            .unzip();
        // Deformed surfaces are reshaped at this time, then moved by their
        // edits and rigid motions (their triangles are one run, in the order
        // the mesh keeps).
        for animation in &self.animations {
            let (Target::Object(s), Motion::Deformed(mesh)) = (animation.target, &animation.motion) else { continue };
            let first = triangle_surfaces.iter().position(|&t| t == s).unwrap_or(triangle_surfaces.len());
            let bent = mesh.triangles_at(pose.time, moved(s));
            if first + bent.len() <= triangles.len() {
                triangles[first..first + bent.len()].copy_from_slice(&bent);
            }
        }
        let (spheres, sphere_surfaces): (Vec<Sphere>, Vec<u32>) = self
            .accel
            .spheres()
            .map(|(sphere, s)| (Sphere { center: moved(s).transform_point3(sphere.center), radius: sphere.radius }, s))
            .unzip();
        let mut accel = if refit {
            Accel::build_moved(triangles, triangle_surfaces, spheres, sphere_surfaces, &self.accel)
        } else {
            Accel::build(triangles, triangle_surfaces, spheres, sphere_surfaces)
        };
        accel.set_alpha_mask(self.accel.alpha_mask().cloned());
        // The sun and sky cover the scene where it now is.
        crate::light::fit_distant_lights(&mut lights, accel.bounds());
        Scene {
            source: self.source.clone(),
            camera: self.camera.clone(),
            materials: self.materials.clone(),
            surfaces: self.surfaces.clone(),
            lights,
            accel,
            media: self.media.clone(),
            names: self.names.clone(),
            animations: self.animations.clone(),
            notes: self.notes.clone(),
            texturing: self.texturing.clone(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::photon::{TraceSettings, trace_photons};

    const ANIMATED: &str = r#"
[camera]
position = [0.0, 0.0, 3.9]
look_at = [0.0, 0.0, 0.0]
resolution = [16, 16]

[[material]]
name = "white"
type = "diffuse"
albedo = [0.7, 0.7, 0.7]

[[object]]
shape = "quad"
corner = [-1.0, -1.0, -1.0]
edge_u = [0.0, 0.0, 2.0]
edge_v = [2.0, 0.0, 0.0]
material = "white"

[[object]]
name = "block"
shape = "box"
center = [0.0, -0.7, 0.0]
size = [0.6, 0.6, 0.6]
material = "white"

[[light]]
name = "bulb"
type = "point"
position = [0.5, 0.9, 0.0]
intensity = [2.0, 2.0, 2.0]

[[animation]]
target = "bulb"
type = "rotate"
center = [0.0, 0.9, 0.0]
axis = [0.0, 1.0, 0.0]
period = 4.0

[[animation]]
target = "block"
type = "move"
offset = [0.4, 0.0, 0.0]
period = 2.0
"#;

    fn animated() -> Scene {
        Scene::from_toml(ANIMATED, "animated.toml", None).unwrap()
    }

    #[test]
    fn a_rotation_turns_about_its_axis_through_its_centre() {
        let m = Motion::Rotate { center: Vec3::new(0.0, 0.9, 0.0), axis: Vec3::Y, period: 4.0 };
        // A quarter period: +x goes to −z (counter-clockwise seen from +y).
        let p = m.at(1.0).transform_point3(Vec3::new(0.5, 0.9, 0.0));
        assert!((p - Vec3::new(0.0, 0.9, -0.5)).length() < 1e-6, "{p}");
        assert!((m.at(4.0).transform_point3(Vec3::X) - Vec3::X).length() < 1e-5, "a full period is the identity");
    }

    #[test]
    fn a_move_eases_to_its_offset_at_half_period_and_back() {
        let m = Motion::Move { offset: Vec3::new(0.4, 0.0, 0.0), period: 2.0 };
        let at = |t| m.at(t).transform_point3(Vec3::ZERO);
        assert!(at(0.0).length() < 1e-7);
        assert!((at(1.0) - Vec3::new(0.4, 0.0, 0.0)).length() < 1e-6);
        assert!((at(0.5) - Vec3::new(0.2, 0.0, 0.0)).length() < 1e-6);
        assert!(at(2.0).length() < 1e-6);
    }

    #[test]
    fn the_scene_file_names_and_animates_objects_and_lights() {
        let scene = animated();
        assert!(scene.is_animated());
        assert_eq!(scene.names.objects, vec![("block".to_string(), 1)]);
        assert_eq!(scene.names.lights, vec![Some("bulb".to_string())]);
        let quarter = scene.at_time(1.0);
        assert!((quarter.lights[0].anchor() - Vec3::new(0.0, 0.9, -0.5)).length() < 1e-6);
        // The block moved by its offset at half its period; the floor stayed.
        let centre = |s: &Scene, surface| {
            let points: Vec<Vec3> = s.accel.triangles().filter(|t| t.1 == surface).flat_map(|t| t.0.v).collect();
            points.iter().sum::<Vec3>() / points.len() as f32
        };
        assert!((centre(&quarter, 1) - centre(&scene, 1) - Vec3::new(0.4, 0.0, 0.0)).length() < 1e-5);
        assert!((centre(&quarter, 0) - centre(&scene, 0)).length() < 1e-6);
        // Rest pose at time 0 leaves everything where it was.
        let rest = scene.posed(&scene.rest_pose());
        let bits = |s: &Scene| {
            s.accel.triangles().flat_map(|t| t.0.v).map(|v| v.to_array().map(f32::to_bits)).collect::<Vec<_>>()
        };
        assert_eq!(bits(&rest), bits(&scene));
    }

    #[test]
    fn an_edit_moves_an_area_light_with_its_body() {
        let text = ANIMATED.replace(
            "type = \"point\"\nposition = [0.5, 0.9, 0.0]\nintensity = [2.0, 2.0, 2.0]",
            "type = \"sphere\"\ncenter = [0.5, 0.5, 0.0]\nradius = 0.1\nradiance = [5.0, 5.0, 5.0]",
        );
        let scene = Scene::from_toml(&text, "area.toml", None).unwrap();
        let mut pose = scene.rest_pose();
        pose.lights[0] = pose.lights[0].with_anchor(Vec3::new(-0.5, 0.5, 0.0));
        let moved = scene.posed(&pose);
        let (body, _) = moved.accel.spheres().next().unwrap();
        assert!((body.center - moved.lights[0].anchor()).length() < 1e-6, "the sphere body follows its light");
        assert!((body.center - Vec3::new(-0.5, 0.5, 0.0)).length() < 1e-6);
    }

    /// Posing refits the sun's disc to where the scene now is, and turns
    /// the sun with its animation.
    #[test]
    fn a_posed_scene_refits_the_distant_lights() {
        let text = format!(
            "{ANIMATED}\n[[light]]\nname = \"sun\"\ntype = \"directional\"\ndirection = [0.0, -1.0, 0.0]\nirradiance = [1.0, 1.0, 1.0]\n\n[[animation]]\ntarget = \"sun\"\ntype = \"rotate\"\ncenter = [0.0, 0.0, 0.0]\naxis = [0.0, 0.0, 1.0]\nperiod = 4.0\n"
        );
        let scene = Scene::from_toml(&text, "sun.toml", None).unwrap();
        // The block pushed 2 along +x, past the floor's edge, at t = 1.
        let mut pose = Pose { time: 1.0, ..scene.rest_pose() };
        pose.offsets[1] = Vec3::new(2.0, 0.0, 0.0);
        let posed = scene.posed(&pose);
        let Light::Directional { direction, disc, .. } = posed.lights[1] else { unreachable!() };
        let mut refit = posed.lights.clone();
        crate::light::fit_distant_lights(&mut refit, posed.accel.bounds());
        assert_eq!(Some(disc), refit[1].distant_disc());
        assert!(disc.center.x > scene.lights[1].distant_disc().unwrap().center.x + 0.01, "{disc:?}");
        // A quarter turn about +z: −y goes to +x.
        assert!((direction - Vec3::X).length() < 1e-5, "{direction}");
    }

    #[test]
    fn animations_with_unknown_targets_or_bad_periods_are_located_errors() {
        let bad = ANIMATED.replace("target = \"bulb\"", "target = \"lamp\"");
        let e = Scene::from_toml(&bad, "bad.toml", None).err().unwrap().to_string();
        assert!(e.contains("bad.toml:") && e.contains("\"lamp\"") && e.contains("bulb"), "{e}");
        let bad = ANIMATED.replace("period = 4.0", "period = 0.0");
        let e = Scene::from_toml(&bad, "bad.toml", None).err().unwrap().to_string();
        assert!(e.contains("[[animation]] #1") && e.contains("period"), "{e}");
        let bad = ANIMATED.replace("offset = [0.4, 0.0, 0.0]", "center = [0.0, 0.0, 0.0]");
        let e = Scene::from_toml(&bad, "bad.toml", None).err().unwrap().to_string();
        assert!(e.contains("[[animation]] #2"), "{e}");
        let bad = ANIMATED.replace("name = \"bulb\"", "name = \"block\"");
        let e = Scene::from_toml(&bad, "bad.toml", None).err().unwrap().to_string();
        assert!(e.contains("already"), "{e}");
    }

    #[test]
    fn the_same_time_and_seed_give_the_same_photons_whatever_the_thread_count() {
        let scene = animated();
        let trace = |threads: usize, time: f32| {
            let posed = scene.at_time(time);
            let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
            let settings = TraceSettings { photons: 20_000, seed: 3, ..Default::default() };
            let traced = pool.install(|| trace_photons(&posed, &settings, &crate::progress::Silent));
            traced.global.iter().map(|p| (p.position.map(f32::to_bits), p.power_rgb9e5)).collect::<Vec<_>>()
        };
        let one = trace(1, 1.3);
        assert!(one.len() > 1000);
        assert_eq!(one, trace(2, 1.3), "1 and 2 threads");
        assert_eq!(one, trace(3, 1.3), "1 and 3 threads");
        assert_ne!(one, trace(2, 0.3), "another time moves the photons");
    }
}

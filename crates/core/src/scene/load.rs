//! Turns a parsed scene description into a `Scene`, checking every value.

use super::desc::{
    AnimationDesc, CameraDesc, EnvironmentDesc, LightDesc, MaterialDesc, MediumDesc, ObjectDesc, SceneDesc, V3,
};
use super::error::{SceneError, line_col};
use super::files::SceneFiles;
use super::limits::{self, MAX_COORD, MAX_EMISSION, MIN_LENGTH};
use super::{Animation, Motion, Names, Scene, Surface, Target};
use crate::camera::Camera;
use crate::geometry::{Accel, Sphere, Triangle, TriangleNormals};
use crate::light::{Disc, Light};
use crate::material::{Material, mean};
use crate::medium::{Media, Medium, Phase, RegionMesh};
use glam::{Mat3, Vec3};
use std::collections::HashMap;
use std::ops::Range;
use std::path::Path;

/// Where we are in the file, for error messages.
struct Place<'a> {
    file: &'a str,
    text: &'a str,
    span: Range<usize>,
    context: String,
}

impl Place<'_> {
    fn error(&self, message: impl Into<String>) -> SceneError {
        SceneError {
            file: self.file.to_string(),
            position: Some(line_col(self.text, self.span.start)),
            context: self.context.clone(),
            message: message.into(),
        }
    }

    /// A point or vector: finite, each component within ±`MAX_COORD`.
    fn coord(&self, field: &str, v: V3) -> Result<Vec3, SceneError> {
        if !v.iter().all(|x| x.is_finite()) {
            return Err(self.error(format!("`{field}` = {v:?} is not finite")));
        }
        if v.iter().any(|x| x.abs() > MAX_COORD) {
            return Err(self.error(format!("`{field}` = {v:?} has a component beyond ±{MAX_COORD:e}")));
        }
        Ok(Vec3::from(v))
    }

    /// A direction of any non-zero length (within ±`MAX_COORD`), made unit.
    fn direction(&self, field: &str, v: V3) -> Result<Vec3, SceneError> {
        self.coord(field, v)?.try_normalize().ok_or_else(|| self.error(format!("`{field}` = {v:?} is zero")))
    }

    fn required<T: Copy>(&self, field: &str, v: Option<T>) -> Result<T, SceneError> {
        v.ok_or_else(|| self.error(format!("missing field `{field}`")))
    }

    /// A number in [lo, hi].
    fn in_range(&self, field: &str, v: f32, (lo, hi): (f32, f32)) -> Result<f32, SceneError> {
        if v >= lo && v <= hi {
            Ok(v)
        } else {
            Err(self.error(format!("`{field}` = {v} must lie between {lo:e} and {hi:e}")))
        }
    }

    /// A radius or side: in [`MIN_LENGTH`, 2·`MAX_COORD`].
    fn length(&self, field: &str, v: f32) -> Result<f32, SceneError> {
        self.in_range(field, v, (MIN_LENGTH, 2.0 * MAX_COORD))
    }

    /// An RGB triple with each component in [0, max].
    fn color(&self, field: &str, v: V3, max: f32) -> Result<Vec3, SceneError> {
        if !v.iter().all(|x| x.is_finite()) {
            return Err(self.error(format!("`{field}` = {v:?} is not finite")));
        }
        let c = Vec3::from(v);
        if c.min_element() < 0.0 {
            return Err(self.error(format!("`{field}` = {v:?} has a negative component")));
        }
        if c.max_element() > max {
            return Err(self.error(format!("`{field}` = {v:?} has a component above {max}")));
        }
        Ok(c)
    }

    /// Rejects fields that were given but do not apply to this entry's kind.
    fn only(&self, kind: &str, given: &[(&str, bool)], allowed: &[&str]) -> Result<(), SceneError> {
        for (name, present) in given {
            if *present && !allowed.contains(name) {
                return Err(self.error(format!("field `{name}` does not apply to {kind}")));
            }
        }
        Ok(())
    }
}

pub fn parse(text: &str, file: &str, files: SceneFiles) -> Result<Scene, SceneError> {
    let desc: SceneDesc = toml::from_str(text).map_err(|e| SceneError {
        file: file.to_string(),
        position: e.span().map(|s| line_col(text, s.start)),
        context: String::new(),
        message: e.message().trim().to_string(),
    })?;
    let place = |span: Range<usize>, context: String| Place { file, text, span, context };

    let camera = load_camera(desc.camera.get_ref(), &place(desc.camera.span(), "[camera]".into()))?;

    let mut materials = Vec::new();
    let mut by_name = HashMap::new();
    for (i, m) in desc.material.iter().enumerate() {
        let p = place(m.span(), format!("[[material]] #{} \"{}\"", i + 1, m.get_ref().name));
        if by_name.insert(m.get_ref().name.clone(), materials.len() as u32).is_some() {
            return Err(p.error("a material with this name is already defined"));
        }
        materials.push(load_material(m.get_ref(), &p)?);
    }

    let mut geometry = GeometryBuilder::default();
    let mut names = Names::default();
    names.materials = desc.material.iter().map(|m| Some(m.get_ref().name.clone())).collect();
    // Animation targets, by name: objects and lights share one namespace.
    let mut targets: HashMap<String, Target> = HashMap::new();
    let mut name = |p: &Place, name: &Option<String>, target: Target| -> Result<Option<String>, SceneError> {
        let Some(name) = name else { return Ok(None) };
        if targets.insert(name.clone(), target).is_some() {
            return Err(p.error(format!("an object or light named \"{name}\" is already defined")));
        }
        Ok(Some(name.clone()))
    };
    let mut lights = Vec::new();
    let mut texturing = crate::texture::Texturing::default();
    // What glTF objects bring besides geometry: their animations and notes.
    let (mut gltf_animations, mut notes) = (Vec::new(), Vec::new());
    for (i, o) in desc.object.iter().enumerate() {
        let p = place(o.span(), format!("[[object]] #{}", i + 1));
        let obj = o.get_ref();
        if let Some(file) = &obj.gltf {
            let mut parts = SceneParts {
                materials: &mut materials,
                lights: &mut lights,
                names: &mut names,
                texturing: &mut texturing,
                animations: &mut gltf_animations,
                notes: &mut notes,
            };
            load_gltf_object(obj, file, &p, files, &mut geometry, &mut parts)?;
            continue;
        }
        let Some(material_name) = &obj.material else { return Err(p.error("missing field `material`")) };
        let material = *by_name.get(material_name.get_ref()).ok_or_else(|| {
            let known: Vec<&str> = desc.material.iter().map(|m| m.get_ref().name.as_str()).collect();
            let at = place(material_name.span(), p.context.clone());
            let hint = if known.is_empty() {
                "no [[material]] is defined".to_string()
            } else {
                format!("defined: {}", known.join(", "))
            };
            at.error(format!("unknown material \"{}\" ({hint})", material_name.get_ref()))
        })?;
        let surface = geometry.add_surface(Surface { material, emitter: None });
        if let Some(n) = name(&p, &obj.name, Target::Object(surface))? {
            names.objects.push((n, surface));
        }
        let start = geometry.counts();
        load_object(obj, &p, files, surface, &mut geometry)?;
        geometry.check_since(start, &p)?;
    }

    for (i, l) in desc.light.iter().enumerate() {
        let p = place(l.span(), format!("[[light]] #{}", i + 1));
        let light = load_light(l.get_ref(), &p)?;
        names.lights.push(name(&p, &l.get_ref().name, Target::Light(lights.len() as u32))?);
        // Area lights are also surfaces: they occlude, and the eye sees them.
        if light.is_area() {
            let emitter_material = materials.len() as u32;
            materials.push(Material::Emitter);
            let surface =
                geometry.add_surface(Surface { material: emitter_material, emitter: Some(lights.len() as u32) });
            let start = geometry.counts();
            match light {
                Light::Sphere { center, radius, .. } => geometry.spheres.push((Sphere { center, radius }, surface)),
                Light::Quad { corner, edge_u, edge_v, .. } => geometry.add_quad(corner, edge_u, edge_v, surface),
                _ => unreachable!("only area lights have geometry"),
            }
            geometry.check_since(start, &p)?;
        }
        lights.push(light);
    }
    if let Some(env) = &desc.environment {
        let p = place(env.span(), "[environment]".into());
        lights.push(load_environment(env.get_ref(), &p, files)?);
        names.lights.push(None);
    }
    if lights.is_empty() {
        return Err(SceneError {
            file: file.into(),
            position: None,
            context: String::new(),
            message: "the scene has no [[light]] and no [environment]: photon mapping needs at least one".into(),
        });
    }

    let mut media = Vec::new();
    for (i, m) in desc.medium.iter().enumerate() {
        let p = place(m.span(), format!("[[medium]] #{}", i + 1));
        let medium = load_medium(m.get_ref(), &p)?;
        let region = match &m.get_ref().region {
            None => None,
            Some(mesh) => {
                let triangles = load_obj(mesh, files, &p)?.into_iter().map(|t| t.v).collect();
                let region = RegionMesh::new(triangles).map_err(|e| p.error(format!("region {mesh}: {e}")))?;
                Some(region)
            }
        };
        media.push((medium, region));
    }
    // Too many media (or phase functions): reported at the last one.
    let media = Media::new(media).map_err(|e| SceneError {
        file: file.to_string(),
        position: desc.medium.last().map(|m| line_col(text, m.span().start)),
        context: "[[medium]]".into(),
        message: e,
    })?;

    let mut animations = gltf_animations;
    for (i, a) in desc.animation.iter().enumerate() {
        let p = place(a.span(), format!("[[animation]] #{}", i + 1));
        let target = a.get_ref().target.get_ref();
        let target = *targets.get(target).ok_or_else(|| {
            let mut known: Vec<&str> = targets.keys().map(String::as_str).collect();
            known.sort();
            let hint = if known.is_empty() {
                "no object or light has a `name`".to_string()
            } else {
                format!("named: {}", known.join(", "))
            };
            place(a.get_ref().target.span(), p.context.clone())
                .error(format!("no object or light is named \"{target}\" ({hint})"))
        })?;
        animations.push(Animation { target, motion: load_motion(a.get_ref(), &p)? });
    }

    let (triangles, tri_surfaces): (Vec<_>, Vec<_>) = geometry.triangles.into_iter().unzip();
    let (spheres, sphere_surfaces): (Vec<_>, Vec<_>) = geometry.spheres.into_iter().unzip();
    let mut accel = Accel::build(triangles, tri_surfaces, spheres, sphere_surfaces);
    // The textures of glTF objects, if any.
    let texturing = texturing.materials.iter().any(Option::is_some).then(|| {
        texturing.materials.resize(materials.len(), None);
        texturing.surface_materials = geometry.surfaces.iter().map(|s| s.material).collect();
        std::sync::Arc::new(texturing)
    });
    accel.set_alpha_mask(texturing.clone());
    crate::light::fit_distant_lights(&mut lights, accel.bounds());
    // Area lights' bodies, after every named material.
    names.materials.resize(materials.len(), None);
    Ok(Scene {
        source: file.to_string(),
        camera,
        materials,
        surfaces: geometry.surfaces,
        lights,
        accel,
        media,
        names,
        animations,
        notes,
        texturing,
    })
}

/// What a glTF object adds to besides geometry.
struct SceneParts<'a> {
    materials: &'a mut Vec<Material>,
    lights: &'a mut Vec<Light>,
    /// Images, material textures (by scene material) and texture coordinates
    /// (by triangle) of the glTF objects so far.
    texturing: &'a mut crate::texture::Texturing,
    names: &'a mut Names,
    /// The files' own animations (node motions, deformed meshes).
    animations: &'a mut Vec<Animation>,
    /// The files' notes, each naming its file.
    notes: &'a mut Vec<String>,
}

/// Places a glTF file's meshes, materials, lights and emissive surfaces by
/// the object's `rotate_y`, `scale` and `translate`.
fn load_gltf_object(
    o: &ObjectDesc,
    file: &str,
    p: &Place,
    files: SceneFiles,
    geo: &mut GeometryBuilder,
    parts: &mut SceneParts,
) -> Result<(), SceneError> {
    let given = [
        ("name", o.name.is_some()),
        ("material", o.material.is_some()),
        ("mesh", o.mesh.is_some()),
        ("shape", o.shape.is_some()),
        ("rotate_y", o.rotate_y.is_some()),
        ("scale", o.scale.is_some()),
        ("translate", o.translate.is_some()),
    ];
    p.only("a glTF object (its materials are the file's)", &given, &["rotate_y", "scale", "translate"])?;
    let scale = p.in_range("scale", o.scale.unwrap_or(1.0), (MIN_LENGTH, MAX_COORD))?;
    let translate = p.coord("translate", o.translate.unwrap_or([0.0; 3]))?;
    let degrees = p.in_range("rotate_y", o.rotate_y.unwrap_or(0.0), (-MAX_COORD, MAX_COORD))?;
    let world_from_file = glam::Affine3A::from_scale_rotation_translation(
        Vec3::splat(scale),
        glam::Quat::from_rotation_y(degrees.to_radians()),
        translate,
    );
    let bytes = files.read(file, false).map_err(|e| p.error(format!("cannot read glTF file {file}: {e}")))?;
    // The glTF file's own buffers and images are beside it.
    let folder = match files {
        SceneFiles::Folder(folder) => Some(folder.join(file).parent().map(Path::to_path_buf).unwrap_or_default()),
        _ => None,
    };
    let own_files = folder.as_deref().map_or(files, SceneFiles::Folder);
    let name = match files {
        SceneFiles::Folder(folder) => folder.join(file).display().to_string(),
        _ => file.to_string(),
    };
    let asset =
        super::gltf::asset_from_bytes(&bytes, &name, own_files, world_from_file, None, &crate::progress::Silent)
            .map_err(|e| p.error(e.to_string()))?;
    parts.notes.extend(asset.notes.iter().map(|n| format!("{file}: {n}")));
    // The file's animations play in the scene, as when it is loaded alone.
    let light_motions: Vec<_> = asset.light_paths.iter().map(|path| asset.motion(path)).collect();
    let primitive_motions: Vec<_> = asset.primitives.iter().map(|p| asset.motion(&p.node_path)).collect();
    let first_material = parts.materials.len() as u32;
    parts.materials.extend(asset.materials);
    parts.names.materials.resize(first_material as usize, None);
    parts.names.materials.extend(asset.material_names);
    // The file's images after those of earlier objects.
    let t = &mut *parts.texturing;
    let first_image = t.images.len() as u32;
    t.images.extend(asset.images);
    t.materials.resize(first_material as usize, None);
    t.materials.extend(asset.material_textures.into_iter().map(|m| {
        m.map(|mut m| {
            for r in [&mut m.base_color, &mut m.metallic_roughness, &mut m.emissive].into_iter().flatten() {
                r.image += first_image;
            }
            m
        })
    }));
    for ((_, light), motion) in asset.lights.into_iter().zip(light_motions) {
        if let Some(motion) = motion {
            parts.animations.push(Animation { target: Target::Light(parts.lights.len() as u32), motion });
        }
        parts.lights.push(light);
        parts.names.lights.push(None);
    }
    let start = geo.counts();
    for (primitive, motion) in asset.primitives.into_iter().zip(primitive_motions) {
        if primitive.triangles.is_empty() {
            continue;
        }
        let emitter = primitive.emitted_light().map(|light| {
            parts.lights.push(light);
            parts.names.lights.push(None);
            parts.lights.len() as u32 - 1
        });
        let surface = geo.add_surface(Surface { material: first_material + primitive.material, emitter });
        if let Some(mesh) = primitive.deformed {
            parts.animations.push(Animation { target: Target::Object(surface), motion: Motion::Deformed(mesh) });
        }
        if let Some(motion) = motion {
            // An emissive surface moves with its light (`Scene::posed`).
            let target = emitter.map_or(Target::Object(surface), Target::Light);
            parts.animations.push(Animation { target, motion });
        }
        if let Some(uvs) = &primitive.uvs {
            parts.texturing.uvs.push_run(geo.triangles.len() as u32, uvs);
        }
        if let Some(tangents) = &primitive.tangents {
            parts.texturing.tangents.push_run(geo.triangles.len() as u32, tangents);
        }
        geo.triangles.extend(primitive.triangles.into_iter().map(|t| (t, surface)));
    }
    if geo.counts() == start {
        return Err(p.error(format!("glTF file {file} has no triangle to render")));
    }
    geo.check_since(start, p)
}

fn load_motion(a: &AnimationDesc, p: &Place) -> Result<Motion, SceneError> {
    let given = [("center", a.center.is_some()), ("axis", a.axis.is_some()), ("offset", a.offset.is_some())];
    let period = p.in_range("period", a.period, limits::PERIOD)?;
    match a.kind.as_str() {
        "rotate" => {
            p.only("a rotation", &given, &["center", "axis"])?;
            Ok(Motion::Rotate {
                center: p.coord("center", p.required("center", a.center)?)?,
                axis: p.direction("axis", a.axis.unwrap_or([0.0, 1.0, 0.0]))?,
                period,
            })
        }
        "move" => {
            p.only("a move", &given, &["offset"])?;
            Ok(Motion::Move { offset: p.coord("offset", p.required("offset", a.offset)?)?, period })
        }
        other => Err(p.error(format!("unknown animation type \"{other}\" (expected rotate or move)"))),
    }
}

fn load_medium(m: &MediumDesc, p: &Place) -> Result<Medium, SceneError> {
    let sigma = |field: &str, v: V3| -> Result<Vec3, SceneError> {
        let c = p.color(field, v, limits::MAX_SIGMA)?;
        if c.to_array().iter().any(|&x| x > 0.0 && x < limits::MIN_SIGMA) {
            return Err(p.error(format!(
                "`{field}` = {v:?} has a component below {:e} that is not 0 (write 0 for none)",
                limits::MIN_SIGMA
            )));
        }
        Ok(c)
    };
    let sigma_a = sigma("sigma_a", m.sigma_a)?;
    let sigma_s = sigma("sigma_s", m.sigma_s)?;
    if (sigma_a + sigma_s).max_element() <= 0.0 {
        return Err(p.error("sigma_a + sigma_s is zero in every channel: the medium does nothing"));
    }
    let parameter = |name: &str, v: Option<f32>| -> Result<f32, SceneError> {
        let v = v.unwrap_or(0.0);
        if v.is_finite() && v > -1.0 && v < 1.0 {
            Ok(v)
        } else {
            Err(p.error(format!("`{name}` = {v} must lie strictly between -1 and 1")))
        }
    };
    let phase = match m.phase.as_deref().unwrap_or("schlick") {
        "schlick" => {
            p.only("a Schlick phase function", &[("g", m.g.is_some())], &[])?;
            Phase::Schlick { k: parameter("k", m.k)? }
        }
        "hg" => {
            p.only("a Henyey-Greenstein phase function", &[("k", m.k.is_some())], &[])?;
            Phase::HenyeyGreenstein { g: parameter("g", m.g)? }
        }
        other => return Err(p.error(format!("unknown phase function \"{other}\" (expected schlick or hg)"))),
    };
    Ok(Medium { sigma_a, sigma_s, phase })
}

fn load_camera(c: &CameraDesc, p: &Place) -> Result<Camera, SceneError> {
    let fov = c.fov_y;
    Camera::new(
        p.coord("position", c.position)?,
        p.coord("look_at", c.look_at)?,
        p.coord("up", c.up)?,
        if fov.is_finite() { fov } else { f32::NAN },
        c.resolution[0],
        c.resolution[1],
    )
    .map_err(|msg| p.error(msg))
}

fn load_material(m: &MaterialDesc, p: &Place) -> Result<Material, SceneError> {
    let given = [
        ("albedo", m.albedo.is_some()),
        ("specular_reflectance", m.specular_reflectance.is_some()),
        ("reflectance", m.reflectance.is_some()),
        ("ior", m.ior.is_some()),
        ("base_color", m.base_color.is_some()),
        ("metallic", m.metallic.is_some()),
        ("roughness", m.roughness.is_some()),
        ("specular", m.specular.is_some()),
        ("specular_color", m.specular_color.is_some()),
        ("clearcoat", m.clearcoat.is_some()),
        ("clearcoat_roughness", m.clearcoat_roughness.is_some()),
        ("sheen_color", m.sheen_color.is_some()),
        ("sheen_roughness", m.sheen_roughness.is_some()),
    ];
    match m.kind.as_str() {
        "diffuse" => {
            p.only("a diffuse material", &given, &["albedo", "specular_reflectance"])?;
            let albedo = p.color("albedo", p.required("albedo", m.albedo)?, 1.0)?;
            let specular = p.color("specular_reflectance", m.specular_reflectance.unwrap_or([0.0; 3]), 1.0)?;
            if (albedo + specular).max_element() > 1.0 + 1e-6 {
                return Err(
                    p.error("albedo + specular_reflectance exceeds 1 in some channel (energy would be created)")
                );
            }
            Ok(Material::Diffuse { albedo, specular })
        }
        "mirror" => {
            p.only("a mirror material", &given, &["reflectance"])?;
            Ok(Material::Mirror { reflectance: p.color("reflectance", m.reflectance.unwrap_or([1.0; 3]), 1.0)? })
        }
        "glass" => {
            p.only("a glass material", &given, &["ior", "base_color", "roughness"])?;
            Ok(Material::Glass(crate::bsdf::dielectric::Dielectric {
                ior: p.in_range("ior", m.ior.unwrap_or(1.5), limits::IOR)?,
                roughness: p.in_range("roughness", m.roughness.unwrap_or(0.0), (0.0, 1.0))?,
                tint: p.color("base_color", m.base_color.unwrap_or([1.0; 3]), 1.0)?,
                absorption: crate::material::Rgb::ZERO,
            }))
        }
        "pbr" => {
            p.only(
                "a pbr material",
                &given,
                &[
                    "base_color",
                    "metallic",
                    "roughness",
                    "specular",
                    "specular_color",
                    "ior",
                    "clearcoat",
                    "clearcoat_roughness",
                    "sheen_color",
                    "sheen_roughness",
                ],
            )?;
            let unit = |field: &str, v: Option<f32>, default: f32| p.in_range(field, v.unwrap_or(default), (0.0, 1.0));
            Ok(Material::from_bsdf(
                crate::bsdf::Bsdf::new(
                    p.color("base_color", p.required("base_color", m.base_color)?, 1.0)?,
                    unit("metallic", m.metallic, 0.0)?,
                    unit("roughness", m.roughness, 0.5)?,
                    unit("specular", m.specular, 1.0)?,
                )
                .with_clearcoat(
                    unit("clearcoat", m.clearcoat, 0.0)?,
                    unit("clearcoat_roughness", m.clearcoat_roughness, 0.0)?,
                )
                .with_sheen(
                    p.color("sheen_color", m.sheen_color.unwrap_or([0.0; 3]), 1.0)?,
                    unit("sheen_roughness", m.sheen_roughness, 0.5)?,
                )
                .with_specular_color(p.color("specular_color", m.specular_color.unwrap_or([1.0; 3]), 100.0)?)
                .with_ior(p.in_range("ior", m.ior.unwrap_or(1.5), (1.0, 3.0))?),
            ))
        }
        other => Err(p.error(format!("unknown material type \"{other}\" (expected diffuse, mirror, glass or pbr)"))),
    }
}

/// Triangles and spheres collected while loading, each with its surface id.
#[derive(Default)]
struct GeometryBuilder {
    surfaces: Vec<Surface>,
    triangles: Vec<(Triangle, u32)>,
    spheres: Vec<(Sphere, u32)>,
}

impl GeometryBuilder {
    /// Checks what `p`'s entry added since `start` (triangle and sphere counts):
    /// every vertex and sphere bound within ±`MAX_COORD`, and every triangle
    /// with a normal that 32-bit floats can normalise (a quad far from the
    /// origin whose edges vanish beside its corner's magnitude has none).
    fn check_since(&self, (tri_start, sphere_start): (usize, usize), p: &Place) -> Result<(), SceneError> {
        let inside = |x: Vec3| x.is_finite() && x.abs().max_element() <= MAX_COORD;
        for (t, _) in &self.triangles[tri_start..] {
            if let Some(v) = t.v.iter().find(|&&v| !inside(v)) {
                return Err(p.error(format!("a vertex at {v} lies beyond ±{MAX_COORD:e}")));
            }
            if t.geometric_normal().try_normalize().is_none() {
                return Err(p.error(format!(
                    "a triangle {:?} is too thin to have a normal in 32-bit floats (edges too small for its distance from the origin)",
                    t.v
                )));
            }
        }
        for (s, _) in &self.spheres[sphere_start..] {
            if !(inside(s.center - s.radius) && inside(s.center + s.radius)) {
                return Err(p.error(format!(
                    "the sphere (centre {}, radius {}) reaches beyond ±{MAX_COORD:e}",
                    s.center, s.radius
                )));
            }
        }
        Ok(())
    }

    fn counts(&self) -> (usize, usize) {
        (self.triangles.len(), self.spheres.len())
    }

    fn add_surface(&mut self, s: Surface) -> u32 {
        self.surfaces.push(s);
        self.surfaces.len() as u32 - 1
    }

    /// Two triangles, wound so their normal is edge_u × edge_v.
    fn add_quad(&mut self, corner: Vec3, u: Vec3, v: Vec3, surface: u32) {
        let t = |a, b, c| (Triangle { v: [a, b, c], normals: None }, surface);
        self.triangles.push(t(corner, corner + u, corner + u + v));
        self.triangles.push(t(corner, corner + u + v, corner + v));
    }
}

fn load_object(
    o: &ObjectDesc,
    p: &Place,
    files: SceneFiles,
    surface: u32,
    geo: &mut GeometryBuilder,
) -> Result<(), SceneError> {
    let given = [
        ("center", o.center.is_some()),
        ("radius", o.radius.is_some()),
        ("corner", o.corner.is_some()),
        ("edge_u", o.edge_u.is_some()),
        ("edge_v", o.edge_v.is_some()),
        ("size", o.size.is_some()),
        ("rotate_y", o.rotate_y.is_some()),
        ("scale", o.scale.is_some()),
        ("translate", o.translate.is_some()),
    ];
    let rotation = |deg: Option<f32>| -> Result<Mat3, SceneError> {
        let deg = p.in_range("rotate_y", deg.unwrap_or(0.0), (-MAX_COORD, MAX_COORD))?;
        Ok(Mat3::from_rotation_y(deg.to_radians()))
    };
    match (&o.mesh, o.shape.as_deref()) {
        (Some(_), Some(_)) => Err(p.error("give either `mesh` or `shape`, not both")),
        (None, None) => Err(p.error("missing `mesh`, `shape` or `gltf`")),
        (Some(mesh), None) => {
            p.only("a mesh object", &given, &["rotate_y", "scale", "translate"])?;
            let scale = p.in_range("scale", o.scale.unwrap_or(1.0), (MIN_LENGTH, MAX_COORD))?;
            let translate = p.coord("translate", o.translate.unwrap_or([0.0; 3]))?;
            let rot = rotation(o.rotate_y)?;
            let start = geo.triangles.len();
            for tri in load_obj(mesh, files, p)? {
                let v = tri.v.map(|x| rot * (x * scale) + translate);
                let normals = tri.normals.map(|TriangleNormals(n)| TriangleNormals(n.map(|x| (rot * x).normalize())));
                let tri = Triangle { v, normals };
                // Scaling down can make a triangle degenerate: dropped, as in the file.
                if has_normal(&tri) {
                    geo.triangles.push((tri, surface));
                }
            }
            if geo.triangles.len() == start {
                return Err(p.error(format!("mesh {mesh} has no triangle left of non-zero area at scale {scale}")));
            }
            Ok(())
        }
        (None, Some("sphere")) => {
            p.only("a sphere", &given, &["center", "radius"])?;
            let center = p.coord("center", p.required("center", o.center)?)?;
            let radius = p.length("radius", p.required("radius", o.radius)?)?;
            geo.spheres.push((Sphere { center, radius }, surface));
            Ok(())
        }
        (None, Some("quad")) => {
            p.only("a quad", &given, &["corner", "edge_u", "edge_v"])?;
            let corner = p.coord("corner", p.required("corner", o.corner)?)?;
            let u = p.coord("edge_u", p.required("edge_u", o.edge_u)?)?;
            let v = p.coord("edge_v", p.required("edge_v", o.edge_v)?)?;
            quad_area(p, "quad", u, v)?;
            geo.add_quad(corner, u, v, surface);
            Ok(())
        }
        (None, Some("box")) => {
            p.only("a box", &given, &["center", "size", "rotate_y"])?;
            let center = p.coord("center", p.required("center", o.center)?)?;
            let size = p.required("size", o.size)?;
            if !size.iter().all(|x| (MIN_LENGTH..=2.0 * MAX_COORD).contains(x)) {
                return Err(p.error(format!(
                    "box `size` = {size:?} must be positive, each side between {MIN_LENGTH:e} and {:e}",
                    2.0 * MAX_COORD
                )));
            }
            let size = Vec3::from(size);
            let rot = rotation(o.rotate_y)?;
            add_box(geo, center, size * 0.5, rot, surface);
            Ok(())
        }
        (None, Some(other)) => Err(p.error(format!("unknown shape \"{other}\" (expected sphere, quad or box)"))),
    }
}

/// Six outward-facing quads of a box with half-extent `h`, rotated by `rot`.
fn add_box(geo: &mut GeometryBuilder, center: Vec3, h: Vec3, rot: Mat3, surface: u32) {
    let (x, y, z) = (rot * Vec3::X * h.x, rot * Vec3::Y * h.y, rot * Vec3::Z * h.z);
    // For each face: the outward axis `n` and two edges whose cross product is n.
    for (n, a, b) in [(x, y, z), (y, z, x), (z, x, y)] {
        for sign in [1.0f32, -1.0] {
            let (n, a) = (n * sign, a * sign);
            let corner = center + n - a - b;
            geo.add_quad(corner, a * 2.0, b * 2.0, surface);
        }
    }
}

/// A triangle that 32-bit floats can give a unit normal; others count as
/// zero-area and are dropped.
fn has_normal(t: &Triangle) -> bool {
    t.geometric_normal().try_normalize().is_some()
}

/// Reads a Wavefront OBJ file into triangles (non-degenerate ones only), its
/// vertex normals made unit. Positions and normals are checked line by line
/// first, so that an error can name the OBJ line.
fn load_obj(mesh: &str, files: SceneFiles, p: &Place) -> Result<Vec<Triangle>, SceneError> {
    let name = match files {
        SceneFiles::Folder(folder) => folder.join(mesh).display().to_string(),
        _ => mesh.to_string(),
    };
    // Built-in scenes read their meshes from the copies embedded in the binary.
    let embedded = p.file.starts_with("builtin:").then(|| super::builtin::mesh(mesh)).flatten();
    let text = match embedded {
        Some(text) => text.to_string(),
        None => {
            let bytes = files.read(mesh, false).map_err(|e| p.error(format!("mesh {mesh}: {e}")))?;
            String::from_utf8(bytes).map_err(|e| p.error(format!("cannot read mesh {name}: not UTF-8 text: {e}")))?
        }
    };
    check_obj_lines(&text, &name.to_string(), p)?;
    let options = tobj::LoadOptions { triangulate: true, single_index: true, ..Default::default() };
    // The OBJ's own materials are ignored, so `mtllib` files are not opened.
    let loaded = tobj::load_obj_buf(&mut text.as_bytes(), &options, |_| Err(tobj::LoadError::OpenFileFailed));
    let (models, _) = loaded.map_err(|e| p.error(format!("cannot read mesh {name}: {e}")))?;
    let mut tris = Vec::new();
    for model in models {
        let m = &model.mesh;
        let at = |values: &[f32], i: u32| Vec3::from_slice(&values[3 * i as usize..3 * i as usize + 3]);
        let has_normals = m.normals.len() == m.positions.len();
        for idx in m.indices.chunks_exact(3) {
            let idx = [idx[0], idx[1], idx[2]];
            if idx.iter().any(|&i| 3 * i as usize + 2 >= m.positions.len()) {
                return Err(p.error(format!("mesh {name} has a face with a vertex index out of range")));
            }
            let v = idx.map(|i| at(&m.positions, i));
            // Checked line by line above; kept as a guard for what tobj makes of them.
            if v.iter().any(|x| !x.is_finite() || x.abs().max_element() > MAX_COORD) {
                return Err(p.error(format!("mesh {name} has a vertex that is not finite or beyond ±{MAX_COORD:e}")));
            }
            let normals = match has_normals {
                false => None,
                true => {
                    let n = idx.map(|i| at(&m.normals, i).try_normalize());
                    let [Some(a), Some(b), Some(c)] = n else {
                        return Err(p.error(format!("mesh {name} has a vertex normal that is zero or not finite")));
                    };
                    Some(TriangleNormals([a, b, c]))
                }
            };
            let tri = Triangle { v, normals };
            if has_normal(&tri) {
                tris.push(tri);
            }
        }
    }
    if tris.is_empty() {
        return Err(p.error(format!("mesh {name} has no triangles")));
    }
    Ok(tris)
}

/// Checks every `v` (position) and `vn` (normal) line of an OBJ file:
/// coordinates finite and within ±`MAX_COORD`, normals also not zero.
fn check_obj_lines(text: &str, name: &str, p: &Place) -> Result<(), SceneError> {
    for (i, line) in text.lines().enumerate() {
        let mut words = line.split_whitespace();
        let kind = match words.next() {
            Some("v") => "vertex",
            Some("vn") => "vertex normal",
            _ => continue,
        };
        let bad = |why: &str| p.error(format!("mesh {name}:{}: {kind} `{}` {why}", i + 1, line.trim()));
        // Unparsable numbers are left to the OBJ reader, which reports them.
        let xyz: Vec<f32> = words.take(3).filter_map(|w| w.parse().ok()).collect();
        if xyz.iter().any(|x| !x.is_finite()) {
            return Err(bad("is not finite"));
        }
        if xyz.iter().any(|x| x.abs() > MAX_COORD) {
            return Err(bad(&format!("has a component beyond ±{MAX_COORD:e}")));
        }
        if kind == "vertex normal" && xyz.len() == 3 && Vec3::from_slice(&xyz).try_normalize().is_none() {
            return Err(bad("is zero (or too short to normalise)"));
        }
    }
    Ok(())
}

/// Rejects a quad whose area is (nearly) zero.
fn quad_area(p: &Place, kind: &str, u: Vec3, v: Vec3) -> Result<(), SceneError> {
    if u.cross(v).length() >= limits::MIN_QUAD_AREA {
        Ok(())
    } else {
        Err(p.error(format!(
            "{kind} has zero area (|edge_u × edge_v| below {:e}: the edges are parallel, zero or tiny)",
            limits::MIN_QUAD_AREA
        )))
    }
}

/// A light, with its total power checked: finite and not (nearly) zero.
fn load_light(l: &LightDesc, p: &Place) -> Result<Light, SceneError> {
    let light = light_from_desc(l, p)?;
    let power = mean(light.power());
    if !(power.is_finite() && power >= limits::MIN_LIGHT_POWER) {
        return Err(p.error(format!(
            "the light's total power {power:e} W is below {:e}: it would emit nothing",
            limits::MIN_LIGHT_POWER
        )));
    }
    Ok(light)
}

fn light_from_desc(l: &LightDesc, p: &Place) -> Result<Light, SceneError> {
    let given = [
        ("position", l.position.is_some()),
        ("intensity", l.intensity.is_some()),
        ("direction", l.direction.is_some()),
        ("cutoff_angle", l.cutoff_angle.is_some()),
        ("falloff_start_angle", l.falloff_start_angle.is_some()),
        ("center", l.center.is_some()),
        ("radius", l.radius.is_some()),
        ("radiance", l.radiance.is_some()),
        ("corner", l.corner.is_some()),
        ("edge_u", l.edge_u.is_some()),
        ("edge_v", l.edge_v.is_some()),
        ("irradiance", l.irradiance.is_some()),
    ];
    let nonzero = |field: &str, c: Vec3| {
        if c.max_element() > 0.0 { Ok(c) } else { Err(p.error(format!("`{field}` is zero: the light emits nothing"))) }
    };
    match l.kind.as_str() {
        "point" => {
            p.only("a point light", &given, &["position", "intensity"])?;
            Ok(Light::Point {
                position: p.coord("position", p.required("position", l.position)?)?,
                intensity: nonzero(
                    "intensity",
                    p.color("intensity", p.required("intensity", l.intensity)?, MAX_EMISSION)?,
                )?,
            })
        }
        "spot" => {
            p.only(
                "a spot light",
                &given,
                &["position", "intensity", "direction", "cutoff_angle", "falloff_start_angle"],
            )?;
            let axis = p.direction("direction", p.required("direction", l.direction)?)?;
            let cutoff = p.in_range("cutoff_angle", l.cutoff_angle.unwrap_or(20.0), limits::CUTOFF_ANGLE)?;
            let start = l.falloff_start_angle.unwrap_or(cutoff * 0.75);
            if !(start >= 0.0 && start <= cutoff) {
                return Err(p.error(format!("`falloff_start_angle` = {start} must be in [0, cutoff_angle = {cutoff}]")));
            }
            Ok(Light::Spot {
                position: p.coord("position", p.required("position", l.position)?)?,
                axis,
                intensity: nonzero(
                    "intensity",
                    p.color("intensity", p.required("intensity", l.intensity)?, MAX_EMISSION)?,
                )?,
                cutoff: cutoff.to_radians(),
                falloff_start: start.to_radians(),
            })
        }
        "sphere" => {
            p.only("a sphere light", &given, &["center", "radius", "radiance"])?;
            Ok(Light::Sphere {
                center: p.coord("center", p.required("center", l.center)?)?,
                radius: p.length("radius", p.required("radius", l.radius)?)?,
                radiance: nonzero("radiance", p.color("radiance", p.required("radiance", l.radiance)?, MAX_EMISSION)?)?,
            })
        }
        "quad" => {
            p.only("a quad light", &given, &["corner", "edge_u", "edge_v", "radiance"])?;
            let edge_u = p.coord("edge_u", p.required("edge_u", l.edge_u)?)?;
            let edge_v = p.coord("edge_v", p.required("edge_v", l.edge_v)?)?;
            quad_area(p, "quad light", edge_u, edge_v)?;
            Ok(Light::Quad {
                corner: p.coord("corner", p.required("corner", l.corner)?)?,
                edge_u,
                edge_v,
                radiance: nonzero("radiance", p.color("radiance", p.required("radiance", l.radiance)?, MAX_EMISSION)?)?,
            })
        }
        "directional" => {
            p.only("a directional light", &given, &["direction", "irradiance"])?;
            let irradiance = p.color("irradiance", p.required("irradiance", l.irradiance)?, MAX_EMISSION)?;
            Ok(Light::Directional {
                direction: p.direction("direction", p.required("direction", l.direction)?)?,
                irradiance: nonzero("irradiance", irradiance)?,
                // Fitted to the scene's bounds once they are known.
                disc: Disc::UNIT,
            })
        }
        other => {
            Err(p.error(format!("unknown light type \"{other}\" (expected point, spot, sphere, quad or directional)")))
        }
    }
}

/// The `[environment]` table: a uniform sky or a map (read relative to
/// the scene's `files`), its disc fitted later.
fn load_environment(e: &EnvironmentDesc, p: &Place, files: SceneFiles) -> Result<Light, SceneError> {
    let map = match &e.map {
        Some(file) => {
            let bytes = files.read(file, false).map_err(|e| p.error(format!("environment map {file}: {e}")))?;
            let map = crate::envmap::EnvironmentMap::from_bytes(&bytes, file).map_err(|e| p.error(e))?;
            Some(std::sync::Arc::new(map))
        }
        None => None,
    };
    let radiance = match (e.radiance, &map) {
        (Some(radiance), _) => p.color("radiance", radiance, MAX_EMISSION)?,
        (None, Some(_)) => Vec3::ONE,
        (None, None) => return Err(p.error("`radiance` or `map` is needed: a uniform sky or an image of one")),
    };
    if radiance.max_element() <= 0.0 {
        return Err(p.error("`radiance` is zero: the environment emits nothing"));
    }
    if map.as_ref().is_some_and(|m| m.integral().max_element() <= 0.0) {
        return Err(p.error("the environment map is black: it emits nothing"));
    }
    Ok(Light::Environment { radiance, disc: Disc::UNIT, map })
}

#[cfg(test)]
mod tests {
    use super::*;

    const BASE: &str = r#"
[camera]
position = [0.0, 0.0, 3.0]
look_at = [0.0, 0.0, 0.0]
fov_y = 40.0
resolution = [16, 16]

[[material]]
name = "white"
type = "diffuse"
albedo = [0.5, 0.5, 0.5]

[[object]]
shape = "sphere"
center = [0.0, 0.0, 0.0]
radius = 1.0
material = "white"

[[light]]
type = "point"
position = [0.0, 2.0, 0.0]
intensity = [1.0, 1.0, 1.0]
"#;

    fn err(text: &str) -> SceneError {
        match parse(text, "test.toml", SceneFiles::beside(None)) {
            Ok(_) => panic!("scene was accepted:\n{text}"),
            Err(e) => e,
        }
    }

    /// A pbr material takes a clear coat; out of range is a located
    /// error, and glass refuses one.
    #[test]
    fn pbr_materials_take_a_clear_coat() {
        let coated = BASE.replace(
            "type = \"diffuse\"\nalbedo = [0.5, 0.5, 0.5]",
            "type = \"pbr\"\nbase_color = [0.5, 0.1, 0.1]\nclearcoat = 1.0\nclearcoat_roughness = 0.1",
        );
        let s = parse(&coated, "test.toml", SceneFiles::beside(None)).unwrap();
        let Material::Pbr(b) = s.materials[0] else { panic!("{:?}", s.materials[0]) };
        assert_eq!((b.clearcoat, b.clearcoat_roughness), (1.0, 0.1));
        // A pbr material takes an index of refraction (F0 = 1/9 at 2).
        let s = parse(&coated.replace("clearcoat = 1.0", "ior = 2.0"), "test.toml", SceneFiles::beside(None)).unwrap();
        let Material::Pbr(b) = s.materials[0] else { panic!("{:?}", s.materials[0]) };
        assert!((b.f0 - 1.0 / 9.0).abs() < 1e-6 && b.clearcoat == 0.0);
        assert!(err(&coated.replace("clearcoat = 1.0", "ior = 0.5")).to_string().contains("ior"));
        let e = err(&coated.replace("clearcoat = 1.0", "clearcoat = 1.5"));
        assert!(e.to_string().contains("clearcoat") && e.to_string().contains("test.toml"), "{e}");
        let glass = BASE.replace("type = \"diffuse\"\nalbedo = [0.5, 0.5, 0.5]", "type = \"glass\"\nclearcoat = 1.0");
        assert!(err(&glass).to_string().contains("clearcoat"));
        // And a sheen (KHR_materials_sheen), its colour checked per channel.
        let sheened = coated.replace("clearcoat = 1.0", "sheen_color = [0.9, 0.8, 0.7]\nsheen_roughness = 0.3");
        let s = parse(&sheened, "test.toml", SceneFiles::beside(None)).unwrap();
        let Material::Pbr(b) = s.materials[0] else { panic!("{:?}", s.materials[0]) };
        assert_eq!((b.sheen_color, b.sheen_roughness), (Vec3::new(0.9, 0.8, 0.7), 0.3));
        let e = err(&sheened.replace("0.9, 0.8", "1.9, 0.8"));
        assert!(e.to_string().contains("sheen_color") && e.to_string().contains("test.toml"), "{e}");
        // And a specular colour (KHR_materials_specular), which may exceed 1.
        let tinted = coated.replace("clearcoat = 1.0", "specular_color = [1.0, 2.0, 0.5]");
        let s = parse(&tinted, "test.toml", SceneFiles::beside(None)).unwrap();
        let Material::Pbr(b) = s.materials[0] else { panic!("{:?}", s.materials[0]) };
        assert_eq!(b.specular_color, Vec3::new(1.0, 2.0, 0.5));
        assert!(err(&tinted.replace("2.0, 0.5", "-2.0, 0.5")).to_string().contains("specular_color"));
    }

    #[test]
    fn base_scene_loads() {
        let s = parse(BASE, "test.toml", SceneFiles::beside(None)).unwrap();
        assert_eq!(s.accel.sphere_count(), 1);
        assert_eq!(s.lights.len(), 1);
    }

    /// Material names are kept, one per material (area lights' bodies
    /// unnamed), for front ends that edit materials by name.
    #[test]
    fn material_names_are_kept() {
        let s = parse(BASE, "test.toml", SceneFiles::beside(None)).unwrap();
        assert_eq!(s.names.materials, vec![Some("white".to_string())]);
        let caustic = Scene::load("cornell-caustic").unwrap();
        assert_eq!(caustic.names.materials.len(), caustic.materials.len());
        assert!(caustic.names.materials.last().unwrap().is_none(), "the sphere light's body");
        let glb = Scene::load(concat!(env!("CARGO_MANIFEST_DIR"), "/../../scenes/showcase.glb")).unwrap();
        assert_eq!(glb.names.materials.len(), glb.materials.len());
        assert!(glb.names.materials.iter().flatten().count() >= 2, "{:?}", glb.names.materials);
    }

    #[test]
    fn syntax_error_names_file_and_line() {
        let e = err(&BASE.replace("fov_y = 40.0", "fov_y = = 40.0"));
        assert_eq!(e.file, "test.toml");
        assert_eq!(e.position.unwrap().0, 5, "{e}");
    }

    #[test]
    fn unknown_field_is_rejected() {
        let e = err(&BASE.replace("radius = 1.0", "radius = 1.0\nradious = 2.0"));
        assert!(e.to_string().contains("radious"), "{e}");
        assert!(e.position.is_some());
    }

    #[test]
    fn unknown_material_names_the_object() {
        let e = err(&BASE.replace("material = \"white\"", "material = \"whte\""));
        assert!(e.to_string().contains("[[object]] #1") && e.to_string().contains("whte"), "{e}");
        assert_eq!(e.position.unwrap(), (17, 12), "{e}");
    }

    #[test]
    fn missing_mesh_is_reported() {
        let e = err(&BASE.replace("shape = \"sphere\"\ncenter = [0.0, 0.0, 0.0]\nradius = 1.0", "mesh = \"nope.obj\""));
        assert!(e.message.contains("nope.obj") && e.message.contains("not found"), "{e}");
    }

    #[test]
    fn bad_albedo_values_are_rejected() {
        for bad in ["[-0.1, 0.5, 0.5]", "[1.2, 0.5, 0.5]", "[nan, 0.5, 0.5]", "[inf, 0.5, 0.5]"] {
            let e = err(&BASE.replace("albedo = [0.5, 0.5, 0.5]", &format!("albedo = {bad}")));
            assert!(e.context.contains("[[material]] #1"), "{e}");
            assert!(e.message.contains("albedo"), "{e}");
        }
    }

    #[test]
    fn degenerate_camera_is_rejected() {
        let e = err(&BASE.replace("look_at = [0.0, 0.0, 0.0]", "look_at = [0.0, 0.0, 3.0]"));
        assert!(e.context == "[camera]" && e.message.contains("coincide"), "{e}");
        let e = err(&BASE.replace("resolution = [16, 16]", "resolution = [0, 16]"));
        assert!(e.message.contains("zero"), "{e}");
    }

    #[test]
    fn scene_without_lights_is_rejected() {
        let text = BASE.split("[[light]]").next().unwrap();
        assert!(err(text).message.contains("no [[light]]"));
    }

    #[test]
    fn misplaced_and_invalid_light_fields_are_rejected() {
        let e = err(&BASE.replace("type = \"point\"", "type = \"point\"\nradius = 1.0"));
        assert!(e.message.contains("radius") && e.message.contains("point light"), "{e}");
        let e = err(&BASE.replace("intensity = [1.0, 1.0, 1.0]", "intensity = [0.0, 0.0, 0.0]"));
        assert!(e.message.contains("emits nothing"), "{e}");
    }

    /// A sun: its direction made unit, its disc fitted to the scene's bounds
    /// (the unit sphere at the origin: radius √3).
    #[test]
    fn directional_lights_load_with_fitted_discs() {
        let sun = "type = \"directional\"\ndirection = [0.0, -2.0, 0.0]\nirradiance = [3.0, 2.0, 1.0]";
        let point = format!("type = \"point\"\n{POINT}");
        let s = parse(&BASE.replace(&point, sun), "test.toml", SceneFiles::beside(None)).unwrap();
        let Light::Directional { direction, irradiance, disc } = s.lights[0] else { panic!("{:?}", s.lights[0]) };
        assert_eq!((direction, irradiance), (Vec3::NEG_Y, Vec3::new(3.0, 2.0, 1.0)));
        assert!(disc.center.length() < 1e-6 && (disc.radius / 3f32.sqrt() - 1.0).abs() < 0.01, "{disc:?}");
        let light = "[[light]] #1";
        rejects(&point, &sun.replace("direction = [0.0, -2.0, 0.0]\n", ""), light, &["direction"]);
        rejects(&point, &sun.replace("\nirradiance = [3.0, 2.0, 1.0]", ""), light, &["irradiance"]);
        rejects(&point, &sun.replace("[0.0, -2.0, 0.0]", "[0.0, 0.0, 0.0]"), light, &["direction", "zero"]);
        rejects(&point, &sun.replace("[3.0, 2.0, 1.0]", "[2e6, 0.0, 0.0]"), light, &["irradiance", "above"]);
        rejects(&point, &sun.replace("[3.0, 2.0, 1.0]", "[0.0, 0.0, 0.0]"), light, &["irradiance", "nothing"]);
        rejects(&point, &format!("{sun}\nradius = 1.0"), light, &["radius", "directional"]);
        rejects(&point, &sun.replace("directional", "sun"), light, &["directional"]);
    }

    /// An `[environment]` alone lights a scene; bad radiance is located.
    #[test]
    fn an_environment_is_a_light() {
        let text = BASE.split("[[light]]").next().unwrap().to_string();
        let sky = |radiance: &str| format!("{text}[environment]\nradiance = {radiance}\n");
        let s = parse(&sky("[0.5, 1.0, 2.0]"), "test.toml", SceneFiles::beside(None)).unwrap();
        let Light::Environment { radiance, disc, .. } = s.lights[0] else { panic!("{:?}", s.lights[0]) };
        assert_eq!(radiance, Vec3::new(0.5, 1.0, 2.0));
        assert!((disc.radius / 3f32.sqrt() - 1.0).abs() < 0.01, "{disc:?}");
        assert_eq!(s.names.lights, vec![None]);
        // With a [[light]] too: both, the sky last.
        let s = parse(
            &format!("{BASE}\n[environment]\nradiance = [1.0, 1.0, 1.0]\n"),
            "test.toml",
            SceneFiles::beside(None),
        )
        .unwrap();
        assert!(matches!(s.lights[..], [Light::Point { .. }, Light::Environment { .. }]));
        for (radiance, words) in
            [("[-1.0, 1.0, 1.0]", "negative"), ("[0.0, 0.0, 0.0]", "nothing"), ("[1e7, 1.0, 1.0]", "above")]
        {
            let e = err(&sky(radiance));
            assert!(e.context == "[environment]" && e.position.is_some() && e.message.contains(words), "{e}");
        }
        let e = err(&format!("{text}[environment]\nradiance = [1.0, 1.0, 1.0]\nturbidity = 2.0\n"));
        assert!(e.message.contains("turbidity"), "{e}");
    }

    #[test]
    fn obj_mesh_with_smooth_normals_loads() {
        let dir = std::env::temp_dir().join(format!("hikari-obj-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        std::fs::write(
            dir.join("tri.obj"),
            "v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 1\nvn 0 0 1\nvn 0.6 0 0.8\nf 1//1 2//2 3//3\n",
        )
        .unwrap();
        let text = BASE
            .replace("shape = \"sphere\"\ncenter = [0.0, 0.0, 0.0]\nradius = 1.0", "mesh = \"tri.obj\"\nscale = 2.0");
        let s = parse(&text, "mem.toml", SceneFiles::Folder(&dir)).unwrap();
        assert_eq!(s.accel.triangle_count(), 1);
        let hit = s.accel.intersect(&crate::geometry::Ray::new(Vec3::new(0.2, 0.2, 1.0), -Vec3::Z)).unwrap();
        assert!((hit.point - Vec3::new(0.2, 0.2, 0.0)).length() < 1e-5);
        // Interpolated smooth normal, not the flat one.
        assert!(hit.shading_normal.x > 0.01);
        let _ = std::fs::remove_dir_all(&dir);
    }

    #[test]
    fn media_load_and_bad_media_are_rejected() {
        let fog = "\n[[medium]]\nsigma_a = [0.1, 0.1, 0.1]\nsigma_s = [0.2, 0.3, 0.4]\nphase = \"hg\"\ng = 0.5\n";
        let s = parse(&format!("{BASE}{fog}"), "test.toml", SceneFiles::beside(None)).unwrap();
        let m = s.media.entries()[0].medium;
        assert_eq!(m.phase, Phase::HenyeyGreenstein { g: 0.5 });
        assert_eq!(m.sigma_s, Vec3::new(0.2, 0.3, 0.4));
        for (bad, words) in [
            (fog.replace("g = 0.5", "g = 1.0"), "strictly between"),
            (fog.replace("g = 0.5", "k = 0.5"), "does not apply"),
            (fog.replace("sigma_a = [0.1, 0.1, 0.1]", "sigma_a = [-0.1, 0.1, 0.1]"), "negative"),
            (fog.replace("phase = \"hg\"", "phase = \"rayleigh\""), "unknown phase"),
            (format!("{fog}region = \"fog.obj\"\n"), "not found"),
            ("\n[[medium]]\n".to_string(), "does nothing"),
        ] {
            let e = err(&format!("{BASE}{bad}"));
            assert!(e.context.starts_with("[[medium]]") && e.message.contains(words), "{e}");
        }
    }

    #[test]
    fn region_media_load_and_open_regions_are_rejected() {
        let dir = std::env::temp_dir().join(format!("hikari-region-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let mut obj = String::new();
        let tris = crate::medium::region::box_triangles(Vec3::ZERO, Vec3::ONE);
        for t in &tris {
            for v in t {
                obj += &format!("v {} {} {}\n", v.x, v.y, v.z);
            }
        }
        let faces: Vec<String> =
            (0..tris.len()).map(|i| format!("f {} {} {}", 3 * i + 1, 3 * i + 2, 3 * i + 3)).collect();
        std::fs::write(dir.join("closed.obj"), format!("{obj}{}\n", faces.join("\n"))).unwrap();
        std::fs::write(dir.join("open.obj"), format!("{obj}{}\n", faces[1..].join("\n"))).unwrap();
        let fog = |region: &str| format!("{BASE}\n[[medium]]\nsigma_s = [0.5, 0.5, 0.5]\nregion = \"{region}\"\n");
        let s = parse(&fog("closed.obj"), "test.toml", SceneFiles::Folder(&dir)).unwrap();
        assert!(
            s.media.has_regions() && s.media.mask_at(Vec3::splat(0.5)) == 1 && s.media.mask_at(Vec3::splat(2.0)) == 0
        );
        let e = parse(&fog("open.obj"), "test.toml", SceneFiles::Folder(&dir)).err().unwrap();
        assert!(e.message.contains("open.obj") && e.message.contains("not closed") && e.position.is_some(), "{e}");
        let _ = std::fs::remove_dir_all(&dir);
        let hg = |g: f32| format!("\n[[medium]]\nsigma_s = [0.1, 0.1, 0.1]\nphase = \"hg\"\ng = {g}\n");
        let five: String = (0..5).map(|i| hg(i as f32 * 0.1)).collect();
        assert!(err(&format!("{BASE}{five}")).message.contains("phase functions"));
    }

    /// `BASE` with `from` replaced by `to`; the error must name the entry, its
    /// line, and contain every word of `words`.
    fn rejects(from: &str, to: &str, context: &str, words: &[&str]) {
        assert!(BASE.contains(from), "{from}");
        let e = err(&BASE.replace(from, to));
        assert!(e.position.is_some() && e.context.starts_with(context), "{to}: {e}");
        for w in words {
            assert!(e.message.contains(w), "{to}: {e}");
        }
    }

    const SPHERE: &str = "center = [0.0, 0.0, 0.0]\nradius = 1.0";
    const POINT: &str = "position = [0.0, 2.0, 0.0]\nintensity = [1.0, 1.0, 1.0]";

    fn quad(corner: &str, u: &str, v: &str) -> String {
        format!("shape = \"quad\"\ncorner = {corner}\nedge_u = {u}\nedge_v = {v}\n")
    }

    #[test]
    fn coordinates_beyond_a_million_are_rejected() {
        let obj = "[[object]] #1";
        rejects("center = [0.0, 0.0, 0.0]", "center = [2e6, 0.0, 0.0]", obj, &["center", "beyond"]);
        rejects("center = [0.0, 0.0, 0.0]", "center = [0.0, 1e38, 0.0]", obj, &["beyond"]);
        let sphere = format!("shape = \"sphere\"\n{SPHERE}");
        let edge = quad("[0.0, 0.0, 0.0]", "[1.0, 0.0, 0.0]", "[1e30, 1e30, 1e30]");
        rejects(&sphere, &edge, obj, &["edge_v", "beyond"]);
        let corner = quad("[0.0, 1e38, 0.0]", "[1.0, 0.0, 0.0]", "[0.0, 0.0, 1.0]");
        rejects(&sphere, &corner, obj, &["corner", "beyond"]);
        rejects("look_at = [0.0, 0.0, 0.0]", "look_at = [0.0, 0.0, -1e7]", "[camera]", &["look_at"]);
        rejects("fov_y = 40.0", "fov_y = 40.0\nup = [0.0, 1e30, 0.0]", "[camera]", &["up"]);
        rejects("position = [0.0, 2.0, 0.0]", "position = [0.0, 2e6, 0.0]", "[[light]] #1", &["position"]);
    }

    #[test]
    fn derived_vertices_beyond_a_million_are_rejected() {
        let sphere = format!("shape = \"sphere\"\n{SPHERE}");
        let far = quad("[9e5, 0.0, 0.0]", "[9e5, 0.0, 0.0]", "[0.0, 0.0, 1.0]");
        rejects(&sphere, &far, "[[object]] #1", &["vertex", "beyond"]);
        rejects(SPHERE, "center = [999999.5, 0.0, 0.0]\nradius = 1.0", "[[object]] #1", &["sphere", "beyond"]);
        let boxed = "shape = \"box\"\ncenter = [999999.0, 0.0, 0.0]\nsize = [4.0, 1.0, 1.0]\nrotate_y = 30.0";
        rejects(&sphere, boxed, "[[object]] #1", &["vertex", "beyond"]);
        let light = "type = \"sphere\"\ncenter = [0.0, 999999.9, 0.0]\nradius = 1.0\nradiance = [1.0, 1.0, 1.0]";
        rejects(&format!("type = \"point\"\n{POINT}"), light, "[[light]] #1", &["beyond"]);
    }

    #[test]
    fn quads_too_thin_for_their_position_are_rejected() {
        let sphere = format!("shape = \"sphere\"\n{SPHERE}");
        // |edge_u × edge_v| = 1e-10 passes the area test, but next to 5e5 the
        // edges vanish in f32 (spacing 0.03) and the triangles have no normal.
        let thin = quad("[5e5, 0.0, 0.0]", "[1e-5, 0.0, 0.0]", "[0.0, 1e-5, 0.0]");
        rejects(&sphere, &thin, "[[object]] #1", &["too thin"]);
        let tiny = quad("[0.0, 0.0, 0.0]", "[1e-7, 0.0, 0.0]", "[0.0, 1e-7, 0.0]");
        rejects(&sphere, &tiny, "[[object]] #1", &["zero area"]);
        let light = format!("type = \"quad\"\nradiance = [1.0, 1.0, 1.0]\n{}", thin.replace("shape = \"quad\"\n", ""));
        rejects(&format!("type = \"point\"\n{POINT}"), &light, "[[light]] #1", &["too thin"]);
    }

    #[test]
    fn lengths_and_factors_are_bounded() {
        let obj = "[[object]] #1";
        for bad in ["1e-7", "1e-20", "3e6", "0.0", "-1.0"] {
            rejects("radius = 1.0", &format!("radius = {bad}"), obj, &["radius"]);
        }
        let boxed = |size: &str| format!("shape = \"box\"\ncenter = [0.0, 0.0, 0.0]\nsize = {size}");
        let sphere = format!("shape = \"sphere\"\n{SPHERE}");
        rejects(&sphere, &boxed("[1.0, 1e-7, 1.0]"), obj, &["size"]);
        rejects(&sphere, &boxed("[1.0, 3e6, 1.0]"), obj, &["size"]);
        let rotated = format!("{}\nrotate_y = 1e7", boxed("[1.0, 1.0, 1.0]"));
        rejects(&sphere, &rotated, obj, &["rotate_y"]);
        let glass = |ior: &str| format!("name = \"white\"\ntype = \"glass\"\nior = {ior}");
        let white = "name = \"white\"\ntype = \"diffuse\"\nalbedo = [0.5, 0.5, 0.5]";
        assert!(parse(&BASE.replace(white, &glass("1.5")), "t.toml", SceneFiles::None).is_ok());
        rejects(white, &glass("0.001"), "[[material]] #1", &["ior"]);
        rejects(white, &glass("1000.0"), "[[material]] #1", &["ior"]);
    }

    #[test]
    fn emission_and_light_power_are_bounded() {
        let light = "[[light]] #1";
        rejects("intensity = [1.0, 1.0, 1.0]", "intensity = [2e6, 1.0, 1.0]", light, &["intensity", "above"]);
        let sphere_light = |radius: &str, radiance: &str| {
            format!("type = \"sphere\"\ncenter = [0.0, 3.0, 0.0]\nradius = {radius}\nradiance = {radiance}")
        };
        let point = format!("type = \"point\"\n{POINT}");
        rejects(&point, &sphere_light("1.0", "[1e7, 0.0, 0.0]"), light, &["radiance", "above"]);
        rejects(&point, &sphere_light("1e-6", "[1e-30, 0.0, 0.0]"), light, &["power"]);
        rejects("intensity = [1.0, 1.0, 1.0]", "intensity = [1e-30, 0.0, 0.0]", light, &["power"]);
        let spot =
            "type = \"spot\"\nposition = [0.0, 2.0, 0.0]\nintensity = [1.0, 1.0, 1.0]\ndirection = [0.0, -1.0, 0.0]";
        rejects(&point, &format!("{spot}\ncutoff_angle = 0.001"), light, &["cutoff_angle"]);
        rejects(&point, &spot.replace("[0.0, -1.0, 0.0]", "[0.0, 0.0, 0.0]"), light, &["direction", "zero"]);
        // A ramp thinner than f32 resolves still has a positive power.
        let thin = format!("{spot}\ncutoff_angle = 20.0\nfalloff_start_angle = 19.999999");
        let s = parse(&BASE.replace(&point, &thin), "test.toml", SceneFiles::beside(None)).unwrap();
        assert!(crate::material::mean(s.lights[0].power()) > 0.0);
    }

    #[test]
    fn camera_field_of_view_and_resolution_are_located_errors() {
        rejects("fov_y = 40.0", "fov_y = 0.001", "[camera]", &["fov_y"]);
        rejects("fov_y = 40.0", "fov_y = 179.9", "[camera]", &["fov_y"]);
        rejects("resolution = [16, 16]", "resolution = [100000, 100000]", "[camera]", &["at most 16384"]);
        rejects("resolution = [16, 16]", "resolution = [16384, 16384]", "[camera]", &["pixels"]);
        assert!(parse(&BASE.replace("[16, 16]", "[8192, 8192]"), "t.toml", SceneFiles::None).is_ok());
        // Beyond u32: the TOML reader's own located error.
        let e = err(&BASE.replace("[16, 16]", "[16, 99999999999]"));
        assert!(e.position.is_some(), "{e}");
    }

    #[test]
    fn medium_coefficients_are_bounded() {
        let fog = |sigma: &str| format!("{BASE}\n[[medium]]\nsigma_s = {sigma}\n");
        for (sigma, words) in
            [("[2e6, 0.0, 0.0]", "above"), ("[1e-9, 0.5, 0.5]", "below"), ("[1e-45, 0.0, 0.0]", "below")]
        {
            let e = err(&fog(sigma));
            assert!(e.context == "[[medium]] #1" && e.message.contains(words) && e.position.is_some(), "{e}");
        }
        assert!(parse(&fog("[1e6, 0.0, 1e-6]"), "t.toml", SceneFiles::None).is_ok());
    }

    /// Writes `files` into a fresh folder and loads `BASE` with its sphere
    /// replaced by `object`.
    fn with_files(tag: &str, files: &[(&str, &str)], object: &str) -> Result<Scene, SceneError> {
        let dir = std::env::temp_dir().join(format!("hikari-{tag}-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        for (name, text) in files {
            std::fs::write(dir.join(name), text).unwrap();
        }
        let result = parse(
            &BASE.replace(&format!("shape = \"sphere\"\n{SPHERE}"), object),
            "test.toml",
            SceneFiles::Folder(&dir),
        );
        let _ = std::fs::remove_dir_all(&dir);
        result
    }

    #[test]
    fn obj_vertices_and_normals_are_checked_by_line() {
        let tri = "v 0 0 0\nv 1 0 0\nv 0 1 0\n";
        for (normals, words) in [
            ("vn 0 0 1\nvn 0 0 0\nvn 0 0 1\n", ["m.obj:5", "vertex normal", "zero"]),
            ("vn 0 0 1\nvn 0 0 1\nvn nan 0 1\n", ["m.obj:6", "vertex normal", "not finite"]),
            ("vn 0 0 1\nvn 1e-30 0 0\nvn 0 0 1\n", ["m.obj:5", "vertex normal", "zero"]),
        ] {
            let obj = format!("{tri}{normals}f 1//1 2//2 3//3\n");
            let e = with_files("vn", &[("m.obj", &obj)], "mesh = \"m.obj\"").err().unwrap();
            assert!(e.position.is_some() && e.context == "[[object]] #1", "{e}");
            assert!(words.iter().all(|w| e.message.contains(w)), "{e}");
        }
        for (v, words) in [("v 0 1e39 0", ["m.obj:3", "not finite"]), ("v 0 2e6 0", ["m.obj:3", "beyond"])] {
            let obj = format!("v 0 0 0\nv 1 0 0\n{v}\nf 1 2 3\n");
            let e = with_files("v", &[("m.obj", &obj)], "mesh = \"m.obj\"").err().unwrap();
            assert!(words.iter().all(|w| e.message.contains(w)), "{e}");
        }
    }

    #[test]
    fn mesh_transforms_are_bounded() {
        let obj = [("m.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n")];
        let e = with_files("scale", &obj, "mesh = \"m.obj\"\nscale = 1e7").err().unwrap();
        assert!(e.message.contains("scale"), "{e}");
        let e = with_files("far", &obj, "mesh = \"m.obj\"\nscale = 1e6\ntranslate = [1.0, 0.0, 0.0]").err().unwrap();
        assert!(e.message.contains("beyond") && e.position.is_some(), "{e}");
        let e = with_files("tx", &obj, "mesh = \"m.obj\"\ntranslate = [0.0, 0.0, 1e9]").err().unwrap();
        assert!(e.message.contains("translate"), "{e}");
        // Scaled so small that f32 gives its triangle no normal.
        let small = [("m.obj", "v 0 0 0\nv 1e-15 0 0\nv 0 1e-15 0\nf 1 2 3\n")];
        let e = with_files("small", &small, "mesh = \"m.obj\"\nscale = 1e-6").err().unwrap();
        assert!(e.message.contains("no triangle"), "{e}");
    }

    #[test]
    fn box_faces_point_outward() {
        let mut geo = GeometryBuilder::default();
        add_box(&mut geo, Vec3::new(1.0, 2.0, 3.0), Vec3::new(0.5, 1.0, 0.25), Mat3::from_rotation_y(0.3), 0);
        assert_eq!(geo.triangles.len(), 12);
        for (t, _) in &geo.triangles {
            let centroid = (t.v[0] + t.v[1] + t.v[2]) / 3.0;
            assert!(t.geometric_normal().dot(centroid - Vec3::new(1.0, 2.0, 3.0)) > 0.0);
        }
    }
}

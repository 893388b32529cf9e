//! Editing a loaded scene from Python without reloading it: the camera and
//! the lights. What an edit does not touch (the BVH, textures) is kept; a
//! still scene is edited in place (copied once if a render still holds it),
//! an animated one keeps its edits and is posed with them at each render.

use crate::scene::Scene;
use glam::Vec3;
use hikari_core::camera::Camera as CoreCamera;
use hikari_core::light::Light as CoreLight;
use hikari_core::material::Material;
use hikari_core::scene::{Pose, Scene as CoreScene};
use pyo3::exceptions::{PyIndexError, PyValueError};
use pyo3::prelude::*;
use std::sync::Arc;

/// A scene with its edits.
#[derive(Clone)]
pub struct Edited {
    /// A still scene with its edits made, or an animated scene as loaded.
    scene: Arc<CoreScene>,
    /// An animated scene's edits, applied before its animations at each render.
    camera: CoreCamera,
    lights: Vec<CoreLight>,
}

impl Edited {
    pub fn new(scene: CoreScene) -> Self {
        Edited { camera: scene.camera.clone(), lights: scene.lights.clone(), scene: Arc::new(scene) }
    }

    pub fn camera(&self) -> &CoreCamera {
        &self.camera
    }

    pub fn lights(&self) -> &[CoreLight] {
        &self.lights
    }

    /// The scene at `time` of its animations, with the edits.
    pub fn at_time(&self, time: f32) -> Arc<CoreScene> {
        if !self.scene.is_animated() {
            return self.scene.clone();
        }
        let pose = Pose { time, lights: self.lights.clone(), ..self.scene.rest_pose() };
        let mut posed = self.scene.posed(&pose);
        posed.camera = self.camera.clone();
        Arc::new(posed)
    }

    pub fn materials(&self) -> &[Material] {
        &self.scene.materials
    }

    pub fn material_names(&self) -> &[Option<String>] {
        &self.scene.names.materials
    }

    /// Material `index` replaced: the scene's own (posing copies them).
    fn set_material(&mut self, index: usize, material: Material) {
        Arc::make_mut(&mut self.scene).materials[index] = material;
    }

    /// The lights that surfaces of material `index` emit (a glTF emissive
    /// material's meshes, an area light's body), in the scene's order.
    pub fn lights_emitted_by(&self, index: usize) -> Vec<usize> {
        let mut lights: Vec<usize> = (self.scene.surfaces.iter())
            .filter(|s| s.material as usize == index)
            .filter_map(|s| s.emitter.map(|e| e as usize))
            .collect();
        lights.sort_unstable();
        lights.dedup();
        lights
    }

    fn set_camera(&mut self, camera: CoreCamera) {
        if !self.scene.is_animated() {
            Arc::make_mut(&mut self.scene).camera = camera.clone();
        }
        self.camera = camera;
    }

    /// Light `index` replaced: an area light moved carries its geometry
    /// with it (the BVH rebuilt, as the viewer's edits do).
    fn set_light(&mut self, index: usize, light: CoreLight) {
        self.lights[index] = light.clone();
        if self.scene.is_animated() {
            return;
        }
        if light.is_area() && light.anchor() != self.scene.lights[index].anchor() {
            let pose = Pose { lights: self.lights.clone(), ..self.scene.rest_pose() };
            let mut posed = self.scene.posed(&pose);
            posed.camera = self.camera.clone();
            self.scene = Arc::new(posed);
        } else {
            Arc::make_mut(&mut self.scene).lights[index] = light;
        }
    }
}

fn vec3((x, y, z): (f32, f32, f32), what: &str) -> PyResult<Vec3> {
    let v = Vec3::new(x, y, z);
    if v.is_finite() { Ok(v) } else { Err(PyValueError::new_err(format!("{what}: ({x}, {y}, {z}) is not finite"))) }
}

fn tuple(v: Vec3) -> (f32, f32, f32) {
    (v.x, v.y, v.z)
}

/// The scene's camera; setting a field changes the scene's.
#[pyclass(module = "hikari_render", frozen)]
pub struct Camera {
    pub(crate) scene: Py<Scene>,
}

impl Camera {
    fn edit(&self, change: impl FnOnce(&mut CoreCamera)) -> PyResult<()> {
        let scene = self.scene.get();
        let mut state = scene.state();
        let mut c = state.camera().clone();
        change(&mut c);
        let camera = CoreCamera::new(c.position, c.look_at, c.up, c.fov_y, c.width, c.height)
            .map_err(|e| PyValueError::new_err(format!("camera: {e}")))?;
        state.set_camera(camera);
        Ok(())
    }

    fn get(&self) -> CoreCamera {
        self.scene.get().state().camera().clone()
    }
}

#[pymethods]
impl Camera {
    /// Where the eye is: (x, y, z).
    #[getter]
    fn position(&self) -> (f32, f32, f32) {
        tuple(self.get().position)
    }
    #[setter]
    fn set_position(&self, v: (f32, f32, f32)) -> PyResult<()> {
        let v = vec3(v, "camera.position")?;
        self.edit(|c| c.position = v)
    }
    /// The point the eye looks at.
    #[getter]
    fn look_at(&self) -> (f32, f32, f32) {
        tuple(self.get().look_at)
    }
    #[setter]
    fn set_look_at(&self, v: (f32, f32, f32)) -> PyResult<()> {
        let v = vec3(v, "camera.look_at")?;
        self.edit(|c| c.look_at = v)
    }
    /// The direction that is up in the image.
    #[getter]
    fn up(&self) -> (f32, f32, f32) {
        tuple(self.get().up)
    }
    #[setter]
    fn set_up(&self, v: (f32, f32, f32)) -> PyResult<()> {
        let v = vec3(v, "camera.up")?;
        self.edit(|c| c.up = v)
    }
    /// The full vertical field of view, in degrees.
    #[getter]
    fn fov_y(&self) -> f32 {
        self.get().fov_y
    }
    #[setter]
    fn set_fov_y(&self, v: f32) -> PyResult<()> {
        self.edit(|c| c.fov_y = v)
    }

    fn __repr__(&self) -> String {
        let c = self.get();
        format!(
            "<hikari_render.Camera position={:?} look_at={:?} up={:?} fov_y={}>",
            tuple(c.position),
            tuple(c.look_at),
            tuple(c.up),
            c.fov_y
        )
    }
}

/// One of the scene's lights; setting a field changes the scene's.
#[pyclass(module = "hikari_render", frozen)]
pub struct Light {
    pub(crate) scene: Py<Scene>,
    pub(crate) index: usize,
}

impl Light {
    fn get(&self) -> PyResult<CoreLight> {
        let scene = self.scene.get();
        let state = scene.state();
        state.lights().get(self.index).cloned().ok_or_else(|| PyIndexError::new_err("no such light"))
    }

    fn set(&self, light: CoreLight) {
        self.scene.get().state().set_light(self.index, light);
    }
}

#[pymethods]
impl Light {
    /// "point", "spot", "sphere", "quad", "sun", "sky" or "mesh".
    #[getter]
    fn kind(&self) -> PyResult<&'static str> {
        Ok(match self.get()? {
            CoreLight::Point { .. } => "point",
            CoreLight::Spot { .. } => "spot",
            CoreLight::Sphere { .. } => "sphere",
            CoreLight::Quad { .. } => "quad",
            CoreLight::Directional { .. } => "sun",
            CoreLight::Environment { .. } => "sky",
            CoreLight::Mesh(_) => "mesh",
        })
    }

    /// The light's name in its file, if it has one.
    #[getter]
    fn name(&self) -> Option<String> {
        self.scene.get().state().scene.names.lights.get(self.index).cloned().flatten()
    }

    /// The RGB emission in hikari's radiometric units: W/sr for point and
    /// spot lights, W/m² for suns, W/(m² sr) for area lights, skies and
    /// emissive meshes.
    #[getter]
    fn color(&self) -> PyResult<(f32, f32, f32)> {
        Ok(tuple(self.get()?.emission()))
    }
    #[setter]
    fn set_color(&self, rgb: (f32, f32, f32)) -> PyResult<()> {
        let c = vec3(rgb, "light.color")?;
        if c.min_element() < 0.0 {
            return Err(PyValueError::new_err(format!("light.color: {rgb:?} has a negative channel")));
        }
        let light = self.get()?.with_emission(c);
        self.set(light);
        Ok(())
    }

    /// Where a point or spot light sits, a sphere light's centre or a quad
    /// light's corner; None for suns, skies and emissive meshes.
    #[getter]
    fn position(&self) -> PyResult<Option<(f32, f32, f32)>> {
        let light = self.get()?;
        Ok(has_position(&light).then(|| tuple(light.anchor())))
    }
    #[setter]
    fn set_position(&self, v: (f32, f32, f32)) -> PyResult<()> {
        let p = vec3(v, "light.position")?;
        let light = self.get()?;
        if !has_position(&light) {
            return Err(PyValueError::new_err("light.position: a sun, a sky or an emissive mesh has no position"));
        }
        self.set(light.with_anchor(p));
        Ok(())
    }

    fn __repr__(&self) -> PyResult<String> {
        Ok(format!("<hikari_render.Light {} {}: color={:?}>", self.index, self.kind()?, self.color()?))
    }
}

fn has_position(light: &CoreLight) -> bool {
    matches!(
        light,
        CoreLight::Point { .. } | CoreLight::Spot { .. } | CoreLight::Sphere { .. } | CoreLight::Quad { .. }
    )
}

/// One of the scene's materials; setting a field changes the scene's.
#[pyclass(module = "hikari_render", name = "Material", frozen)]
pub struct MaterialView {
    pub(crate) scene: Py<Scene>,
    pub(crate) index: usize,
}

impl MaterialView {
    fn get(&self) -> Material {
        self.scene.get().state().materials()[self.index]
    }

    fn set(&self, material: Material) {
        self.scene.get().state().set_material(self.index, material);
    }
}

fn unit_interval(v: f32, what: &str) -> PyResult<f32> {
    if (0.0..=1.0).contains(&v) { Ok(v) } else { Err(PyValueError::new_err(format!("{what}: {v} is outside 0 to 1"))) }
}

#[pymethods]
impl MaterialView {
    /// "diffuse", "mirror", "glass", "pbr" (glTF's metallic–roughness) or
    /// "emitter" (an area light's body).
    #[getter]
    fn kind(&self) -> &'static str {
        match self.get() {
            Material::Diffuse { .. } => "diffuse",
            Material::Mirror { .. } => "mirror",
            Material::Glass { .. } => "glass",
            Material::Pbr(_) => "pbr",
            Material::Emitter => "emitter",
        }
    }

    /// The base colour: a diffuse material's albedo, a mirror's
    /// reflectance, a glTF material's base colour factor (times its
    /// texture where it has one), the colour seen through a solid piece of
    /// glass; None for emitters.
    #[getter]
    fn base_color(&self) -> Option<(f32, f32, f32)> {
        match self.get() {
            Material::Diffuse { albedo, .. } => Some(tuple(albedo)),
            Material::Mirror { reflectance } => Some(tuple(reflectance)),
            Material::Pbr(b) => Some(tuple(b.base_color)),
            Material::Glass(g) => Some(tuple(g.tint)),
            Material::Emitter => None,
        }
    }
    #[setter]
    fn set_base_color(&self, rgb: (f32, f32, f32)) -> PyResult<()> {
        let c = vec3(rgb, "material.base_color")?;
        if c.min_element() < 0.0 || c.max_element() > 1.0 {
            return Err(PyValueError::new_err(format!("material.base_color: {rgb:?} is outside 0 to 1")));
        }
        let material = match self.get() {
            Material::Diffuse { specular, .. } => Material::Diffuse { albedo: c, specular },
            Material::Mirror { .. } => Material::Mirror { reflectance: c },
            Material::Pbr(b) => Material::Pbr(hikari_core::bsdf::Bsdf { base_color: c, ..b }),
            Material::Glass(g) => Material::Glass(hikari_core::bsdf::dielectric::Dielectric { tint: c, ..g }),
            Material::Emitter => {
                return Err(PyValueError::new_err(format!("material.base_color: a {} has none", self.kind())));
            }
        };
        self.set(material);
        Ok(())
    }

    /// A glTF material's metallic factor; None for the others.
    #[getter]
    fn metallic(&self) -> Option<f32> {
        if let Material::Pbr(b) = self.get() { Some(b.metallic) } else { None }
    }
    #[setter]
    fn set_metallic(&self, v: f32) -> PyResult<()> {
        let v = unit_interval(v, "material.metallic")?;
        let Material::Pbr(b) = self.get() else {
            return Err(PyValueError::new_err(format!("material.metallic: a {} has none", self.kind())));
        };
        self.set(Material::Pbr(hikari_core::bsdf::Bsdf { metallic: v, ..b }));
        Ok(())
    }

    /// A glTF material's or glass's perceptual roughness; None for the others.
    #[getter]
    fn roughness(&self) -> Option<f32> {
        match self.get() {
            Material::Pbr(b) => Some(b.roughness),
            Material::Glass(g) => Some(g.roughness),
            _ => None,
        }
    }
    #[setter]
    fn set_roughness(&self, v: f32) -> PyResult<()> {
        let v = unit_interval(v, "material.roughness")?;
        let material = match self.get() {
            Material::Pbr(b) => Material::Pbr(hikari_core::bsdf::Bsdf { roughness: v, ..b }),
            Material::Glass(g) => Material::Glass(hikari_core::bsdf::dielectric::Dielectric { roughness: v, ..g }),
            _ => return Err(PyValueError::new_err(format!("material.roughness: a {} has none", self.kind()))),
        };
        self.set(material);
        Ok(())
    }

    /// A glTF material's clear coat (KHR_materials_clearcoat's factor, 0:
    /// none); None for the others.
    #[getter]
    fn clearcoat(&self) -> Option<f32> {
        if let Material::Pbr(b) = self.get() { Some(b.clearcoat) } else { None }
    }
    #[setter]
    fn set_clearcoat(&self, v: f32) -> PyResult<()> {
        let v = unit_interval(v, "material.clearcoat")?;
        let Material::Pbr(b) = self.get() else {
            return Err(PyValueError::new_err(format!("material.clearcoat: a {} has none", self.kind())));
        };
        self.set(Material::Pbr(b.with_clearcoat(v, b.clearcoat_roughness)));
        Ok(())
    }

    /// A glTF material's clear coat's perceptual roughness; None for the others.
    #[getter]
    fn clearcoat_roughness(&self) -> Option<f32> {
        if let Material::Pbr(b) = self.get() { Some(b.clearcoat_roughness) } else { None }
    }
    #[setter]
    fn set_clearcoat_roughness(&self, v: f32) -> PyResult<()> {
        let v = unit_interval(v, "material.clearcoat_roughness")?;
        let Material::Pbr(b) = self.get() else {
            return Err(PyValueError::new_err(format!("material.clearcoat_roughness: a {} has none", self.kind())));
        };
        self.set(Material::Pbr(b.with_clearcoat(b.clearcoat, v)));
        Ok(())
    }

    /// A glTF material's specular colour (KHR_materials_specular's
    /// specularColorFactor, scaling the dielectric's F0 per channel; white
    /// is glTF's default); None for the others.
    #[getter]
    fn specular_color(&self) -> Option<(f32, f32, f32)> {
        if let Material::Pbr(b) = self.get() { Some(tuple(b.specular_color)) } else { None }
    }
    #[setter]
    fn set_specular_color(&self, rgb: (f32, f32, f32)) -> PyResult<()> {
        let c = vec3(rgb, "material.specular_color")?;
        if c.min_element() < 0.0 {
            return Err(PyValueError::new_err(format!("material.specular_color: {rgb:?} has a negative component")));
        }
        let Material::Pbr(b) = self.get() else {
            return Err(PyValueError::new_err(format!("material.specular_color: a {} has none", self.kind())));
        };
        self.set(Material::Pbr(b.with_specular_color(c)));
        Ok(())
    }

    /// A glTF material's sheen colour (KHR_materials_sheen's
    /// sheenColorFactor, (0, 0, 0): none); None for the others.
    #[getter]
    fn sheen_color(&self) -> Option<(f32, f32, f32)> {
        if let Material::Pbr(b) = self.get() { Some(tuple(b.sheen_color)) } else { None }
    }
    #[setter]
    fn set_sheen_color(&self, rgb: (f32, f32, f32)) -> PyResult<()> {
        let c = vec3(rgb, "material.sheen_color")?;
        if c.min_element() < 0.0 || c.max_element() > 1.0 {
            return Err(PyValueError::new_err(format!("material.sheen_color: {rgb:?} is outside 0 to 1")));
        }
        let Material::Pbr(b) = self.get() else {
            return Err(PyValueError::new_err(format!("material.sheen_color: a {} has none", self.kind())));
        };
        self.set(Material::Pbr(b.with_sheen(c, b.sheen_roughness)));
        Ok(())
    }

    /// A glTF material's sheen roughness; None for the others.
    #[getter]
    fn sheen_roughness(&self) -> Option<f32> {
        if let Material::Pbr(b) = self.get() { Some(b.sheen_roughness) } else { None }
    }
    #[setter]
    fn set_sheen_roughness(&self, v: f32) -> PyResult<()> {
        let v = unit_interval(v, "material.sheen_roughness")?;
        let Material::Pbr(b) = self.get() else {
            return Err(PyValueError::new_err(format!("material.sheen_roughness: a {} has none", self.kind())));
        };
        self.set(Material::Pbr(b.with_sheen(b.sheen_color, v)));
        Ok(())
    }

    /// The RGB radiance (W/(m² sr)) the material's surfaces emit: a glTF
    /// emissive factor times its strength (an emissive texture's mean where
    /// it has one, the texture's pattern kept), an area light's body's
    /// radiance; (0, 0, 0) for a material that emits nothing. Setting it
    /// changes the lights its surfaces are (as `scene.lights[i].color`
    /// does); a material that emits nothing in the loaded scene cannot be
    /// made to (its surfaces are no lights: export it emissive instead).
    #[getter]
    fn emission(&self) -> (f32, f32, f32) {
        let scene = self.scene.get();
        let state = scene.state();
        let first = state.lights_emitted_by(self.index).first().map(|&i| state.lights()[i].emission());
        tuple(first.unwrap_or(Vec3::ZERO))
    }
    #[setter]
    fn set_emission(&self, rgb: (f32, f32, f32)) -> PyResult<()> {
        let c = vec3(rgb, "material.emission")?;
        if c.min_element() < 0.0 {
            return Err(PyValueError::new_err(format!("material.emission: {rgb:?} has a negative channel")));
        }
        let scene = self.scene.get();
        let mut state = scene.state();
        let lights = state.lights_emitted_by(self.index);
        if lights.is_empty() {
            let name = state.material_names().get(self.index).cloned().flatten();
            let which = name.map_or(format!("material {}", self.index), |n| format!("material '{n}'"));
            return Err(PyValueError::new_err(format!(
                "material.emission: {which} emits no light in the loaded scene, so its surfaces are no lights \
                 to brighten (make it emissive in the file)"
            )));
        }
        for i in lights {
            let light = state.lights()[i].with_emission(c);
            state.set_light(i, light);
        }
        Ok(())
    }

    fn __repr__(&self) -> String {
        format!("<hikari_render.Material {} {}: base_color={:?}>", self.index, self.kind(), self.base_color())
    }
}

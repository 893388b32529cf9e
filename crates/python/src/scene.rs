//! `hk.load` and the `Scene` it returns: renders in one call or pass by pass.

use crate::SceneError;
use crate::convert::{depth_to_array, image_to_array};
use crate::edit::{Camera, Edited, Light, MaterialView};
use crate::settings::{Request, request};
use crate::worker::{Message, Worker};
use hikari_core::scene::{LoadOptions, Scene as CoreScene};
use pyo3::exceptions::{PyRuntimeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use std::path::PathBuf;
use std::sync::{Arc, Mutex};

/// Loads a scene: a built-in name (`hk.scenes()`), a `.toml` scene file or
/// a glTF 2.0 file (`.glb`, or `.gltf` with its buffers), as a str or
/// PathLike. `camera`: a glTF camera by name (default: the first, else one
/// framing the scene). `environment`: an equirectangular sky image (.hdr or
/// .exr) lighting the scene in place of its own. Raises `SceneError` with
/// the file, the place and the problem when the scene cannot be loaded.
#[pyfunction]
#[pyo3(signature = (scene, *, camera = None, environment = None))]
pub fn load(py: Python<'_>, scene: PathBuf, camera: Option<String>, environment: Option<PathBuf>) -> PyResult<Scene> {
    let spec = scene.to_string_lossy().into_owned();
    let options = LoadOptions { camera, environment };
    let loaded = py.detach(|| CoreScene::load_with(&spec, &options)).map_err(|e| SceneError::new_err(e.to_string()))?;
    let notes = loaded.notes.clone();
    warn_each(py, &notes)?;
    Ok(Scene { state: Mutex::new(Edited::new(loaded)), spec })
}

/// A loaded scene, with the edits made to it since (`camera`, `lights`).
#[pyclass(module = "hikari_render", frozen)]
pub struct Scene {
    pub(crate) state: Mutex<Edited>,
    spec: String,
}

#[pymethods]
impl Scene {
    /// Renders the scene and returns the image: a float32 numpy array of
    /// shape (height, width, 3), linear radiance.
    ///
    /// renderer: "gpu" (photon splatting on the GPU; photon-cpu, with a
    ///     warning saying why, where no adapter can), "photon-cpu", "path"
    ///     (the unbiased path tracer) or "vcm".
    /// spp: samples per pixel (photon-cpu 4, path 64 in one pass; path in
    ///     open-ended passes: 4 a pass).
    /// passes: at most this many progressive passes (1: the single pass).
    /// time: stop after the first pass ending past this many seconds.
    /// target_error: stop once the passes' estimated noise (relative to
    ///     the image's mean) is this low, e.g. 0.02.
    ///     With none of passes, time and target_error (and for "path" no
    ///     spp) the passes stop at 2% noise or after 20 s, as the CLI's do.
    /// photons: photon paths per pass (default 200,000).
    /// radius: the global map's radius in scene units (default 3% of the
    ///     scene's diagonal, shrinking pass by pass).
    /// resolution: (width, height) instead of the scene's camera's.
    /// seed: the same seed gives the same image whatever the thread count.
    /// threads: CPU threads (default: all cores).
    /// at: the time, in seconds, the scene's animations are posed at.
    /// aovs: also return the images denoisers take: a dict with "color",
    ///     "albedo" (the reflectance of the first surface seen through
    ///     mirrors and glass), "normal" (its shading normal, world space,
    ///     unit length) and "depth" (float32 (height, width): the distance
    ///     along the camera ray, inf where nothing is hit).
    ///
    /// The GIL is released while rendering; Ctrl-C raises KeyboardInterrupt.
    #[pyo3(signature = (renderer = "gpu", **settings), text_signature = "(renderer='gpu', *, spp=None, passes=None, time=None, target_error=None, photons=None, radius=None, resolution=None, seed=0, threads=None, at=0.0, aovs=False)")]
    fn render<'py>(
        &self,
        py: Python<'py>,
        renderer: &str,
        settings: Option<&Bound<'py, PyDict>>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let request = request(renderer, settings)?;
        let posed = self.posed(py, &request)?;
        let worker = Worker::start(posed, request, false);
        loop {
            let message = worker.next(py);
            warn_each(py, &worker.take_notes())?;
            match message? {
                Some(Message::Done(image, None)) => return image_to_array(py, &image),
                Some(Message::Done(image, Some(aovs))) => {
                    let dict = PyDict::new(py);
                    dict.set_item("color", image_to_array(py, &image)?)?;
                    dict.set_item("albedo", image_to_array(py, &aovs.albedo)?)?;
                    dict.set_item("normal", image_to_array(py, &aovs.normal)?)?;
                    dict.set_item("depth", depth_to_array(py, &aovs.depth, image.width, image.height)?)?;
                    return Ok(dict.into_any());
                }
                Some(Message::Failed(e)) => return Err(PyRuntimeError::new_err(e)),
                Some(Message::Pass(..)) => {}
                None => return Err(PyRuntimeError::new_err("the render ended without an image")),
            }
        }
    }

    /// The same render pass by pass: an iterator of `Pass` (its `index`,
    /// `image`: the mean so far, `noise`: its estimated relative error or
    /// None, `seconds` since the start). Takes `render`'s arguments; the
    /// passes stop as there (breaking out of the loop stops them too).
    #[pyo3(signature = (renderer = "gpu", **settings), text_signature = "(renderer='gpu', *, spp=None, passes=None, time=None, target_error=None, photons=None, radius=None, resolution=None, seed=0, threads=None, at=0.0)")]
    fn progressive(&self, py: Python<'_>, renderer: &str, settings: Option<&Bound<'_, PyDict>>) -> PyResult<Passes> {
        let request = request(renderer, settings)?;
        let posed = self.posed(py, &request)?;
        Ok(Passes { worker: std::sync::Mutex::new(Some(Worker::start(posed, request, true))) })
    }

    /// The images denoisers take, without rendering the colour: a dict
    /// with "albedo", "normal" (float32 (height, width, 3)) and "depth"
    /// (float32 (height, width)), as `render(..., aovs=True)` gives them,
    /// for the scene at `resolution` and posed `at` seconds (a caller
    /// that renders pass by pass asks for them once, beside its passes).
    #[pyo3(signature = (*, resolution = None, at = 0.0))]
    fn aovs<'py>(&self, py: Python<'py>, resolution: Option<(u32, u32)>, at: f32) -> PyResult<Bound<'py, PyDict>> {
        let kwargs = PyDict::new(py);
        kwargs.set_item("resolution", resolution)?;
        kwargs.set_item("at", at)?;
        let request = request("path", Some(&kwargs))?;
        let posed = self.posed(py, &request)?;
        let aovs = py.detach(|| hikari_core::render::aov::render_aovs(&posed));
        let (width, height) = (aovs.albedo.width, aovs.albedo.height);
        let dict = PyDict::new(py);
        dict.set_item("albedo", image_to_array(py, &aovs.albedo)?)?;
        dict.set_item("normal", image_to_array(py, &aovs.normal)?)?;
        dict.set_item("depth", depth_to_array(py, &aovs.depth, width, height)?)?;
        Ok(dict)
    }

    /// The image's size as the scene's camera gives it: (width, height).
    #[getter]
    fn resolution(&self) -> (u32, u32) {
        let camera = self.state().camera().clone();
        (camera.width, camera.height)
    }

    /// The camera: set its `position`, `look_at`, `up` (3-tuples) and
    /// `fov_y` (degrees) and the next render looks through it.
    #[getter]
    fn camera(slf: Py<Self>) -> Camera {
        Camera { scene: slf }
    }

    /// The lights, in the scene's order: set a light's `color` (its
    /// emission) or `position` and the next render uses it.
    #[getter]
    fn lights(slf: Bound<'_, Self>) -> Vec<Light> {
        let count = slf.get().state().lights().len();
        (0..count).map(|index| Light { scene: slf.clone().unbind(), index }).collect()
    }

    /// The materials by name (a TOML material's `name`, a glTF
    /// material's; "material N" for one without a name): set a material's
    /// `base_color`, `metallic` or `roughness` and the next render uses it.
    #[getter]
    fn materials<'py>(slf: Bound<'py, Self>) -> PyResult<Bound<'py, PyDict>> {
        let py = slf.py();
        let names: Vec<Option<String>> = slf.get().state().material_names().to_vec();
        let count = slf.get().state().materials().len();
        let dict = PyDict::new(py);
        for index in 0..count {
            let name = names.get(index).cloned().flatten().unwrap_or_else(|| format!("material {index}"));
            dict.set_item(name, MaterialView { scene: slf.clone().unbind(), index })?;
        }
        Ok(dict)
    }

    fn __repr__(&self) -> String {
        let (w, h) = self.resolution();
        format!("<hikari_render.Scene {:?}, {w}x{h}>", self.spec)
    }
}

impl Scene {
    pub(crate) fn state(&self) -> std::sync::MutexGuard<'_, Edited> {
        self.state.lock().unwrap_or_else(|e| e.into_inner())
    }

    /// The scene as `request` renders it (its edits, posed at its time, at
    /// its resolution; the scene held, not a copy, where nothing changes
    /// it), its settings checked against it.
    fn posed(&self, py: Python<'_>, request: &Request) -> PyResult<Arc<CoreScene>> {
        let edited = self.state().clone();
        let resized = request.resolution.filter(|&r| r != (edited.camera().width, edited.camera().height));
        let posed = py.detach(|| -> Result<Arc<CoreScene>, String> {
            let scene = edited.at_time(request.at);
            Ok(match resized {
                None => scene,
                Some((w, h)) => {
                    let mut resized = (*scene).clone();
                    resized.camera = resized.camera.with_resolution(w, h)?;
                    Arc::new(resized)
                }
            })
        });
        let posed = posed.map_err(PyValueError::new_err)?;
        request.settings.check(&posed, |name| name.replace('-', "_")).map_err(PyValueError::new_err)?;
        Ok(posed)
    }
}

/// One pass of `Scene.progressive`.
#[pyclass(module = "hikari_render", frozen, get_all)]
pub struct Pass {
    /// The pass's number: 1, 2, …
    index: u32,
    /// The mean of the passes so far: float32, (height, width, 3).
    image: Py<PyAny>,
    /// The mean's estimated relative error, None until it can be estimated.
    noise: Option<f64>,
    /// Seconds since the first pass began.
    seconds: f64,
}

#[pymethods]
impl Pass {
    fn __repr__(&self) -> String {
        let noise = self.noise.map_or("None".to_string(), |n| format!("{n:.4}"));
        format!("<hikari_render.Pass {} at {:.2} s, noise {noise}>", self.index, self.seconds)
    }
}

/// The iterator `Scene.progressive` returns.
#[pyclass(module = "hikari_render")]
pub struct Passes {
    worker: std::sync::Mutex<Option<Worker>>,
}

#[pymethods]
impl Passes {
    fn __iter__(slf: PyRef<'_, Self>) -> PyRef<'_, Self> {
        slf
    }

    fn __next__(&self, py: Python<'_>) -> PyResult<Option<Pass>> {
        let mut guard = self.worker.lock().unwrap_or_else(|e| e.into_inner());
        let Some(worker) = guard.as_ref() else { return Ok(None) };
        let message = worker.next(py);
        warn_each(py, &worker.take_notes())?;
        match message {
            Ok(Some(Message::Pass(report, Some(image), noise))) => Ok(Some(Pass {
                index: report.pass,
                image: image_to_array(py, &image)?.unbind(),
                noise,
                seconds: report.seconds,
            })),
            Ok(Some(Message::Failed(e))) => {
                *guard = None;
                Err(PyRuntimeError::new_err(e))
            }
            Ok(_) => {
                *guard = None;
                Ok(None)
            }
            Err(e) => {
                *guard = None;
                Err(e)
            }
        }
    }
}

/// The engine's notes: a fallback or anything refused as a warning (never
/// silent), the rest to the logger "hikari_render".
fn warn_each(py: Python<'_>, notes: &[String]) -> PyResult<()> {
    if notes.is_empty() {
        return Ok(());
    }
    let warnings = py.import("warnings")?;
    let logger = py.import("logging")?.call_method1("getLogger", ("hikari_render",))?;
    for note in notes {
        if note.contains("instead") || note.starts_with("warning") || note.contains("ignored") {
            warnings.call_method1("warn", (note.as_str(), py.get_type::<pyo3::exceptions::PyRuntimeWarning>()))?;
        } else {
            logger.call_method1("info", (note.as_str(),))?;
        }
    }
    Ok(())
}

//! `hikari_render._hikari`: hikari from Python. Every render goes through
//! the engine's `Session`, as the CLI's do, so the same settings give the
//! same pixels. `python/hikari_render/__init__.py` re-exports this module;
//! `__init__.pyi` types it.

mod convert;
mod edit;
mod scene;
mod settings;
mod worker;

use pyo3::create_exception;
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use std::path::PathBuf;

create_exception!(
    _hikari,
    SceneError,
    PyValueError,
    "A scene that cannot be loaded: the message names the file, the place in it and the problem, as the CLI's does."
);

/// The built-in scenes' names (`load` takes them).
#[pyfunction]
fn scenes() -> Vec<&'static str> {
    hikari_core::scene::builtin::NAMES.to_vec()
}

/// Writes `image` (float32, shape (height, width, 3), linear) to `path`:
/// a .png tone-mapped as the CLI does after `exposure` stops, or an .exr of
/// linear float RGB. The file appears whole or not at all.
#[pyfunction]
#[pyo3(signature = (path, image, *, exposure = 0.0))]
fn save(py: Python<'_>, path: PathBuf, image: numpy::PyReadonlyArray3<'_, f32>, exposure: f32) -> PyResult<()> {
    let image = convert::image_from_array(&image)?;
    py.detach(|| hikari_core::output::write_image(&path, &image, exposure))
        .map_err(|e| pyo3::exceptions::PyOSError::new_err(e.to_string()))
}

#[pymodule]
fn _hikari(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    m.add("SceneError", m.py().get_type::<SceneError>())?;
    m.add_function(wrap_pyfunction!(scenes, m)?)?;
    m.add_function(wrap_pyfunction!(scene::load, m)?)?;
    m.add_function(wrap_pyfunction!(save, m)?)?;
    m.add_class::<scene::Scene>()?;
    m.add_class::<edit::Camera>()?;
    m.add_class::<edit::Light>()?;
    m.add_class::<edit::MaterialView>()?;
    m.add_class::<scene::Pass>()?;
    m.add_class::<scene::Passes>()?;
    Ok(())
}

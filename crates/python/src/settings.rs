//! Python's keyword arguments as the engine's settings and plan.

use hikari_engine::{Plan, RenderSettings, RendererKind};
use pyo3::conversion::FromPyObjectOwned;
use pyo3::exceptions::{PyTypeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use std::time::Duration;

/// What `Scene.render` and `Scene.progressive` were asked for.
#[derive(Clone, Debug)]
pub struct Request {
    pub settings: RenderSettings,
    pub plan: Plan,
    pub resolution: Option<(u32, u32)>,
    pub threads: Option<usize>,
    pub at: f32,
    /// Also the AOVs (albedo, normal, depth).
    pub aovs: bool,
}

/// The keyword arguments `Scene.render` and `Scene.progressive` take.
pub const KEYWORDS: &[&str] =
    &["spp", "passes", "time", "target_error", "photons", "radius", "resolution", "seed", "threads", "at", "aovs"];

/// `renderer` and the keyword arguments, checked as the CLI checks its
/// flags (the scene's own limits are checked once it is posed); an
/// unknown keyword is a TypeError, as Python's own calls make it.
pub fn request(renderer: &str, kwargs: Option<&Bound<'_, PyDict>>) -> PyResult<Request> {
    fn get<'py, T: FromPyObjectOwned<'py>>(kwargs: Option<&Bound<'py, PyDict>>, key: &str) -> PyResult<Option<T>> {
        match kwargs.map(|k| k.get_item(key)).transpose()?.flatten() {
            Some(value) if !value.is_none() => value.extract::<T>().map(Some).map_err(|e| {
                let e: PyErr = e.into();
                let shown = value.repr().map_or_else(|_| "?".to_string(), |r| r.to_string());
                PyValueError::new_err(format!("{key}={shown}: {e}"))
            }),
            _ => Ok(None),
        }
    }
    if let Some(kwargs) = kwargs {
        for key in kwargs.keys() {
            let key: String = key.extract()?;
            if !KEYWORDS.contains(&key.as_str()) {
                return Err(PyTypeError::new_err(format!(
                    "unexpected keyword argument {key:?} (takes {})",
                    KEYWORDS.join(", ")
                )));
            }
        }
    }
    let spp: Option<u32> = get(kwargs, "spp")?;
    let passes: Option<u32> = get(kwargs, "passes")?;
    let time: Option<f64> = get(kwargs, "time")?;
    let target_error: Option<f64> = get(kwargs, "target_error")?;
    let photons: Option<u64> = get(kwargs, "photons")?;
    let radius: Option<f32> = get(kwargs, "radius")?;
    let resolution: Option<(u32, u32)> = get(kwargs, "resolution")?;
    let seed: u64 = get(kwargs, "seed")?.unwrap_or(0);
    let threads: Option<usize> = get(kwargs, "threads")?;
    let at: f32 = get(kwargs, "at")?.unwrap_or(0.0);
    let aovs: bool = get(kwargs, "aovs")?.unwrap_or(false);
    let bad = |m: String| Err(PyValueError::new_err(m));
    let Some(kind) = RendererKind::from_name(renderer) else {
        return bad(format!("renderer={renderer:?}: one of \"gpu\", \"photon-cpu\", \"path\", \"vcm\""));
    };
    if let Some(t) = time.filter(|t| !(*t > 0.0 && *t <= 3.2e7)) {
        return bad(format!("time={t}: seconds, more than 0 and at most a year"));
    }
    if let Some(e) = target_error.filter(|e| !(*e > 0.0 && *e < 1.0)) {
        return bad(format!("target_error={e}: a fraction between 0 and 1 (e.g. 0.02 for 2%)"));
    }
    if passes == Some(0) {
        return bad("passes=0: at least 1".into());
    }
    if threads == Some(0) {
        return bad("threads=0: at least 1 (None: all cores)".into());
    }
    if !(0.0..=1e6).contains(&at) {
        return bad(format!("at={at}: seconds between 0 and 1,000,000"));
    }
    if let Some((w, h)) = resolution {
        use hikari_core::scene::limits::{MAX_PIXELS, MAX_SIDE};
        if w == 0 || h == 0 || w > MAX_SIDE || h > MAX_SIDE || w as u64 * h as u64 > MAX_PIXELS {
            return bad(format!("resolution=({w}, {h}): each side 1 to {MAX_SIDE}, at most {MAX_PIXELS} pixels"));
        }
    }
    let defaults = RenderSettings::default();
    let settings =
        RenderSettings { renderer: kind, spp, photons: photons.unwrap_or(defaults.photons), radius, seed, ..defaults };
    let plan = Plan { passes, time: time.map(Duration::from_secs_f64), target_error, ..Default::default() };
    Ok(Request { settings, plan, resolution, threads, at, aovs })
}

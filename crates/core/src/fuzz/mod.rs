//! Structured fuzzing of scene files: mutate a valid scene (numbers pushed
//! to extremes, entries swapped, dropped or duplicated, keys moved between
//! entries, values of the wrong type), load it, and render what loads at a
//! tiny size through each renderer given. The loader must answer with a
//! `Scene` or a `SceneError` that has a position; nothing may panic, and
//! every pixel must be finite with no sample dropped as non-finite.
//!
//! Renderers are closures, so that a crate on top (the GPU renderer) can
//! add its own: see `cpu_renderers` and `check_text`.

use crate::photon::{TraceSettings, trace_photons};
use crate::progress::Silent;
use crate::render::{Image, path, photon_cpu};
use crate::sampling::Rng;
use crate::scene::{Scene, SceneError};
use std::panic::{AssertUnwindSafe, catch_unwind};
use std::path::Path;
use std::sync::Mutex;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::time::{Duration, Instant};
use toml::{Table, Value};

pub mod gltf;

/// Renders a scene (already at its tiny test size); returns the image and
/// the number of samples the renderer dropped as non-finite.
pub type RenderFn<'a> = Box<dyn Fn(&Scene) -> (Image, u64) + 'a>;

/// A named renderer for `check_text`.
pub struct Renderer<'a> {
    pub name: &'static str,
    pub render: RenderFn<'a>,
}

/// Side of the square image every mutant is rendered at.
pub const SIZE: u32 = 8;

/// `photon-cpu` (a few hundred photons, 1 spp) and `path` (1 spp).
pub fn cpu_renderers() -> Vec<Renderer<'static>> {
    vec![
        Renderer {
            name: "photon-cpu",
            render: Box::new(|scene: &Scene| {
                let traced = trace_photons(scene, &TraceSettings { photons: 300, seed: 1, max_bounces: 16 }, &Silent);
                let settings = photon_cpu::PhotonCpuSettings { spp: 1, area_light_samples: 1, ..Default::default() };
                photon_cpu::PhotonCpuRenderer::new(scene, &traced, &settings).render(&Silent)
            }),
        },
        Renderer {
            name: "path",
            render: Box::new(|scene: &Scene| {
                path::render(scene, &path::PathSettings { spp: 1, seed: 1, max_depth: 16, pass: 1 }, &Silent)
            }),
        },
    ]
}

/// What a scene text came to, when nothing went wrong.
#[derive(Debug)]
pub enum Outcome {
    /// Loaded and rendered finite by every renderer.
    Rendered,
    /// Rejected by the loader with a located error.
    Rejected(SceneError),
}

/// Loads `text` (relative meshes against `base_dir`) and renders it at
/// `SIZE`×`SIZE` with each renderer. `Err` describes a failure: a panic, an
/// error without a position, a non-finite pixel or dropped sample, or a
/// render slower than `slow`.
pub fn check_text(
    text: &str,
    name: &str,
    base_dir: Option<&Path>,
    renderers: &[Renderer],
    slow: Duration,
) -> Result<Outcome, String> {
    let loaded = guarded(|| Scene::from_toml(text, name, base_dir)).map_err(|p| format!("loader panicked: {p}"))?;
    let scene = match loaded {
        Err(e) if e.position.is_none() && !e.message.contains("no [[light]]") => {
            return Err(format!("loader error without a position: {e}"));
        }
        Err(e) => return Ok(Outcome::Rejected(e)),
        Ok(scene) => scene,
    };
    render_all(scene, renderers, slow)
}

/// Renders a loaded `scene` at `SIZE`×`SIZE` with each renderer (see `check_text`).
fn render_all(mut scene: Scene, renderers: &[Renderer], slow: Duration) -> Result<Outcome, String> {
    scene.camera = scene.camera.with_resolution(SIZE, SIZE).map_err(|e| format!("camera: {e}"))?;
    for r in renderers {
        let start = Instant::now();
        let (image, dropped) = guarded(|| (r.render)(&scene)).map_err(|p| format!("{} panicked: {p}", r.name))?;
        if let Some(i) = image.pixels.iter().position(|p| !p.is_finite()) {
            return Err(format!("{}: pixel {i} is {}", r.name, image.pixels[i]));
        }
        if dropped > 0 {
            return Err(format!("{}: {dropped} samples were not finite", r.name));
        }
        if start.elapsed() > slow {
            return Err(format!("{}: took {:.1} s for {SIZE}x{SIZE}", r.name, start.elapsed().as_secs_f64()));
        }
    }
    Ok(Outcome::Rendered)
}

/// The message of the last panic, set by the hook `quiet_panics` installs.
static LAST_PANIC: Mutex<Option<String>> = Mutex::new(None);

/// How many `guarded` calls are running: panics outside them go to the
/// previous hook as usual (a failing assertion must still be printed).
static GUARDED: AtomicUsize = AtomicUsize::new(0);

/// Replaces the panic hook with one that records the message (and where)
/// of a panic inside `check_text` instead of printing it, so a fuzz run's
/// output stays readable. For fuzz drivers: it affects the whole process.
pub fn quiet_panics() {
    let previous = std::panic::take_hook();
    std::panic::set_hook(Box::new(move |info| {
        if GUARDED.load(Ordering::SeqCst) == 0 {
            return previous(info);
        }
        let at = info.location().map(|l| format!(" at {}:{}", l.file(), l.line())).unwrap_or_default();
        let msg = payload_text(info.payload());
        *LAST_PANIC.lock().unwrap_or_else(|e| e.into_inner()) = Some(format!("{msg}{at}"));
    }));
}

fn payload_text(payload: &(dyn std::any::Any + Send)) -> String {
    payload
        .downcast_ref::<&str>()
        .map(|s| s.to_string())
        .or_else(|| payload.downcast_ref::<String>().cloned())
        .unwrap_or_else(|| "(no message)".into())
}

/// Runs `f`, turning a panic into its message.
fn guarded<T>(f: impl FnOnce() -> T) -> Result<T, String> {
    GUARDED.fetch_add(1, Ordering::SeqCst);
    let result = catch_unwind(AssertUnwindSafe(f));
    GUARDED.fetch_sub(1, Ordering::SeqCst);
    result.map_err(|payload| {
        let recorded = LAST_PANIC.lock().unwrap_or_else(|e| e.into_inner()).take();
        recorded.unwrap_or_else(|| payload_text(payload.as_ref()))
    })
}

/// Numbers the mutator writes in place of a number: the edges of every
/// documented range and far beyond them.
const EXTREMES: &[f64] = &[
    0.0,
    -0.0,
    1.0,
    -1.0,
    1e-45,
    1e-38,
    1e-30,
    -1e-30,
    1e-20,
    1e-12,
    1e-7,
    1e-6,
    1e-3,
    0.5,
    0.99999994,
    0.999,
    1.00001,
    2.0,
    89.999,
    90.0,
    179.0,
    179.99,
    180.0,
    360.0,
    1e3,
    16384.0,
    16385.0,
    1e5,
    1e6,
    -1e6,
    1.000001e6,
    2e6,
    1e7,
    1e20,
    1e30,
    -1e30,
    1e38,
    -1e38,
    3.4e38,
    1e300,
    f64::NAN,
    f64::INFINITY,
    f64::NEG_INFINITY,
];

/// Integers likewise (resolution, and floats written as integers).
const INT_EXTREMES: &[i64] = &[
    0,
    1,
    -1,
    2,
    7,
    8192,
    16384,
    16385,
    100_000,
    1 << 24,
    i32::MAX as i64,
    u32::MAX as i64,
    1 << 32,
    i64::MAX,
    i64::MIN,
];

/// Strings the mutator writes in place of a string.
const WORDS: &[&str] = &[
    "diffuse",
    "mirror",
    "glass",
    "emitter",
    "sphere",
    "quad",
    "box",
    "point",
    "spot",
    "hg",
    "schlick",
    "meshes/fog-layer.obj",
    "missing.obj",
    "",
    "white",
    "glass",
    "red",
];

/// Keys the mutator may add to an entry (from any kind of entry).
const KEYS: &[&str] = &[
    "position",
    "look_at",
    "up",
    "fov_y",
    "resolution",
    "albedo",
    "specular_reflectance",
    "reflectance",
    "ior",
    "shape",
    "mesh",
    "center",
    "radius",
    "corner",
    "edge_u",
    "edge_v",
    "size",
    "rotate_y",
    "scale",
    "translate",
    "intensity",
    "direction",
    "cutoff_angle",
    "falloff_start_angle",
    "radiance",
    "sigma_a",
    "sigma_s",
    "phase",
    "k",
    "g",
    "region",
    "type",
    "material",
    "name",
];

/// Applies 1 to 4 random mutations to a scene file. Text that is not valid
/// TOML comes back unchanged.
pub fn mutate(text: &str, rng: &mut Rng) -> String {
    let Ok(mut table) = text.parse::<Table>() else { return text.to_string() };
    let count = 1 + (rng.next_u32() % 4) as usize;
    for _ in 0..count {
        mutate_once(&mut table, rng);
    }
    toml::to_string(&table).unwrap_or_else(|_| text.to_string())
}

fn pick(rng: &mut Rng, n: usize) -> usize {
    (rng.next_u32() as usize) % n.max(1)
}

fn mutate_once(table: &mut Table, rng: &mut Rng) {
    match pick(rng, 10) {
        // Numbers are most of a scene: mutate them most often.
        0..=4 => {
            let mut leaves = Vec::new();
            walk(&Value::Table(table.clone()), &mut Vec::new(), &mut leaves);
            if !leaves.is_empty() {
                let path = leaves.swap_remove(pick(rng, leaves.len()));
                if let Some(v) = at_path(table, &path) {
                    *v = new_number(v, rng);
                }
            }
        }
        5 => entries_op(table, rng),
        6 => {
            // Drop a key of some entry.
            if let Some(entry) = random_entry(table, rng) {
                let keys: Vec<String> = entry.keys().cloned().collect();
                if !keys.is_empty() {
                    entry.remove(&keys[pick(rng, keys.len())]);
                }
            }
        }
        7 => {
            // Add a key that may not belong, with a plausible value.
            let key = KEYS[pick(rng, KEYS.len())];
            let value = match pick(rng, 4) {
                0 => Value::Float(EXTREMES[pick(rng, EXTREMES.len())]),
                1 => Value::String(WORDS[pick(rng, WORDS.len())].into()),
                _ => Value::Array((0..3).map(|_| Value::Float(EXTREMES[pick(rng, EXTREMES.len())])).collect()),
            };
            if let Some(entry) = random_entry(table, rng) {
                entry.insert(key.into(), value);
            }
        }
        8 => {
            // Replace a string with another known word.
            if let Some(entry) = random_entry(table, rng) {
                let keys: Vec<String> = entry.iter().filter(|(_, v)| v.is_str()).map(|(k, _)| k.clone()).collect();
                if !keys.is_empty() {
                    let k = &keys[pick(rng, keys.len())];
                    entry.insert(k.clone(), Value::String(WORDS[pick(rng, WORDS.len())].into()));
                }
            }
        }
        _ => {
            // Change a value's shape: arrays grow or shrink, scalars become arrays.
            if let Some(entry) = random_entry(table, rng) {
                let keys: Vec<String> = entry.keys().cloned().collect();
                if !keys.is_empty() {
                    let k = keys[pick(rng, keys.len())].clone();
                    let v = entry.get_mut(&k).expect("key listed");
                    *v = match std::mem::replace(v, Value::Boolean(false)) {
                        Value::Array(mut a) if pick(rng, 2) == 0 && !a.is_empty() => {
                            a.pop();
                            Value::Array(a)
                        }
                        Value::Array(mut a) => {
                            a.push(Value::Float(EXTREMES[pick(rng, EXTREMES.len())]));
                            Value::Array(a)
                        }
                        other if pick(rng, 2) == 0 => Value::Array(vec![other]),
                        _ => Value::Integer(INT_EXTREMES[pick(rng, INT_EXTREMES.len())]),
                    };
                }
            }
        }
    }
}

/// A new value for the number `v`: an extreme, or `v` scaled, negated or
/// nudged, as a float or an integer.
fn new_number(v: &Value, rng: &mut Rng) -> Value {
    let x = v.as_float().or_else(|| v.as_integer().map(|i| i as f64)).unwrap_or(1.0);
    match pick(rng, 8) {
        0..=2 => Value::Float(EXTREMES[pick(rng, EXTREMES.len())]),
        3 => Value::Integer(INT_EXTREMES[pick(rng, INT_EXTREMES.len())]),
        4 => Value::Float(x * [1e3, 1e6, 1e-3, 1e-6, 1e30, 1e-30][pick(rng, 6)]),
        5 => Value::Float(-x),
        6 => Value::Float(x + [1e-7, -1e-7, 1e-3, 0.5][pick(rng, 4)]),
        _ => match v {
            // Flip the type: an integer where a float was, and back.
            Value::Float(f) if f.is_finite() && f.abs() < 9e18 => Value::Integer(*f as i64),
            _ => Value::Float(x),
        },
    }
}

/// One step of a path to a value: a key of a table or an index of an array.
#[derive(Clone, Debug)]
enum Step {
    Key(String),
    Index(usize),
}

/// Paths of every number in `value`, below `prefix`.
fn walk(value: &Value, prefix: &mut Vec<Step>, out: &mut Vec<Vec<Step>>) {
    match value {
        Value::Integer(_) | Value::Float(_) => out.push(prefix.clone()),
        Value::Array(a) => {
            for (i, v) in a.iter().enumerate() {
                prefix.push(Step::Index(i));
                walk(v, prefix, out);
                prefix.pop();
            }
        }
        Value::Table(t) => {
            for (k, v) in t {
                prefix.push(Step::Key(k.clone()));
                walk(v, prefix, out);
                prefix.pop();
            }
        }
        _ => {}
    }
}

fn at_path<'a>(table: &'a mut Table, path: &[Step]) -> Option<&'a mut Value> {
    let (first, rest) = path.split_first()?;
    let Step::Key(k) = first else { return None };
    let mut v = table.get_mut(k)?;
    for step in rest {
        v = match (step, v) {
            (Step::Key(k), Value::Table(t)) => t.get_mut(k)?,
            (Step::Index(i), Value::Array(a)) => a.get_mut(*i)?,
            _ => return None,
        };
    }
    Some(v)
}

/// The `[camera]` table or an entry of one of the `[[...]]` arrays.
fn random_entry<'a>(table: &'a mut Table, rng: &mut Rng) -> Option<&'a mut Table> {
    let keys: Vec<String> = table.keys().cloned().collect();
    let key = keys.get(pick(rng, keys.len()))?;
    match table.get_mut(key)? {
        Value::Table(t) => Some(t),
        Value::Array(a) if !a.is_empty() => {
            let i = pick(rng, a.len());
            a[i].as_table_mut()
        }
        _ => None,
    }
}

/// Swaps, drops or duplicates entries of one `[[...]]` array.
fn entries_op(table: &mut Table, rng: &mut Rng) {
    let arrays: Vec<String> = table.iter().filter(|(_, v)| v.is_array()).map(|(k, _)| k.clone()).collect();
    let Some(key) = arrays.get(pick(rng, arrays.len())) else { return };
    let Some(Value::Array(a)) = table.get_mut(key) else { return };
    if a.is_empty() {
        return;
    }
    let (i, j) = (pick(rng, a.len()), pick(rng, a.len()));
    match pick(rng, 3) {
        0 => a.swap(i, j),
        1 => {
            a.remove(i);
        }
        _ => {
            let copy = a[i].clone();
            a.insert(j, copy);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn mutants_differ_and_stay_toml() {
        let base = crate::scene::builtin::source("cornell-box").unwrap();
        let mut rng = Rng::for_item(5, 0);
        let mut changed = 0;
        for _ in 0..50 {
            let m = mutate(base, &mut rng);
            assert!(m.parse::<Table>().is_ok(), "{m}");
            changed += (m.parse::<Table>().unwrap() != base.parse::<Table>().unwrap()) as u32;
        }
        assert!(changed >= 45, "{changed} of 50 mutants differ from the base");
    }

    #[test]
    fn a_panicking_renderer_is_reported() {
        let base = crate::scene::builtin::source("cornell-box").unwrap();
        let boom = [Renderer { name: "boom", render: Box::new(|_: &Scene| panic!("kaboom")) }];
        let e = check_text(base, "builtin:cornell-box", None, &boom, Duration::from_secs(60)).unwrap_err();
        assert!(e.contains("boom panicked") && e.contains("kaboom"), "{e}");
    }
}

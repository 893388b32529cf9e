//! Functions the page's script can call (`window.hikari` in
//! `web/index.html`): what the browser tests read, and what a page that
//! embeds hikari may want.

use crate::app::VIEWER;
use wasm_bindgen::prelude::*;

fn with_viewer<T>(f: impl FnOnce(&crate::app::Viewer) -> T) -> Option<T> {
    VIEWER.with(|v| v.borrow().upgrade()).map(|viewer| f(&viewer.borrow()))
}

/// Frames in the running mean on screen (0 before the first).
#[wasm_bindgen(js_name = framesInMean)]
pub fn frames_in_mean() -> u32 {
    with_viewer(|v| v.frames_in_mean()).unwrap_or(0)
}

/// The adapter the page renders on, as the panel names it ("" before WebGPU answered).
#[wasm_bindgen]
pub fn adapter() -> String {
    with_viewer(|v| v.readouts.adapter.clone()).unwrap_or_default()
}

/// Where frames go: "surface" (the canvas's WebGPU surface), "copy" (read
/// back into a 2D canvas, where the browser cannot present a WebGPU
/// canvas), "" before WebGPU answered.
#[wasm_bindgen]
pub fn presentation() -> String {
    with_viewer(|v| v.presentation().to_string()).unwrap_or_default()
}

/// Where photons are traced: "GPU" (the compute-shader tracer), "CPU"
/// (the page's thread, where the GPU tracer cannot run), "" before the first set.
#[wasm_bindgen]
pub fn tracer() -> String {
    with_viewer(|v| v.tracer_device().to_string()).unwrap_or_default()
}

/// The scene on screen: a built-in scene's name or the dropped files'.
#[wasm_bindgen(js_name = sceneName)]
pub fn scene_name() -> String {
    with_viewer(|v| v.scene_name.clone()).unwrap_or_default()
}

/// The error the page shows ("" when none).
#[wasm_bindgen(js_name = lastError)]
pub fn last_error() -> String {
    with_viewer(|v| v.error.clone().unwrap_or_default()).unwrap_or_else(crate::page::error_text)
}

/// PNG downloads made by the panel's "save PNG".
#[wasm_bindgen(js_name = savedPngs)]
pub fn saved_pngs() -> u32 {
    with_viewer(|v| v.saved_pngs).unwrap_or(0)
}

/// The panel's terms as "direct,indirect,…" (those switched on).
#[wasm_bindgen]
pub fn terms() -> String {
    with_viewer(|v| v.terms()).unwrap_or_default()
}

/// The running mean's linear radiance: width, height, then RGBA floats
/// row by row from the top.
#[wasm_bindgen(js_name = readMean)]
pub async fn read_mean() -> Result<js_sys::Float32Array, JsValue> {
    let (ctx, texture) =
        with_viewer(|v| v.mean_texture()).flatten().ok_or_else(|| JsValue::from_str("no frame yet"))?;
    let pixels =
        hikari_gpu::readback::read_rgba_async(&ctx, &texture).await.map_err(|e| JsValue::from_str(&e.to_string()))?;
    let mut out = Vec::with_capacity(2 + pixels.len() * 4);
    out.push(texture.width() as f32);
    out.push(texture.height() as f32);
    out.extend(pixels.iter().flat_map(|p| p.to_array()));
    Ok(js_sys::Float32Array::from(out.as_slice()))
}

/// Where the panel last drew the widget named `name` (a term's checkbox,
/// "save PNG", "open") as [left, top, right, bottom] in CSS pixels; empty
/// when it was not drawn.
#[wasm_bindgen(js_name = widgetRect)]
pub fn widget_rect(name: &str) -> Vec<f32> {
    with_viewer(|v| v.widget_rect(name)).flatten().map_or(Vec::new(), |r| r.to_vec())
}

/// The last timed frame's passes as JSON, `{"timed": "wall clock",
/// "passes": [{"pass": "g-buffer", "ms": 1.5}, …]}` (or "timestamps"): the panel's
/// "GPU passes" (a frame is timed every 2 s while the panel shows).
#[wasm_bindgen(js_name = passTimes)]
pub fn pass_times() -> String {
    with_viewer(|v| {
        let passes: Vec<String> =
            v.readouts.passes.iter().map(|(name, ms)| format!("{{\"pass\":\"{name}\",\"ms\":{ms}}}")).collect();
        let how = if v.readouts.timestamps { "timestamps" } else { "wall clock" };
        format!("{{\"timed\":\"{how}\",\"passes\":[{}]}}", passes.join(","))
    })
    .unwrap_or_default()
}

/// The mean's noise as its frames estimate it, relative to its mean (the
/// panel's "noise ≈"); NaN before it was first read.
#[wasm_bindgen]
pub fn noise() -> f64 {
    with_viewer(|v| v.readouts.noise).flatten().unwrap_or(f64::NAN)
}

/// Mean frames per second since the page's first frame (the panel's figure).
#[wasm_bindgen]
pub fn fps() -> f64 {
    with_viewer(|v| v.readouts.fps).unwrap_or(0.0)
}

//! hikari in a browser tab: the viewer of `hikari view` on WebGPU, built to
//! `wasm32-unknown-unknown` and bound with wasm-bindgen
//! (`bash scripts/web.sh build`, docs/web.md).
//!
//! A browser gives a page one thread, and nothing on it may block: the
//! frame is driven by `requestAnimationFrame` (winit's redraws), every GPU
//! readback is awaited (`hikari_gpu`'s `_async` calls), and photons are
//! traced by the GPU tracer in a task of their own, whose readbacks yield
//! to the frames between batches. The page's address chooses the scene
//! and the photons (`options`); files dropped on it become the scene
//! (`files`). Natively only those two pure parts build (and are tested).

pub mod files;
pub mod options;

#[cfg(target_arch = "wasm32")]
mod api;
#[cfg(target_arch = "wasm32")]
mod app;
#[cfg(target_arch = "wasm32")]
mod canvas_copy;
#[cfg(target_arch = "wasm32")]
mod input;
#[cfg(target_arch = "wasm32")]
mod page;
#[cfg(target_arch = "wasm32")]
mod photons;

/// The page's entry point (wasm-bindgen calls it when the module loads).
#[cfg(target_arch = "wasm32")]
#[wasm_bindgen::prelude::wasm_bindgen(start)]
pub fn start() {
    page::install_panic_hook();
    if !page::has_webgpu() {
        page::show_no_webgpu();
        return;
    }
    match options::PageOptions::parse(&page::query()) {
        Ok(options) => app::run(options),
        Err(e) => page::show_error(&e),
    }
}

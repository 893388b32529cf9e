//! The page around the canvas (`web/index.html`): its status line, its
//! error box, the panic hook that fills it, the no-WebGPU message, file
//! drops and the file dialog, and downloads.

use crate::files::DroppedFile;
use wasm_bindgen::JsCast;
use wasm_bindgen::prelude::*;
use wasm_bindgen_futures::JsFuture;

/// The one line a browser without WebGPU shows instead of a blank canvas.
pub const NO_WEBGPU: &str = "hikari needs WebGPU, which this browser does not offer: use Chrome or Edge 113 or \
     later (on Linux with chrome://flags/#enable-unsafe-webgpu and #enable-vulkan), Safari 26, or Firefox 141 \
     on Windows (dom.webgpu.enabled elsewhere).";

pub fn window() -> web_sys::Window {
    web_sys::window().expect("a page has a window")
}

pub fn document() -> web_sys::Document {
    window().document().expect("a page has a document")
}

fn element(id: &str) -> Option<web_sys::HtmlElement> {
    document().get_element_by_id(id).and_then(|e| e.dyn_into().ok())
}

/// The page's address query (`?scene=…`).
pub fn query() -> String {
    window().location().search().unwrap_or_default()
}

/// Shows `text` in the status line (empty: hides it) and logs it.
pub fn set_status(text: &str) {
    if let Some(status) = element("status") {
        status.set_text_content(Some(text));
        let _ = status.style().set_property("display", if text.is_empty() { "none" } else { "block" });
    }
    if !text.is_empty() {
        web_sys::console::log_1(&format!("hikari: {text}").into());
    }
}

/// Shows an error on the page (and in the console).
pub fn show_error(text: &str) {
    web_sys::console::error_1(&format!("hikari: {text}").into());
    if let Some(error) = element("error") {
        error.set_text_content(Some(text));
        let _ = error.style().set_property("display", "block");
    }
}

pub fn clear_error() {
    if let Some(error) = element("error") {
        error.set_text_content(None);
        let _ = error.style().set_property("display", "none");
    }
}

/// The error box's text (empty when none shows).
pub fn error_text() -> String {
    element("error").and_then(|e| e.text_content()).unwrap_or_default()
}

/// A panic shows its message on the page, not only in the console.
pub fn install_panic_hook() {
    std::panic::set_hook(Box::new(|info| {
        show_error(&format!("hikari stopped: {info} (reload the page to start again)"));
        set_status("");
    }));
}

/// Whether `navigator.gpu` exists (the browser speaks WebGPU).
pub fn has_webgpu() -> bool {
    let navigator = window().navigator();
    js_sys::Reflect::get(&navigator, &"gpu".into()).is_ok_and(|gpu| !gpu.is_undefined() && !gpu.is_null())
}

pub fn show_no_webgpu() {
    set_status("");
    if let Some(canvas) = element("hikari-canvas") {
        let _ = canvas.style().set_property("display", "none");
    }
    if let Some(message) = element("no-webgpu") {
        message.set_text_content(Some(NO_WEBGPU));
        let _ = message.style().set_property("display", "block");
    }
    web_sys::console::warn_1(&NO_WEBGPU.into());
}

/// Offers `bytes` as a download named `name`.
pub fn download(name: &str, bytes: &[u8], mime: &str) -> Result<(), JsValue> {
    let parts = js_sys::Array::of1(&js_sys::Uint8Array::from(bytes));
    let properties = web_sys::BlobPropertyBag::new();
    properties.set_type(mime);
    let blob = web_sys::Blob::new_with_u8_array_sequence_and_options(&parts, &properties)?;
    let url = web_sys::Url::create_object_url_with_blob(&blob)?;
    let link: web_sys::HtmlAnchorElement = document().create_element("a")?.dyn_into()?;
    link.set_href(&url);
    link.set_download(name);
    link.click();
    // Released once the browser has taken the download.
    let release = Closure::once_into_js(move || {
        let _ = web_sys::Url::revoke_object_url(&url);
    });
    window().set_timeout_with_callback_and_timeout_and_arguments_0(release.unchecked_ref(), 60_000)?;
    Ok(())
}

/// Opens the page's file dialog (`<input id="file">`).
pub fn open_file_dialog() {
    if let Some(input) = element("file") {
        input.click();
    }
}

/// Calls `open` with the files dropped on the page or picked in its file
/// dialog (read asynchronously, all of one drop together).
pub fn on_files(open: impl Fn(Vec<DroppedFile>) + 'static) -> Result<(), JsValue> {
    let open = std::rc::Rc::new(open);
    let read = {
        let open = open.clone();
        move |list: Option<web_sys::FileList>| {
            let Some(list) = list else { return };
            let files: Vec<web_sys::File> = (0..list.length()).filter_map(|i| list.get(i)).collect();
            if files.is_empty() {
                return;
            }
            let open = open.clone();
            wasm_bindgen_futures::spawn_local(async move {
                let mut read = Vec::new();
                for file in files {
                    match JsFuture::from(file.array_buffer()).await {
                        Ok(buffer) => read
                            .push(DroppedFile { name: file.name(), bytes: js_sys::Uint8Array::new(&buffer).to_vec() }),
                        Err(e) => show_error(&format!("{}: cannot read the file: {e:?}", file.name())),
                    }
                }
                if !read.is_empty() {
                    open(read);
                }
            });
        }
    };
    let read = std::rc::Rc::new(read);
    let document = document();
    let over = Closure::<dyn Fn(web_sys::DragEvent)>::new(|event: web_sys::DragEvent| event.prevent_default());
    document.add_event_listener_with_callback("dragover", over.as_ref().unchecked_ref())?;
    over.forget();
    let dropped = {
        let read = read.clone();
        Closure::<dyn Fn(web_sys::DragEvent)>::new(move |event: web_sys::DragEvent| {
            event.prevent_default();
            read(event.data_transfer().and_then(|d| d.files()));
        })
    };
    document.add_event_listener_with_callback("drop", dropped.as_ref().unchecked_ref())?;
    dropped.forget();
    if let Some(input) = element("file") {
        let input: web_sys::HtmlInputElement = input.unchecked_into();
        let target = input.clone();
        let changed = Closure::<dyn Fn()>::new(move || {
            read(target.files());
            // The same file picked again is a change too.
            target.set_value("");
        });
        input.add_event_listener_with_callback("change", changed.as_ref().unchecked_ref())?;
        changed.forget();
    }
    Ok(())
}

/// Resolves after `ms` milliseconds (the browser's timer; the page's other
/// tasks run meanwhile).
pub async fn sleep(ms: i32) {
    let promise = js_sys::Promise::new(&mut |resolve, _| {
        let _ = window().set_timeout_with_callback_and_timeout_and_arguments_0(&resolve, ms);
    });
    let _ = wasm_bindgen_futures::JsFuture::from(promise).await;
}

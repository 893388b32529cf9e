//! The wgpu device: chosen once (see `capabilities`), shared by every pass,
//! with every GPU error turned into a `GpuError` instead of a panic.

use crate::capabilities::{Capabilities, loop_budget, preference};
use std::sync::{Arc, Mutex};
use std::time::Duration;
use thiserror::Error;

#[derive(Debug, Error)]
pub enum GpuError {
    #[error("no GPU adapter found ({0})")]
    NoAdapter(String),
    #[error("no GPU adapter can run the GPU renderer: {0}")]
    Unsupported(String),
    #[error("the GPU adapter refused a device: {0}")]
    Device(String),
    /// A wgpu validation, out-of-memory or internal error, or a lost device.
    #[error("GPU error: {0}")]
    Failed(String),
    #[error("the GPU did not finish within {0:?}")]
    Timeout(Duration),
    #[error("GPU readback failed: {0}")]
    Readback(String),
    /// The scene or the settings need more than the adapter offers.
    #[error("{0}")]
    TooLarge(String),
    /// The adapter lacks what this scene needs (see `GpuRenderer::unsupported`).
    #[error("{0}")]
    SceneUnsupported(String),
    /// A shader would run past the adapter's loop budget even split up.
    #[error("{0}")]
    LoopBudget(String),
}

/// The first error the device reported outside an error scope, or its loss.
type Fault = Arc<Mutex<Option<String>>>;

/// Clones share the device (and its recorded faults).
#[derive(Clone)]
pub struct GpuContext {
    /// The adapter the device was opened on (a window's surface asks it).
    pub adapter: wgpu::Adapter,
    pub device: wgpu::Device,
    pub queue: wgpu::Queue,
    pub adapter_info: wgpu::AdapterInfo,
    pub limits: wgpu::Limits,
    /// Format of the additive radiance targets: Rgba32Float where the adapter
    /// can blend it, else Rgba16Float (and `float32_blend` is false).
    pub radiance_format: wgpu::TextureFormat,
    pub float32_blend: bool,
    /// GPU timestamps can be written between passes (per-pass timings).
    pub timestamps: bool,
    /// R32Float can be rendered (else shadow maps are R16Float).
    pub r32_renderable: bool,
    /// The G-buffer is stored from fragment shaders (`Capabilities::gbuffer_storage`).
    pub gbuffer_storage: bool,
    /// The G-buffer can keep the layer textures' texels (`Capabilities::layer_texels`):
    /// else clear-coat, sheen and specular textures are drawn as their means.
    pub layer_texels: bool,
    /// Loop iterations one shader invocation may run (`capabilities::loop_budget`).
    pub loop_budget: u32,
    /// Longest wait for submitted work before giving up.
    pub wait_timeout: Duration,
    fault: Fault,
}

/// ", bus 0000:17:00.0" where the adapter reports its PCI bus.
fn bus_suffix(info: &wgpu::AdapterInfo) -> String {
    if info.device_pci_bus_id.is_empty() { String::new() } else { format!(", bus {}", info.device_pci_bus_id) }
}

/// Mesa's device-select Vulkan layer (an implicit layer in Debian's Mesa)
/// asks Wayland and X11 for the default GPU while adapters are enumerated;
/// on a machine with no window system at all, libwayland then prints
/// "error: XDG_RUNTIME_DIR is invalid or not set in the environment." twice
/// on a render that succeeds. Where no display is named (none of
/// `WAYLAND_DISPLAY`, `DISPLAY`, `XDG_RUNTIME_DIR`) the layer has nothing to
/// ask, so this turns it off with its own switch (`NODEVICE_SELECT=1`)
/// unless the user set that already. Returns whether it did.
///
/// # Safety
///
/// It changes the process's environment: call it before any other thread
/// runs (first thing in `main`).
pub unsafe fn quiet_headless_device_select() -> bool {
    let unset = |name: &str| std::env::var_os(name).is_none_or(|v| v.is_empty());
    let headless = unset("WAYLAND_DISPLAY") && unset("DISPLAY") && unset("XDG_RUNTIME_DIR");
    if !headless || std::env::var_os("NODEVICE_SELECT").is_some() {
        return false;
    }
    // SAFETY: the caller runs this before any other thread exists.
    unsafe { std::env::set_var("NODEVICE_SELECT", "1") };
    true
}

/// Default `wait_timeout`: a software adapter needs tens of seconds for a
/// large frame; a hung driver should not hold the CLI for ever.
pub const WAIT_TIMEOUT: Duration = Duration::from_secs(600);

impl GpuContext {
    /// Enumerates the adapters (honouring `WGPU_BACKEND`), tries them in
    /// `capabilities::preference` order and opens a device on the first
    /// that has everything the renderer needs.
    pub fn new() -> Result<Self, GpuError> {
        crate::block::wait_for(Self::new_async())
    }

    /// `new` without blocking (a browser's adapter and device are promises).
    pub async fn new_async() -> Result<Self, GpuError> {
        let instance = wgpu::Instance::new(wgpu::InstanceDescriptor::new_without_display_handle_from_env());
        Self::choose(&instance, None).await
    }

    /// As `new`, among the adapters of `instance` that can present to
    /// `surface` (the viewer's window).
    pub fn for_surface(instance: &wgpu::Instance, surface: &wgpu::Surface) -> Result<Self, GpuError> {
        crate::block::wait_for(Self::for_surface_async(instance, surface))
    }

    /// `for_surface` without blocking.
    pub async fn for_surface_async(instance: &wgpu::Instance, surface: &wgpu::Surface<'_>) -> Result<Self, GpuError> {
        Self::choose(instance, Some(surface)).await
    }

    async fn choose(instance: &wgpu::Instance, surface: Option<&wgpu::Surface<'_>>) -> Result<Self, GpuError> {
        let mut adapters = instance.enumerate_adapters(wgpu::Backends::all()).await;
        if adapters.is_empty() {
            return Err(GpuError::NoAdapter("wgpu enumerated none; WGPU_BACKEND may exclude them".into()));
        }
        adapters.sort_by_key(|a| preference(&a.get_info()));
        // HIKARI_GPU picks one (a cluster task's own GPU, docs/cluster.md).
        if let Ok(wanted) = std::env::var(crate::capabilities::ADAPTER_VARIABLE) {
            let names: Vec<String> = adapters
                .iter()
                .enumerate()
                .map(|(i, a)| {
                    let info = a.get_info();
                    format!("{i}: {} ({:?}{})", info.name, info.backend, bus_suffix(&info))
                })
                .collect();
            let mut index = 0..;
            adapters.retain(|a| crate::capabilities::is_wanted(&wanted, index.next().unwrap_or(0), &a.get_info()));
            if adapters.is_empty() {
                return Err(GpuError::NoAdapter(format!(
                    "{}={wanted} names none of the adapters: {}",
                    crate::capabilities::ADAPTER_VARIABLE,
                    names.join(", ")
                )));
            }
        }
        let mut refusals = Vec::new();
        for adapter in adapters {
            let info = adapter.get_info();
            if surface.is_some_and(|s| !adapter.is_surface_supported(s)) {
                refusals.push(format!("{} ({:?}) cannot present to the window", info.name, info.backend));
                continue;
            }
            match Capabilities::check(&adapter) {
                Ok(caps) => return Self::open(adapter, caps).await,
                Err(why) => refusals.push(format!("{} ({:?}) {why}", info.name, info.backend)),
            }
        }
        Err(GpuError::Unsupported(refusals.join(" | ")))
    }

    async fn open(adapter: wgpu::Adapter, caps: Capabilities) -> Result<Self, GpuError> {
        let limits = adapter.limits();
        let (device, queue) = adapter
            .request_device(&wgpu::DeviceDescriptor {
                label: Some("hikari"),
                required_features: caps.features(),
                // The adapter's own limits: the G-buffer needs 64 bytes per sample
                // of colour attachments, and photon buffers want the largest
                // bindings the adapter allows (sizes are checked against them).
                required_limits: limits.clone(),
                ..Default::default()
            })
            .await
            .map_err(|e| GpuError::Device(e.to_string()))?;
        let fault: Fault = Arc::default();
        let record = |fault: &Fault, what: String| {
            let mut slot = fault.lock().unwrap_or_else(|e| e.into_inner());
            slot.get_or_insert(what);
        };
        let lost = fault.clone();
        device.set_device_lost_callback(move |reason, message| {
            record(&lost, format!("device lost ({reason:?}): {message}"));
        });
        let uncaptured = fault.clone();
        device.on_uncaptured_error(Arc::new(move |error: wgpu::Error| {
            record(&uncaptured, first_line(&error.to_string()));
        }));
        let info = adapter.get_info();
        Ok(GpuContext {
            adapter,
            device,
            queue,
            loop_budget: loop_budget(&info),
            adapter_info: info,
            limits,
            radiance_format: caps.radiance_format(),
            float32_blend: caps.float32_blend,
            timestamps: caps.timestamps,
            gbuffer_storage: caps.gbuffer_storage,
            layer_texels: caps.layer_texels,
            r32_renderable: caps.r32_renderable,
            wait_timeout: WAIT_TIMEOUT,
            fault,
        })
    }

    /// One line naming the adapter, for logs and summaries.
    pub fn describe(&self) -> String {
        let i = &self.adapter_info;
        // Browsers may withhold the name (headless Chromium's SwiftShader does).
        let name = if i.name.is_empty() { "an unnamed adapter" } else { &i.name };
        format!("{name} ({:?}, {:?}){}", i.backend, i.device_type, bus_suffix(i).replacen(",", "", 1))
    }

    /// Runs `f` under error scopes for validation, out-of-memory and internal
    /// errors: the first error any of them caught, or a fault the device
    /// reported meanwhile, becomes the result.
    pub fn scoped<T>(&self, f: impl FnOnce() -> T) -> Result<T, GpuError> {
        let scopes = self.error_scopes();
        let value = f();
        scopes.finish()?;
        self.check()?;
        Ok(value)
    }

    /// Opens error scopes on this thread until `ErrorScopes::finish`.
    pub fn error_scopes(&self) -> ErrorScopes {
        ErrorScopes(
            [wgpu::ErrorFilter::Validation, wgpu::ErrorFilter::OutOfMemory, wgpu::ErrorFilter::Internal]
                .map(|filter| self.device.push_error_scope(filter)),
            self.fault.clone(),
        )
    }

    /// The device's first uncaptured error or its loss, if any.
    pub fn check(&self) -> Result<(), GpuError> {
        match self.fault.lock().unwrap_or_else(|e| e.into_inner()).as_ref() {
            Some(what) => Err(GpuError::Failed(what.clone())),
            None => Ok(()),
        }
    }

    /// Blocks until the submitted work is done, at most `wait_timeout`.
    /// In a browser the device runs by itself and this only checks for
    /// faults: wait for a result with an `_async` readback instead.
    pub fn wait(&self) -> Result<(), GpuError> {
        self.device.poll(wgpu::PollType::Wait { submission_index: None, timeout: Some(self.wait_timeout) }).map_err(
            |e| match e {
                wgpu::PollError::Timeout => GpuError::Timeout(self.wait_timeout),
                other => GpuError::Failed(other.to_string()),
            },
        )?;
        self.check()
    }
}

/// Error scopes for validation, out-of-memory and internal errors, closed
/// by `finish` in reverse order.
pub struct ErrorScopes(
    [wgpu::ErrorScopeGuard; 3],
    /// Where a browser records what the scopes catch (natively unused).
    #[cfg_attr(not(target_arch = "wasm32"), allow(dead_code))]
    Fault,
);

impl ErrorScopes {
    /// The first error the scopes caught, as a `GpuError`. In a browser
    /// the scopes answer later (promises): their first error is recorded
    /// as the device's fault, which the next `GpuContext::check` (every
    /// `scoped` call and readback) reports, so an error still never passes.
    pub fn finish(self) -> Result<(), GpuError> {
        #[cfg(not(target_arch = "wasm32"))]
        {
            crate::block::wait_for(self.finish_async())
        }
        #[cfg(target_arch = "wasm32")]
        {
            let fault = self.1.clone();
            // Popped now (the scope stack is the device's), answered later.
            let answer = self.finish_async();
            wasm_bindgen_futures::spawn_local(async move {
                if let Err(GpuError::Failed(what)) = answer.await {
                    fault.lock().unwrap_or_else(|e| e.into_inner()).get_or_insert(what);
                }
            });
            Ok(())
        }
    }

    /// `finish` waiting without blocking. The scopes are popped when this
    /// is called, before the returned future runs.
    pub fn finish_async(self) -> impl Future<Output = Result<(), GpuError>> + use<> {
        let answers: Vec<_> = self.0.into_iter().rev().map(|scope| scope.pop()).collect();
        async move {
            let mut first = None;
            for answer in answers {
                if let Some(error) = answer.await {
                    first.get_or_insert(error);
                }
            }
            first_error(first)
        }
    }
}

fn first_error(first: Option<wgpu::Error>) -> Result<(), GpuError> {
    match first {
        Some(error) => Err(GpuError::Failed(first_line(&error.to_string()))),
        None => Ok(()),
    }
}

/// wgpu's errors span many lines (the error, then its sources); the CLI
/// prints one line.
fn first_line(text: &str) -> String {
    let lines: Vec<&str> = text.lines().map(str::trim).filter(|l| !l.is_empty()).collect();
    lines.join(" ").chars().take(400).collect()
}

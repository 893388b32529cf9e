//! Where photons are traced (`--trace`): the GPU tracer (hikari_gpu::trace)
//! or the CPU one, chosen once per run and falling back to the CPU, with one
//! line saying why, whenever the GPU cannot trace.

use crate::log::Log;
use hikari_core::photon::{TraceSettings, TracedPhotons, trace_photons};
use hikari_core::progress::Progress;
use hikari_core::scene::Scene;
use hikari_gpu::GpuContext;
use hikari_gpu::trace::GpuTracer;

#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[cfg_attr(feature = "clap", derive(clap::ValueEnum))]
pub enum TraceDevice {
    /// The GPU on a hardware adapter, the CPU on a software one (lavapipe,
    /// llvmpipe), where the "GPU" is the same CPU cores running an emulator
    /// and the native CPU tracer is faster.
    #[default]
    Auto,
    /// A compute shader on the GPU, falling back to the CPU (saying why)
    /// where the adapter or the scene does not allow it.
    Gpu,
    /// The CPU tracer (all cores).
    Cpu,
}

/// The rule of `TraceDevice::Auto`: trace on the GPU unless the adapter is
/// a CPU.
pub fn gpu_by_default(ctx: &GpuContext) -> bool {
    ctx.adapter_info.device_type != wgpu::DeviceType::Cpu
}

/// Traces photon sets for a run: on the GPU tracer when it was chosen and
/// works, else on the CPU.
pub struct PhotonTracer {
    gpu: Option<(GpuContext, GpuTracer)>,
    /// Where a fallback to the CPU is said.
    log: Log,
}

impl PhotonTracer {
    pub fn cpu(log: Log) -> Self {
        PhotonTracer { gpu: None, log }
    }

    /// The tracer `choice` asks for on `ctx` (an adapter already opened for
    /// rendering, if any; `--trace gpu` opens one otherwise).
    pub fn choose(choice: TraceDevice, ctx: Option<&GpuContext>, scene: &Scene, log: Log) -> Self {
        let opened;
        let ctx = match (choice, ctx) {
            (TraceDevice::Cpu, _) => return Self::cpu(log),
            (TraceDevice::Auto, None) => return Self::cpu(log),
            (TraceDevice::Auto, Some(ctx)) if !gpu_by_default(ctx) => return Self::cpu(log),
            (_, Some(ctx)) => ctx,
            (TraceDevice::Gpu, None) => match GpuContext::new() {
                Ok(ctx) => {
                    opened = ctx;
                    &opened
                }
                Err(e) => {
                    log.note(&format!("trace: {e}: tracing photons on the CPU instead"));
                    return Self::cpu(log);
                }
            },
        };
        match GpuTracer::new(ctx, scene) {
            Ok(tracer) => PhotonTracer { gpu: Some((ctx.clone(), tracer)), log },
            Err(e) => {
                log.note(&format!("trace: {e}: tracing photons on the CPU instead"));
                Self::cpu(log)
            }
        }
    }

    /// Traces `scene` from now on: a moved or edited pose of the scene it
    /// was chosen for (the viewer's). A GPU failure sends later sets to the CPU.
    pub fn set_scene(&mut self, scene: &Scene) {
        if let Some((ctx, tracer)) = &mut self.gpu {
            if let Err(e) = tracer.set_scene(ctx, scene) {
                self.log.note(&format!("trace: gpu: {e}: tracing photons on the CPU instead"));
                self.gpu = None;
            }
        }
    }

    /// "gpu" or "cpu": where the next set will be traced.
    pub fn device(&self) -> &'static str {
        if self.gpu.is_some() { "gpu" } else { "cpu" }
    }

    /// Traces a set; a GPU failure (loop budget, memory, a lost device)
    /// sends this set and every later one to the CPU, saying why once.
    pub fn trace(&mut self, scene: &Scene, settings: &TraceSettings, progress: &dyn Progress) -> TracedPhotons {
        if let Some((ctx, tracer)) = &mut self.gpu {
            match tracer.trace(ctx, settings) {
                Ok((traced, _)) => return traced,
                Err(e) => {
                    self.log.note(&format!("trace: gpu: {e}: tracing photons on the CPU instead"));
                    self.gpu = None;
                }
            }
        }
        trace_photons(scene, settings, progress)
    }
}

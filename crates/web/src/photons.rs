//! The page's photon tracer: the GPU tracer in a task of its own. A frame
//! asks for a set (a pose of the scene, a count, a seed); the task poses
//! the scene, traces it with the compute shader, awaiting each batch's
//! readbacks so that frames go on meanwhile, and leaves the set for the
//! next frame to take. One set is traced at a time; a request made while
//! one is in flight waits for it.
//!
//! Where the GPU tracer cannot run (the adapter refuses its shader, or a
//! set fails), sets are traced by the CPU tracer on the page's one thread,
//! at most `CPU_PHOTONS` paths so that a frame stalls only briefly; the
//! panel says so.

use crate::options::TraceChoice;
use hikari_core::photon::{TraceSettings, trace_photons};
use hikari_core::progress::Silent;
use hikari_core::scene::{Pose, Scene};
use hikari_gpu::GpuContext;
use hikari_gpu::trace::GpuTracer;
pub use hikari_viewer::photon_set::{Job, PhotonSet};
use std::cell::RefCell;
use std::rc::Rc;
use std::sync::Arc;
use web_time::Instant;

/// Most photon paths a set traced on the page's thread may have.
pub const CPU_PHOTONS: u64 = 20_000;

/// What the tracing task hands back: the set (or why there is none) and
/// the tracer, with the pose its scene is in.
type Finished = (Result<PhotonSet, String>, Option<(GpuTracer, Pose, Arc<Scene>)>);

pub struct Tracing {
    ctx: GpuContext,
    /// The scene as loaded (poses are made from it).
    base: Arc<Scene>,
    /// The GPU tracer and the pose its scene is in; `None` while a set is
    /// in flight, or for good once it failed (the CPU traces then).
    tracer: Option<(GpuTracer, Pose, Arc<Scene>)>,
    pub gpu_failed: Option<String>,
    in_flight: bool,
    finished: Rc<RefCell<Option<Finished>>>,
    next_id: u64,
    /// Sets received (for the panel).
    pub received: u64,
}

impl Tracing {
    /// A tracer for poses of `base`: on the GPU where `choice` and the
    /// adapter allow it.
    pub fn new(ctx: GpuContext, base: Arc<Scene>, choice: TraceChoice) -> Self {
        let software = ctx.adapter_info.device_type == wgpu::DeviceType::Cpu;
        let on_cpu = match choice {
            TraceChoice::Cpu => Some("trace=cpu in the page address".to_string()),
            TraceChoice::Auto if software => {
                Some("a software adapter, where the CPU traces faster than the emulated GPU".to_string())
            }
            _ => None,
        };
        let (tracer, gpu_failed) = match on_cpu {
            Some(why) => (None, Some(why)),
            None => match GpuTracer::new(&ctx, &base) {
                Ok(tracer) => (Some((tracer, base.rest_pose(), base.clone())), None),
                Err(e) => (None, Some(format!("the GPU tracer cannot run here ({e})"))),
            },
        };
        Tracing { ctx, base, tracer, gpu_failed, in_flight: false, finished: Rc::default(), next_id: 0, received: 0 }
    }

    /// "GPU" or "CPU": where sets are traced now.
    pub fn device(&self) -> &'static str {
        if self.gpu_failed.is_none() { "GPU" } else { "CPU" }
    }

    pub fn busy(&self) -> bool {
        self.in_flight
    }

    /// The number the next request will get.
    pub fn next_id(&self) -> u64 {
        self.next_id
    }

    /// Starts tracing `job` (nothing is in flight: see `busy`); the set
    /// comes from `take` on a later frame. On the CPU it is traced now.
    pub fn request(&mut self, mut job: Job) {
        debug_assert!(!self.in_flight);
        let id = self.next_id;
        self.next_id += 1;
        let started = Instant::now();
        let Some((mut tracer, traced_pose, traced_scene)) = self.tracer.take().filter(|_| self.gpu_failed.is_none())
        else {
            job.photons = job.photons.min(CPU_PHOTONS);
            let scene = Arc::new(self.base.posed_for_frame(&job.pose));
            let pose_seconds = started.elapsed().as_secs_f64();
            let settings = TraceSettings { photons: job.photons, seed: job.seed, ..Default::default() };
            let traced = trace_photons(&scene, &settings, &Silent);
            let set = PhotonSet {
                id,
                pose: job.pose,
                scene,
                traced,
                seconds: started.elapsed().as_secs_f64(),
                pose_seconds,
                photons: job.photons,
            };
            *self.finished.borrow_mut() = Some((Ok(set), None));
            self.in_flight = true;
            return;
        };
        self.in_flight = true;
        let (ctx, base, finished) = (self.ctx.clone(), self.base.clone(), self.finished.clone());
        wasm_bindgen_futures::spawn_local(async move {
            let moved = traced_pose != job.pose;
            let scene = if moved { Arc::new(base.posed_for_frame(&job.pose)) } else { traced_scene };
            let pose_seconds = if moved { started.elapsed().as_secs_f64() } else { 0.0 };
            let settings = TraceSettings { photons: job.photons, seed: job.seed, ..Default::default() };
            let outcome = async {
                if moved {
                    tracer.set_scene(&ctx, &scene)?;
                }
                tracer.trace_async(&ctx, &settings).await
            }
            .await;
            let answer = match outcome {
                Ok((traced, _)) => {
                    let seconds = started.elapsed().as_secs_f64();
                    let set = PhotonSet {
                        id,
                        pose: job.pose.clone(),
                        scene: scene.clone(),
                        traced,
                        seconds,
                        pose_seconds,
                        photons: job.photons,
                    };
                    (Ok(set), Some((tracer, job.pose, scene)))
                }
                Err(e) => (Err(e.to_string()), None),
            };
            *finished.borrow_mut() = Some(answer);
        });
    }

    /// The set traced since the last call, if one is done. A GPU failure
    /// sends this request's set and every later one to the CPU.
    pub fn take(&mut self) -> Option<PhotonSet> {
        let (result, tracer) = self.finished.borrow_mut().take()?;
        self.in_flight = false;
        self.received += 1;
        if tracer.is_some() {
            self.tracer = tracer;
        }
        match result {
            Ok(set) => Some(set),
            Err(e) => {
                self.gpu_failed = Some(format!("the GPU tracer failed ({e})"));
                self.next_id -= 1;
                None
            }
        }
    }
}

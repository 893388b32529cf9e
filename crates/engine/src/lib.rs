//! hikari's one rendering API. Given a loaded scene and [`RenderSettings`],
//! a [`Session`] chooses the renderer once (the GPU with its fallback to
//! photon-cpu and the one-line reason), renders progressive passes with
//! their noise estimate and stops at a pass count, a time, a target error
//! or an interrupt, handing back the image. `hikari render` and the Python
//! module call it; they only parse their arguments and write the output.

pub mod log;
pub mod passes;
pub mod renderers;
pub mod session;
pub mod settings;
pub mod tracer;

pub use log::Log;
pub use session::{Outcome, PassReport, Session, StopReason};
pub use settings::{EstimatorChoice, Plan, RenderSettings, RendererKind, TraceDevice, VcmStrategies};

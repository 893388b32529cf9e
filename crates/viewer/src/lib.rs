//! What `hikari view` (a native window) and `hikari-web` (a browser tab)
//! share: the orbiting camera, the egui panel and the settings it edits,
//! the frame-rate statistics and the animation clock. Each front end keeps
//! only its own event loop, photon tracing and frame pacing.

pub mod clock;
pub mod frame_stats;
pub mod orbit;
pub mod panel;
pub mod photon_set;
pub mod settings;
pub mod surface;

//! What `hikari view` (a native window) and `hikari-web` (a browser tab)
//! share: the frame loop (`frames`: photon requests, the renderer of the
//! set on screen, the running mean, presenting), the orbiting camera, the
//! egui panel and the settings it edits, the frame-rate statistics and the
//! animation clock. Each front end keeps only its own event loop, photon
//! tracing, frame pacing and error checks.

pub mod clock;
pub mod frame_stats;
pub mod frames;
pub mod orbit;
pub mod panel;
pub mod photon_set;
pub mod settings;
pub mod surface;

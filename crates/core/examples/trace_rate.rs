//! Photon tracing rate on a built-in scene: `cargo run --release -p hikari-core
//! --example trace_rate -- [scene] [photons]`. Prints M paths/s.

use hikari_core::photon::{TraceSettings, trace_photons};
use hikari_core::progress::Silent;
use hikari_core::scene::Scene;
use std::time::Instant;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let scene = Scene::load(args.get(1).map_or("cornell-box", String::as_str)).expect("scene");
    let photons: u64 = args.get(2).and_then(|s| s.parse().ok()).unwrap_or(5_000_000);
    let settings = TraceSettings { photons, seed: 1, ..Default::default() };
    let start = Instant::now();
    let traced = trace_photons(&scene, &settings, &Silent);
    let secs = start.elapsed().as_secs_f64();
    println!("{} paths, {} stored: {:.2} M paths/s", photons, traced.global.len(), photons as f64 / secs / 1e6);
}

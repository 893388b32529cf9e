//! Loading a large glTF file: `cargo run --release -p hikari-core --example
//! gltf_load -- [triangles] [photons] [KEEP.glb]`. Writes a wavy grid of about that many
//! triangles (default 1,000,000) under a point light as a `.glb`, then
//! times `Scene::load` (parse, accessors, transforms, BVH build), reports
//! the resident memory it added per triangle, and the photon-tracing rate
//! on it beside cornell-box's. With KEEP.glb the grid is written there and
//! kept (to try it in `hikari render` and `hikari view`).

use hikari_core::photon::{TraceSettings, trace_photons};
use hikari_core::progress::Silent;
use hikari_core::scene::Scene;
use std::time::Instant;

/// Resident set size of this process, bytes (Linux).
fn rss() -> u64 {
    let status = std::fs::read_to_string("/proc/self/status").unwrap_or_default();
    status
        .lines()
        .find_map(|l| l.strip_prefix("VmRSS:"))
        .and_then(|v| v.trim().trim_end_matches("kB").trim().parse::<u64>().ok())
        .map_or(0, |kb| kb * 1024)
}

fn rate(scene: &Scene, photons: u64) -> f64 {
    let start = Instant::now();
    trace_photons(scene, &TraceSettings { photons, seed: 1, ..Default::default() }, &Silent);
    photons as f64 / start.elapsed().as_secs_f64() / 1e6
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let triangles: u64 = args.get(1).and_then(|s| s.parse().ok()).unwrap_or(1_000_000);
    let photons: u64 = args.get(2).and_then(|s| s.parse().ok()).unwrap_or(1_000_000);
    let glb = hikari_core::test_scenes::wavy_grid_glb(triangles);
    let keep = args.get(3).map(std::path::PathBuf::from);
    let path =
        keep.clone().unwrap_or_else(|| std::env::temp_dir().join(format!("hikari-grid-{}.glb", std::process::id())));
    std::fs::write(&path, &glb).expect("write the grid");
    drop(glb);

    let before = rss();
    let start = Instant::now();
    let scene = Scene::load(path.to_str().unwrap()).expect("the grid loads");
    let secs = start.elapsed().as_secs_f64();
    let added = rss().saturating_sub(before);
    let count = scene.accel.triangle_count();
    println!(
        "{count} triangles ({:.1} MB .glb): loaded with BVH in {secs:.2} s, {:.0} bytes resident per triangle",
        std::fs::metadata(&path).map_or(0.0, |m| m.len() as f64 / 1e6),
        added as f64 / count as f64
    );
    if keep.is_none() {
        let _ = std::fs::remove_file(&path);
    }
    let cornell = Scene::load("cornell-box").unwrap();
    let (big, small) = (rate(&scene, photons), rate(&cornell, photons));
    println!(
        "photon tracing: {big:.2} M paths/s on the grid, {small:.2} M paths/s on cornell-box ({:.0}%)",
        100.0 * big / small
    );
}

//! Helpers shared by the CLI's test files.
#![allow(dead_code)]

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

pub fn hikari(args: &[&str], dir: &Path) -> Output {
    Command::new(env!("CARGO_BIN_EXE_hikari")).args(args).current_dir(dir).output().expect("the binary runs")
}

/// One virtual X server at a time: `xvfb-run -a` picks a free display
/// number, and two started at once can pick the same one.
pub fn one_display() -> std::sync::MutexGuard<'static, ()> {
    static DISPLAY: std::sync::Mutex<()> = std::sync::Mutex::new(());
    DISPLAY.lock().unwrap_or_else(|e| e.into_inner())
}

pub fn scratch_dir(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("hikari-cli-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

pub fn stderr(out: &Output) -> String {
    String::from_utf8_lossy(&out.stderr).into_owned()
}

/// A failure: non-zero exit, the expected words on stderr, no panic, no image.
pub fn assert_fails_with(out: &Output, dir: &Path, words: &[&str]) {
    let err = stderr(out);
    assert!(!out.status.success(), "succeeded: {err}");
    assert!(!err.contains("panicked"), "panicked: {err}");
    for w in words {
        assert!(err.contains(w), "stderr lacks {w:?}: {err}");
    }
    let images: Vec<_> = std::fs::read_dir(dir)
        .unwrap()
        .filter_map(|e| e.ok())
        .filter(|e| e.path().extension().is_some_and(|x| x == "png"))
        .collect();
    assert!(images.is_empty(), "an image was left behind");
}

/// A tiny scene: a sphere under a point light.
pub const SCENE: &str = r#"
[camera]
position = [0.0, 0.0, 3.0]
look_at = [0.0, 0.0, 0.0]
resolution = [8, 8]

[[material]]
name = "white"
type = "diffuse"
albedo = [0.5, 0.5, 0.5]

[[object]]
shape = "sphere"
center = [0.0, 0.0, 0.0]
radius = 1.0
material = "white"

[[light]]
type = "point"
position = [0.0, 2.0, 2.0]
intensity = [5.0, 5.0, 5.0]
"#;

/// A glTF file of `hikari_gpu::test_support::sun_over_a_box` without its
/// sun: the loader lights it with a white sky.
pub fn unlit_glb() -> Vec<u8> {
    let mut scene = hikari_gpu::test_support::sun_over_a_box(32);
    scene.lights.clear();
    hikari_core::scene::gltf::export::scene_to_glb(&scene).unwrap()
}

/// Relative RMS difference of two images: √(Σ|a−b|²/Σ|b|²).
pub fn relative_rms(a: &[[f32; 3]], b: &[[f32; 3]]) -> f64 {
    let (mut num, mut den) = (0.0f64, 0.0f64);
    for (p, q) in a.iter().zip(b) {
        for c in 0..3 {
            num += ((p[c] - q[c]) as f64).powi(2);
            den += (q[c] as f64).powi(2);
        }
    }
    (num / den).sqrt()
}

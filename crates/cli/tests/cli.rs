//! The `hikari` binary as a user meets it: good runs, bad input, exit codes.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn hikari(args: &[&str], dir: &Path) -> Output {
    Command::new(env!("CARGO_BIN_EXE_hikari")).args(args).current_dir(dir).output().expect("the binary runs")
}

/// One virtual X server at a time: `xvfb-run -a` picks a free display
/// number, and two started at once can pick the same one.
fn one_display() -> std::sync::MutexGuard<'static, ()> {
    static DISPLAY: std::sync::Mutex<()> = std::sync::Mutex::new(());
    DISPLAY.lock().unwrap_or_else(|e| e.into_inner())
}

fn scratch_dir(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("hikari-cli-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn stderr(out: &Output) -> String {
    String::from_utf8_lossy(&out.stderr).into_owned()
}

/// A failure: non-zero exit, the expected words on stderr, no panic, no image.
fn assert_fails_with(out: &Output, dir: &Path, words: &[&str]) {
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

const SCENE: &str = r#"
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

#[test]
fn renders_a_builtin_scene_and_reports() {
    let dir = scratch_dir("ok");
    let out = hikari(
        &["render", "cornell-caustic", "--resolution", "24x16", "--photons", "3000", "-o", "out.png", "-q"],
        &dir,
    );
    let err = stderr(&out);
    assert!(out.status.success(), "{err}");
    assert!(err.contains("3000 emitted") && err.contains("paths/s") && err.contains("wrote out.png"), "{err}");
    let img = image::open(dir.join("out.png")).unwrap();
    assert_eq!((img.width(), img.height()), (24, 16));
    let out =
        hikari(&["render", "--renderer", "path", "--spp", "2", "--resolution", "8x8", "-o", "truth.exr", "-q"], &dir);
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(dir.join("truth.exr").is_file());
}

#[test]
fn lists_builtin_scenes() {
    let out = hikari(&["scenes"], &std::env::temp_dir());
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success() && text.contains("cornell-box") && text.contains("cornell-caustic"), "{text}");
}

#[test]
fn bad_scene_files_are_reported_with_file_and_line() {
    let dir = scratch_dir("bad");
    let cases: &[(&str, String, &[&str])] = &[
        ("syntax.toml", SCENE.replace("radius = 1.0", "radius = = 1.0"), &["syntax.toml:15:10", "extra `=`"]),
        ("field.toml", SCENE.replace("radius = 1.0", "radius = 1.0\ncolour = 3"), &["field.toml:", "colour"]),
        (
            "material.toml",
            SCENE.replace("material = \"white\"", "material = \"snow\""),
            &["material.toml:16:", "[[object]] #1", "unknown material \"snow\""],
        ),
        (
            "mesh.toml",
            SCENE.replace("shape = \"sphere\"\ncenter = [0.0, 0.0, 0.0]\nradius = 1.0", "mesh = \"missing.obj\""),
            &["mesh.toml:", "missing.obj", "not found"],
        ),
        (
            "albedo.toml",
            SCENE.replace("albedo = [0.5, 0.5, 0.5]", "albedo = [0.5, -0.5, 0.5]"),
            &["albedo.toml:", "[[material]] #1", "negative"],
        ),
        (
            "bright.toml",
            SCENE.replace("albedo = [0.5, 0.5, 0.5]", "albedo = [0.5, 1.5, 0.5]"),
            &["bright.toml:", "above 1"],
        ),
        ("nan.toml", SCENE.replace("radius = 1.0", "radius = nan"), &["nan.toml:", "radius"]),
        (
            "camera.toml",
            SCENE.replace("look_at = [0.0, 0.0, 0.0]", "look_at = [0.0, 0.0, 3.0]"),
            &["camera.toml:", "[camera]", "coincide"],
        ),
    ];
    for (name, text, words) in cases {
        std::fs::write(dir.join(name), text).unwrap();
        let out = hikari(&["render", name, "-o", "out.png", "-q"], &dir);
        assert_fails_with(&out, &dir, words);
    }
}

/// A scene with a medium renders with the default GPU renderer (or the
/// CPU fallback when the machine has no adapter), photon-cpu and the path
/// tracer, with glass in the fog too (on the GPU where it is a hardware one).
#[test]
fn media_are_rendered() {
    let dir = scratch_dir("fog");
    std::fs::write(dir.join("fog.toml"), format!("{SCENE}\n[[medium]]\nsigma_s = [0.1, 0.1, 0.1]\n")).unwrap();
    let out = hikari(&["render", "fog.toml", "--photons", "2000", "-o", "fog.png", "-q"], &dir);
    let err = stderr(&out);
    assert!(out.status.success(), "{err}");
    assert!(err.contains("gpu:"), "{err}");
    assert!(err.contains("in the volume map"), "{err}");
    assert!(dir.join("fog.png").is_file());
    let _ = std::fs::remove_file(dir.join("fog.png"));
    for renderer in ["photon-cpu", "path"] {
        let out = hikari(&["render", "fog.toml", "--renderer", renderer, "--spp", "2", "-o", "p.png", "-q"], &dir);
        assert!(out.status.success(), "{}", stderr(&out));
        assert!(dir.join("p.png").is_file());
        let _ = std::fs::remove_file(dir.join("p.png"));
    }
    let glass = SCENE.replace("type = \"diffuse\"\nalbedo = [0.5, 0.5, 0.5]", "type = \"glass\"");
    std::fs::write(dir.join("glass.toml"), format!("{glass}\n[[medium]]\nsigma_s = [0.1, 0.1, 0.1]\n")).unwrap();
    let out = hikari(&["render", "glass.toml", "--photons", "2000", "-o", "g.png", "-q"], &dir);
    let err = stderr(&out);
    assert!(out.status.success(), "{err}");
    // Drawn on the GPU (lavapipe included: its gathers are split to fit
    // its loop cap) or left to photon-cpu with the reason.
    assert!(err.contains("gpu:") || err.contains("rendering with photon-cpu instead"), "{err}");
    assert!(dir.join("g.png").is_file());
    let _ = std::fs::remove_file(dir.join("g.png"));
}

#[test]
fn bad_options_are_rejected() {
    let dir = scratch_dir("opts");
    std::fs::write(dir.join("ok.toml"), SCENE).unwrap();
    assert_fails_with(&hikari(&["render", "ok.toml", "--photons", "0"], &dir), &dir, &["--photons"]);
    assert_fails_with(&hikari(&["render", "ok.toml", "--radius", "-1"], &dir), &dir, &["--radius"]);
    assert_fails_with(&hikari(&["render", "ok.toml", "-o", "out.jpg"], &dir), &dir, &["out.jpg", "unsupported"]);
    assert_fails_with(&hikari(&["render", "ok.toml", "--resolution", "0x5"], &dir), &dir, &["--resolution"]);
    assert_fails_with(
        &hikari(&["render", "no-such-scene", "-o", "out.png"], &dir),
        &dir,
        &["no-such-scene", "cornell-box"],
    );
    assert_fails_with(&hikari(&["render", "ok.toml", "-o", "no/such/dir/out.png", "-q"], &dir), &dir, &["out.png"]);
}

/// Out-of-range flags and scene files are input errors: exit code 2, the
/// flag or FILE:LINE:COLUMN named, no image.
#[test]
fn out_of_range_input_exits_with_code_2() {
    let dir = scratch_dir("range");
    std::fs::write(dir.join("ok.toml"), SCENE).unwrap();
    let cases: &[(&[&str], &[&str])] = &[
        (&["--radius", "1e-20"], &["--radius 0.00000000000000000001", "diagonal"]),
        (&["--radius", "1e6"], &["--radius 1000000", "diagonal"]),
        (&["--caustic-radius", "1e-30"], &["--caustic-radius"]),
        (&["--volume-radius", "1e30"], &["--volume-radius"]),
        (&["--photons", "1000000000"], &["--photons"]),
        (&["--exposure", "1e9"], &["--exposure"]),
        (&["--area-light-samples", "100000"], &["--area-light-samples"]),
        (&["--shadow-map-size", "100000"], &["--shadow-map-size"]),
        (&["--resolution", "100000x100000"], &["--resolution"]),
    ];
    for (flags, words) in cases {
        let mut args = vec!["render", "ok.toml", "-o", "out.png", "-q"];
        args.extend_from_slice(flags);
        let out = hikari(&args, &dir);
        assert_fails_with(&out, &dir, words);
        assert_eq!(out.status.code(), Some(2), "{flags:?}: {}", stderr(&out));
    }
    let bad = SCENE.replace("albedo = [0.5, 0.5, 0.5]", "albedo = [0.5, -0.5, 0.5]");
    std::fs::write(dir.join("bad.toml"), bad).unwrap();
    let out = hikari(&["render", "bad.toml", "-o", "out.png", "-q"], &dir);
    assert_fails_with(&out, &dir, &["bad.toml:"]);
    assert_eq!(out.status.code(), Some(2));
}

/// Shadow maps that would take gigabytes (a sphere light: 256 samples × 6
/// cube faces of 8192² texels) are refused before any photon is traced,
/// with the reason, and the CPU renderer draws the image.
#[test]
fn settings_too_large_for_the_gpu_fall_back_with_the_reason() {
    let dir = scratch_dir("large");
    let out = hikari(
        &[
            "render",
            "cornell-caustic",
            "--resolution",
            "8x8",
            "--photons",
            "1000",
            "--shadow-map-size",
            "8192",
            "--area-light-samples",
            "256",
            "-o",
            "out.png",
            "-q",
        ],
        &dir,
    );
    let err = stderr(&out);
    assert!(out.status.success(), "{err}");
    assert!(!err.contains("panicked"), "{err}");
    assert!(err.contains("shadow") && err.contains("rendering with photon-cpu instead"), "{err}");
    assert!(
        err.find("rendering with photon-cpu").unwrap() < err.find("emitted").unwrap(),
        "checked after tracing: {err}"
    );
    assert!(dir.join("out.png").is_file());
}

/// On Mesa's OpenGL (what wgpu finds on a fresh Debian without the Vulkan
/// driver) the renderer names what the adapter lacks and the image is drawn
/// by photon-cpu: no panic.
#[test]
fn the_gl_backend_renders_or_falls_back_with_the_reason() {
    let dir = scratch_dir("gl");
    let out = Command::new(env!("CARGO_BIN_EXE_hikari"))
        .args(["render", "--resolution", "16x16", "--photons", "2000", "-o", "out.png", "-q"])
        .env("WGPU_BACKEND", "gl")
        .current_dir(&dir)
        .output()
        .unwrap();
    let err = stderr(&out);
    assert!(out.status.success(), "{err}");
    assert!(!err.contains("panicked"), "{err}");
    assert!(
        err.contains("gpu:") || (err.contains("(Gl)") && err.contains("rendering with photon-cpu instead")),
        "{err}"
    );
    assert!(dir.join("out.png").is_file());
}

/// `hikari view` in a real window under a virtual X server (Debian's Xvfb,
/// which scripts/test.sh installs): a few frames unattended, the last one
/// written, one summary line.
#[test]
fn view_runs_unattended_under_xvfb() {
    let _display = one_display();
    let dir = scratch_dir("view");
    let out = Command::new("xvfb-run")
        .args(["-a", "-s", "-screen 0 640x480x24", env!("CARGO_BIN_EXE_hikari")])
        .args(["view", "cornell-caustic", "--frames", "4", "--size", "64x48", "--photons", "3000", "-q"])
        .args(["--screenshot", "shot.png"])
        .current_dir(&dir)
        .output()
        .expect("xvfb-run runs (scripts/test.sh installs Debian's xvfb)");
    let (err, text) = (stderr(&out), String::from_utf8_lossy(&out.stdout).into_owned());
    assert!(out.status.success(), "{err}");
    assert!(text.contains("view: 4 frames") && text.contains("fps, 1% low"), "{text}");
    let shot = image::open(dir.join("shot.png")).unwrap();
    assert_eq!((shot.width(), shot.height()), (64, 48));
    // The frame is lit (the ball's scene, not a cleared target).
    let lit = shot.to_rgb8().pixels().filter(|p| p.0.iter().any(|&c| c > 40)).count();
    assert!(lit > 64 * 48 / 2, "only {lit} lit pixels");
}

/// Without a display the viewer says so in one line and exits non-zero.
#[test]
fn view_without_a_display_says_so() {
    let dir = scratch_dir("nodisplay");
    let out = Command::new(env!("CARGO_BIN_EXE_hikari"))
        .args(["view", "--frames", "1", "-q"])
        .env_remove("DISPLAY")
        .env_remove("WAYLAND_DISPLAY")
        .env_remove("WAYLAND_SOCKET")
        .current_dir(&dir)
        .output()
        .unwrap();
    let err = stderr(&out);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(!err.contains("panicked"), "{err}");
    assert!(err.contains("hikari render"), "{err}");
    assert_eq!(err.trim().lines().count(), 1, "{err}");
}

/// Still means converging: with the camera still, each frame draws a fresh
/// photon set and the window shows their mean, so two runs from different
/// seeds come closer with more frames (noise ∝ 1/√frames: 8 frames should
/// differ about 0.35 times as much as 1 frame).
#[test]
fn view_converges_while_the_camera_stands_still() {
    let _display = one_display();
    let dir = scratch_dir("converge");
    let run = |frames: &str, seed: &str, file: &str| {
        let out = Command::new("xvfb-run")
            .args(["-a", "-s", "-screen 0 640x480x24", env!("CARGO_BIN_EXE_hikari")])
            .args(["view", "cornell-box", "--size", "48x36", "--photons", "3000", "-q", "--seed", seed])
            .args(["--frames", frames, "--screenshot", file])
            .current_dir(&dir)
            .output()
            .expect("xvfb-run runs (scripts/test.sh installs Debian's xvfb)");
        let text = String::from_utf8_lossy(&out.stdout).into_owned();
        assert!(out.status.success(), "{}", stderr(&out));
        assert!(text.contains(&format!("{frames} photon sets drawn")), "{text}");
        image::open(dir.join(file)).unwrap().to_rgb32f()
    };
    let rms = |a: &image::Rgb32FImage, b: &image::Rgb32FImage| {
        let sum: f64 = a
            .pixels()
            .zip(b.pixels())
            .flat_map(|(p, q)| (0..3).map(move |c| (p.0[c] - q.0[c]) as f64))
            .map(|d| d * d)
            .sum();
        (sum / (a.len() as f64)).sqrt()
    };
    let one = rms(&run("1", "0", "a1.exr"), &run("1", "100", "b1.exr"));
    let eight = rms(&run("8", "0", "a8.exr"), &run("8", "100", "b8.exr"));
    eprintln!("RMS difference between seeds: 1 frame {one:.5}, 8 frames {eight:.5} (ratio {:.3})", eight / one);
    assert!(one > 0.0);
    assert!(eight < 0.55 * one, "8 frames {eight} vs 1 frame {one}");
}

/// The controls, driven like a user under Xvfb with xdotool (installed by
/// scripts/test.sh): hide the panel (F1), fly forward (W), orbit (left
/// drag), print the camera (C), quit (Escape). The printed camera has
/// flown and turned, and the summary counts the moves.
#[test]
fn view_follows_keys_and_mouse() {
    let _display = one_display();
    let dir = scratch_dir("drive");
    let script = r#"
"$1" view cornell-box --size 64x48 --photons 2000 --frames 100000 -q > out.txt 2> err.txt &
pid=$!
win=$(xdotool search --sync --name "hikari view")
xdotool windowfocus --sync "$win"
sleep 0.5
xdotool key F1
sleep 0.2
xdotool keydown w; sleep 0.8; xdotool keyup w
sleep 0.3
xdotool mousemove --window "$win" 30 20 mousedown 1 mousemove --window "$win" 50 25 mouseup 1
sleep 0.3
xdotool key c
sleep 0.5
xdotool key Escape
wait $pid
"#;
    let out = Command::new("timeout")
        .args(["120", "xvfb-run", "-a", "-s", "-screen 0 640x480x24", "sh", "-c", script, "sh"])
        .arg(env!("CARGO_BIN_EXE_hikari"))
        .current_dir(&dir)
        .output()
        .expect("xvfb-run and xdotool run (scripts/test.sh installs them)");
    let text = std::fs::read_to_string(dir.join("out.txt")).unwrap_or_default();
    let err = std::fs::read_to_string(dir.join("err.txt")).unwrap_or_default();
    assert!(out.status.success(), "{err}{}", stderr(&out));
    let printed = text.split("[camera]").nth(1).expect("C printed the camera");
    let z: f32 = printed
        .lines()
        .find_map(|l| l.strip_prefix("position = ["))
        .and_then(|v| v.trim_end_matches(']').split(',').nth(2))
        .and_then(|z| z.trim().parse().ok())
        .expect("a position line");
    // cornell-box's eye is at z = 3.9, looking toward -z: flying forward lowers z.
    assert!(z < 3.85, "the eye did not fly forward: z = {z}\n{text}");
    let x: f32 = printed
        .lines()
        .find_map(|l| l.strip_prefix("position = ["))
        .and_then(|v| v.split(',').next())
        .and_then(|x| x.trim().parse().ok())
        .expect("a position line");
    // The drag to the right orbits the eye to -x.
    assert!(x < -0.05, "the eye did not orbit: x = {x}\n{text}");
    let moves: usize =
        text.split("over ").nth(1).and_then(|t| t.split(' ').next()).and_then(|n| n.parse().ok()).unwrap_or(0);
    assert!(moves >= 2, "{text}");
}

/// Hot reload: saving the scene file reloads it; a broken save prints the
/// error with its place and keeps the last good scene on screen.
#[test]
fn view_reloads_the_scene_file() {
    let _display = one_display();
    let dir = scratch_dir("reload");
    std::fs::write(dir.join("scene.toml"), SCENE).unwrap();
    std::fs::write(dir.join("broken.toml"), SCENE.replace("radius = 1.0", "radius = = 1.0")).unwrap();
    std::fs::write(
        dir.join("brighter.toml"),
        SCENE.replace("intensity = [5.0, 5.0, 5.0]", "intensity = [9.0, 9.0, 9.0]"),
    )
    .unwrap();
    let script = r#"
"$1" view scene.toml --size 48x36 --photons 2000 --frames 100000 -q > out.txt 2> err.txt &
pid=$!
win=$(xdotool search --sync --name "hikari view")
xdotool windowfocus --sync "$win"
sleep 0.6
cp broken.toml scene.toml
sleep 1.0
cp brighter.toml scene.toml
sleep 1.5
xdotool key Escape
wait $pid
"#;
    let out = Command::new("timeout")
        .args(["120", "xvfb-run", "-a", "-s", "-screen 0 640x480x24", "sh", "-c", script, "sh"])
        .arg(env!("CARGO_BIN_EXE_hikari"))
        .current_dir(&dir)
        .output()
        .expect("xvfb-run and xdotool run (scripts/test.sh installs them)");
    let err = std::fs::read_to_string(dir.join("err.txt")).unwrap_or_default();
    assert!(out.status.success(), "{err}{}", stderr(&out));
    assert!(!err.contains("panicked"), "{err}");
    let broken = err.find("scene.toml:15:10").expect("the broken save's error, located");
    assert!(err[broken..].contains("the last good scene stays"), "{err}");
    let reloaded = err.find("view: reloaded scene.toml").expect("the fixed save reloaded");
    assert!(reloaded > broken, "{err}");
}

//! `hikari view` as a user meets it: in a real window under a virtual X
//! server (Debian's Xvfb, which scripts/test.sh installs), driven by
//! xdotool or running unattended (`--frames`).

mod common;

use common::*;
use std::process::Command;

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
/// flown and turned, and the summary counts the moves. W is held for 2 s:
/// a frame moves the eye by at most a quarter second's flight (so a stall
/// never jumps it), and under a loaded CI machine frames take up to a
/// second each.
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
xdotool keydown w; sleep 2; xdotool keyup w
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
    let moves: usize = text
        .split("camera move to screen")
        .nth(1)
        .and_then(|t| t.split("over ").nth(1))
        .and_then(|t| t.split_whitespace().next())
        .and_then(|n| n.parse().ok())
        .unwrap_or(0);
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
# Wait for the viewer to see each save (it looks between frames, which a
# loaded machine makes slow), at most 30 s.
for i in $(seq 150); do grep -q "last good scene" err.txt && break; sleep 0.2; done
cp brighter.toml scene.toml
for i in $(seq 150); do grep -q "reloaded" err.txt && break; sleep 0.2; done
sleep 0.3
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

/// glTF files lit as the GPU renderer could not light them before: one
/// without lights (the loader's white sky, seen past the floor's edge) and
/// the Cornell box lit by an emissive surface open in the window and draw
/// their light.
#[test]
fn view_opens_gltf_files_under_a_sky_or_an_emissive_surface() {
    let _display = one_display();
    let dir = scratch_dir("view-gltf");
    std::fs::write(dir.join("unlit.glb"), unlit_glb()).unwrap();
    let mesh_light =
        hikari_core::scene::gltf::export::scene_to_glb(&hikari_core::test_scenes::cornell_quad_light(32)).unwrap();
    std::fs::write(dir.join("mesh-light.glb"), mesh_light).unwrap();
    let common = ["--size", "32x32", "--photons", "3000", "--frames", "2"];
    let text = view(&dir, &[&["unlit.glb"], &common[..], &["--screenshot", "sky.exr"]].concat());
    assert!(text.contains("view: 2 frames"), "{text}");
    let sky = exr(&dir, "sky.exr");
    // The top row looks over the floor's far edge: the white sky, radiance 1.
    assert!(sky[..32].iter().all(|p| p.iter().all(|&c| (c - 1.0).abs() < 1e-3)), "{:?}", &sky[..4]);
    assert!(image_mean(&sky[32 * 16..]) > 0.1, "the floor is dark");
    view(&dir, &[&["mesh-light.glb"], &common[..], &["--screenshot", "mesh.exr"]].concat());
    let mesh = exr(&dir, "mesh.exr");
    // The light itself (radiance 12) in view, and the box lit.
    let brightest = mesh.iter().map(|p| p[0]).fold(0.0f32, f32::max);
    assert!((brightest - 12.0).abs() < 0.1, "the light shows {brightest}");
    assert!(image_mean(&mesh) > 0.1, "the box is dark: {}", image_mean(&mesh));
    // `--environment`: an image of a sky (one colour) in place of the white one.
    let sky_image = image::Rgb32FImage::from_raw(8, 4, [2.0f32, 1.0, 0.5].repeat(32)).unwrap();
    image::DynamicImage::ImageRgb32F(sky_image).save(dir.join("sky-image.exr")).unwrap();
    let args = [&["unlit.glb", "--environment", "sky-image.exr"], &common[..], &["--screenshot", "mapped.exr"]];
    view(&dir, &args.concat());
    let mapped = exr(&dir, "mapped.exr");
    assert!(mapped[..32].iter().all(|p| (p[0] - 2.0).abs() < 1e-3 && (p[2] - 0.5).abs() < 1e-3), "{:?}", &mapped[..4]);
}

/// Runs `hikari view ARGS` under Xvfb in `dir`; returns its summary line.
fn view(dir: &std::path::Path, args: &[&str]) -> String {
    let out = Command::new("xvfb-run")
        .args(["-a", "-s", "-screen 0 640x480x24", env!("CARGO_BIN_EXE_hikari"), "view", "-q"])
        .args(args)
        .current_dir(dir)
        .output()
        .expect("xvfb-run runs (scripts/test.sh installs Debian's xvfb)");
    assert!(out.status.success(), "{}", stderr(&out));
    String::from_utf8_lossy(&out.stdout).into_owned()
}

fn render(dir: &std::path::Path, args: &[&str]) {
    let out = hikari(&[&["render", "-q"], args].concat(), dir);
    assert!(out.status.success(), "{}", stderr(&out));
}

fn exr(dir: &std::path::Path, file: &str) -> Vec<[f32; 3]> {
    image::open(dir.join(file)).unwrap().to_rgb32f().pixels().map(|p| p.0).collect()
}

fn image_mean(a: &[[f32; 3]]) -> f64 {
    a.iter().flat_map(|p| p.iter()).map(|&x| x as f64).sum::<f64>() / (3 * a.len()) as f64
}

/// The window draws what `hikari render` draws from the same camera: one
/// frame equals the render of the same photon set (seed 0) to float
/// rounding, and 30 still frames (sets 0–29 at the progressive radii and
/// jitters) equal `render --passes 30`; they keep the path tracer's image
/// mean (within 4%) and lie much closer to its image than one frame does.
#[test]
fn view_matches_the_headless_render() {
    let _display = one_display();
    let dir = scratch_dir("matches");
    view(&dir, &["cornell-box", "--size", "48x36", "--photons", "3000", "--frames", "1", "--screenshot", "v1.exr"]);
    view(&dir, &["cornell-box", "--size", "48x36", "--photons", "3000", "--frames", "30", "--screenshot", "v30.exr"]);
    // The viewer's converging frames use the normal test, as passes do.
    render(
        &dir,
        &[
            "cornell-box",
            "--resolution",
            "48x36",
            "--photons",
            "3000",
            "--normal-test",
            "--passes",
            "1",
            "-o",
            "r1.exr",
        ],
    );
    render(&dir, &["cornell-box", "--resolution", "48x36", "--renderer", "path", "--spp", "1024", "-o", "path.exr"]);
    render(&dir, &["cornell-box", "--resolution", "48x36", "--photons", "3000", "--passes", "30", "-o", "r30.exr"]);
    let (v1, v30, r1, path) = (exr(&dir, "v1.exr"), exr(&dir, "v30.exr"), exr(&dir, "r1.exr"), exr(&dir, "path.exr"));
    let passes = relative_rms(&v30, &exr(&dir, "r30.exr"));
    eprintln!("30 frames vs render --passes 30: {passes:.2e}");
    assert!(passes < 1e-4, "30 still frames differ from 30 passes by {passes}");
    let same = relative_rms(&v1, &r1);
    let (one, thirty) = (relative_rms(&v1, &path), relative_rms(&v30, &path));
    let mean_ratio = image_mean(&v30) / image_mean(&path);
    eprintln!(
        "1 frame vs render: {same:.2e}; vs path: 1 frame {one:.4}, 30 frames {thirty:.4}; mean ratio {mean_ratio:.4}"
    );
    assert!(same < 1e-4, "one frame differs from the render of the same photons by {same}");
    // The early passes' large radii still brighten corners (measured: +2.7%).
    assert!((mean_ratio - 1.0).abs() < 0.04, "the 30-frame mean is off by {mean_ratio}");
    assert!(thirty < 0.5 * one, "30 frames {thirty} vs 1 frame {one}");
}

/// A moving light, re-traced: with `--step` the animation advances each
/// frame, and the last frame shows the scene at its own time (the light
/// moved, the photons re-traced): it matches `hikari render --at` of that
/// time, and not the start, where a still run matches instead.
#[test]
fn view_retraces_a_moving_light() {
    let _display = one_display();
    let dir = scratch_dir("moving");
    let common = ["cornell-orbit", "--size", "40x40", "--photons", "20000", "--frames", "6"];
    let text = view(&dir, &[&common[..], &["--step", "0.4", "--screenshot", "moving.exr"]].concat());
    view(&dir, &[&common[..], &["--screenshot", "still.exr"]].concat());
    // Six still frames are six progressive passes.
    render(
        &dir,
        &["cornell-orbit", "--resolution", "40x40", "--photons", "20000", "--passes", "6", "-o", "passes.exr"],
    );
    let passes = relative_rms(&exr(&dir, "still.exr"), &exr(&dir, "passes.exr"));
    assert!(passes < 1e-4, "the still run differs from render --passes 6 by {passes}");
    for at in ["0", "2"] {
        let file = format!("at{at}.exr");
        render(
            &dir,
            &[
                "cornell-orbit",
                "--resolution",
                "40x40",
                "--photons",
                "100000",
                "--passes",
                "1",
                "--at",
                at,
                "-o",
                &file,
            ],
        );
    }
    let (moving, still) = (exr(&dir, "moving.exr"), exr(&dir, "still.exr"));
    let (at0, at2) = (exr(&dir, "at0.exr"), exr(&dir, "at2.exr"));
    let moved = relative_rms(&at2, &at0);
    let (moving_2, moving_0) = (relative_rms(&moving, &at2), relative_rms(&moving, &at0));
    let (still_0, still_2) = (relative_rms(&still, &at0), relative_rms(&still, &at2));
    eprintln!(
        "renders at 0 and 2 s differ by {moved:.3}; moving run vs 2 s {moving_2:.3}, vs 0 s {moving_0:.3}; \
         still run vs 0 s {still_0:.3}, vs 2 s {still_2:.3}"
    );
    assert!(moved > 0.2, "the light hardly moved: {moved}");
    assert!(moving_2 < 0.25 * moving_0, "the moving run's last frame is not at 2 s");
    assert!(still_0 < 0.25 * still_2, "the still run's frame is not at 0 s");
    assert!(text.contains("scene edit to screen") && text.contains("over 5"), "{text}");
}

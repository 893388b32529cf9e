//! The `hikari` binary as a user meets it: good runs, bad input, exit codes.

mod common;

use common::*;
use std::process::Command;

#[test]
fn renders_a_builtin_scene_and_reports() {
    let dir = scratch_dir("ok");
    let out = hikari(
        &[
            "render",
            "cornell-caustic",
            "--resolution",
            "24x16",
            "--photons",
            "3000",
            "--passes",
            "1",
            "-o",
            "out.png",
            "-q",
        ],
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
    let out = hikari(&["render", "fog.toml", "--photons", "2000", "--passes", "1", "-o", "fog.png", "-q"], &dir);
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
    let out = hikari(&["render", "glass.toml", "--photons", "2000", "--passes", "1", "-o", "g.png", "-q"], &dir);
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
    let no_dir = hikari(&["render", "ok.toml", "--passes", "1", "-o", "no/such/dir/out.png", "-q"], &dir);
    assert_fails_with(&no_dir, &dir, &["out.png"]);
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
            "--passes",
            "1",
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
        .args(["render", "--resolution", "16x16", "--photons", "2000", "--passes", "1", "-o", "out.png", "-q"])
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

/// Progressive passes (docs/progressive.md): a pass count, a time limit,
/// checkpoints compared with a reference, and the errors of each flag.
#[test]
fn renders_in_passes_and_compares_with_a_reference() {
    let dir = scratch_dir("passes");
    let small = ["cornell-box", "--resolution", "32x32", "--photons", "5000", "-q"];
    let ok = |args: &[&str]| {
        let out = hikari(&[&["render"], &small[..], args].concat(), &dir);
        assert!(out.status.success(), "{}", stderr(&out));
        (String::from_utf8_lossy(&out.stdout).into_owned(), stderr(&out))
    };
    ok(&["--renderer", "path", "--spp", "256", "-o", "ref.exr"]);
    let (_, err) = ok(&["--renderer", "photon-cpu", "--passes", "4", "-o", "four.exr"]);
    assert!(err.contains("4 passes in") && err.contains("stopped by the pass count"), "{err}");
    assert!(dir.join("four.exr").is_file());
    // The GPU renderer (or photon-cpu after a line saying why): the same passes.
    let (_, err) = ok(&["--passes", "3", "-o", "gpu.png"]);
    assert!(err.contains("3 passes in"), "{err}");
    let (text, _) = ok(&["--renderer", "photon-cpu", "--passes", "3", "--reference", "ref.exr", "-o", "cpu.png"]);
    let rmse: f64 = text
        .lines()
        .find_map(|l| l.strip_prefix("pass 3, ")?.split("relRMSE ").nth(1)?.split(' ').next()?.parse().ok())
        .expect("the error against the reference");
    assert!(rmse > 0.0 && rmse < 1.0, "{text}");
    assert!(text.contains(" meanratio ") && text.contains(" block16 "), "{text}");
    // A time limit without a pass count: passes until it runs out, checkpoints on the way.
    let (text, err) = ok(&[
        "--renderer",
        "photon-cpu",
        "--time",
        "1.5",
        "--checkpoint",
        "0.3",
        "--reference",
        "ref.exr",
        "-o",
        "t.exr",
    ]);
    assert!(err.contains("stopped by the time limit"), "{err}");
    assert!(text.lines().filter(|l| l.contains("relRMSE")).count() >= 3, "checkpoints: {text}");
    // Bad input: exit 2, nothing written (in a folder of its own, holding the reference).
    let bad = scratch_dir("passes-bad");
    let out = hikari(
        &[
            "render",
            "cornell-box",
            "--resolution",
            "16x16",
            "--renderer",
            "path",
            "--spp",
            "64",
            "-q",
            "-o",
            "ref16.exr",
        ],
        &bad,
    );
    assert!(out.status.success(), "{}", stderr(&out));
    for (args, words) in [
        (&["--passes", "2", "--alpha", "1"][..], &["--alpha"][..]),
        (&["--passes", "0"], &["--passes"]),
        (&["--time", "-1"], &["--time"]),
        (&["--passes", "2", "--reference", "missing.exr"], &["missing.exr"]),
        (&["--passes", "2", "--reference", "ref16.exr"], &["ref16.exr", "16x16", "32x32"]),
        (&["--passes", "2", "--reference", "shown.png"], &["shown.png", "exr"]),
        (&["--passes", "1", "--checkpoint", "1"], &["--checkpoint"]),
    ] {
        let out = hikari(&[&["render"], &small[..], args, &["-o", "bad.png"]].concat(), &bad);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {}", stderr(&out));
        assert_fails_with(&out, &bad, words);
    }
}

/// Ctrl-C ends a progressive render after the pass under way and writes
/// the image so far.
#[test]
fn ctrl_c_writes_the_passes_so_far() {
    let dir = scratch_dir("ctrlc");
    let child = Command::new(env!("CARGO_BIN_EXE_hikari"))
        .args(["render", "cornell-box", "--resolution", "32x32", "--photons", "5000", "--renderer", "photon-cpu"])
        .args(["--passes", "1000000", "-q", "-o", "so-far.exr"])
        .current_dir(&dir)
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    std::thread::sleep(std::time::Duration::from_millis(1500));
    let sent = Command::new("kill").args(["-INT", &child.id().to_string()]).status().unwrap();
    assert!(sent.success());
    let out = child.wait_with_output().unwrap();
    let err = stderr(&out);
    assert!(out.status.success(), "{err}");
    assert!(err.contains("stopped by Ctrl-C"), "{err}");
    assert!(dir.join("so-far.exr").is_file());
}

/// `--trace gpu` traces on the GPU tracer and renders what `--trace cpu`
/// renders (the same photons up to rounding); `auto` picks the CPU on this
/// software adapter; region media are traced on the GPU too.
#[test]
fn traces_photons_on_the_gpu_or_the_cpu() {
    let dir = scratch_dir("trace");
    let render = |trace: &str, scene: &str, out: &str| {
        let args = [
            "render",
            scene,
            "--trace",
            trace,
            "--resolution",
            "24x24",
            "--photons",
            "4000",
            "--passes",
            "1",
            "-o",
            out,
            "-q",
        ];
        let out = hikari(&args, &dir);
        assert!(out.status.success(), "{}", stderr(&out));
        stderr(&out)
    };
    let gpu = render("gpu", "cornell-caustic", "gpu.exr");
    assert!(gpu.contains("traced on the gpu"), "{gpu}");
    let cpu = render("cpu", "cornell-caustic", "cpu.exr");
    assert!(cpu.contains("traced on the cpu"), "{cpu}");
    let read = |name: &str| hikari_core::output::read_exr(&dir.join(name)).unwrap();
    let error = hikari_core::progressive::compare(&read("gpu.exr"), &read("cpu.exr")).unwrap();
    assert!(error.relative_rmse < 1e-3, "{error:?}");
    let auto = render("auto", "cornell-caustic", "auto.png");
    assert!(auto.contains("traced on the cpu"), "lavapipe is a software adapter: {auto}");
    let layered = render("gpu", "fog-stage-layered", "layered.png");
    assert!(layered.contains("traced on the gpu"), "{layered}");
    let bad = hikari(&["render", "--trace", "tpu"], &dir);
    assert_eq!(bad.status.code(), Some(2));
}

/// `--estimator tiled` renders the splat's image; `auto` keeps the raster
/// splat on this software adapter, and says which it used.
#[test]
fn tiled_estimator_renders_the_splat_image() {
    let dir = scratch_dir("estimator");
    let render = |estimator: &str, out: &str| {
        let args = [
            "render",
            "cornell-box",
            "--estimator",
            estimator,
            "--resolution",
            "32x32",
            "--photons",
            "5000",
            "--passes",
            "1",
            "-o",
            out,
        ];
        let out = hikari(&args, &dir);
        assert!(out.status.success(), "{}", stderr(&out));
        stderr(&out)
    };
    assert!(render("tiled", "tiled.exr").contains("Tiled estimator"));
    assert!(render("raster", "raster.exr").contains("Raster estimator"));
    assert!(render("auto", "auto.exr").contains("Raster estimator"));
    let read = |name: &str| hikari_core::output::read_exr(&dir.join(name)).unwrap();
    let error = hikari_core::progressive::compare(&read("tiled.exr"), &read("raster.exr")).unwrap();
    // f16 splat sums on GL differ from the exact tiled sums by up to ~1%.
    assert!(error.relative_rmse < 5e-3, "{error:?}");
}

/// A glTF file renders from the command line (its camera's aspect kept by a
/// one-sided `--resolution`); a broken one, or an unknown `--camera`, is a
/// located error with exit code 2 and no image.
#[test]
fn gltf_files_render_and_broken_ones_are_located_errors() {
    use hikari_core::scene::Scene;
    use hikari_core::scene::gltf::export::scene_to_glb;
    let dir = scratch_dir("gltf");
    let mut scene = Scene::load("cornell-box").unwrap();
    scene.camera = scene.camera.with_resolution(40, 20).unwrap();
    let glb = scene_to_glb(&scene).unwrap();
    std::fs::write(dir.join("box.glb"), &glb).unwrap();
    let out = hikari(
        &[
            "render",
            "box.glb",
            "--renderer",
            "photon-cpu",
            "--resolution",
            "x10",
            "--photons",
            "2000",
            "--passes",
            "1",
            "-o",
            "g.png",
            "-q",
        ],
        &dir,
    );
    assert!(out.status.success(), "{}", stderr(&out));
    let img = image::open(dir.join("g.png")).unwrap();
    assert_eq!((img.width(), img.height()), (20, 10), "the camera's 2:1 aspect ratio is kept");
    std::fs::remove_file(dir.join("g.png")).unwrap();

    std::fs::write(dir.join("cut.glb"), &glb[..glb.len() / 2]).unwrap();
    let out = hikari(&["render", "cut.glb", "-o", "g.png", "-q"], &dir);
    assert_eq!(out.status.code(), Some(2), "{}", stderr(&out));
    assert_fails_with(&out, &dir, &["cut.glb", "glTF"]);

    let out = hikari(&["render", "box.glb", "--camera", "Nope", "-o", "g.png", "-q"], &dir);
    assert_eq!(out.status.code(), Some(2), "{}", stderr(&out));
    assert_fails_with(&out, &dir, &["box.glb", "cameras", "\"Nope\""]);
}

/// A floor and a box under a sun and a sky, in TOML.
const SUN_AND_SKY: &str = r#"
[camera]
position = [0.0, 1.2, 2.5]
look_at = [0.0, 0.2, 0.0]
resolution = [32, 32]

[[material]]
name = "grey"
type = "diffuse"
albedo = [0.5, 0.5, 0.5]

[[object]]
shape = "quad"
corner = [-2.0, 0.0, -2.0]
edge_u = [0.0, 0.0, 4.0]
edge_v = [4.0, 0.0, 0.0]
material = "grey"

[[object]]
shape = "box"
center = [0.0, 0.3, 0.0]
size = [0.6, 0.6, 0.6]
material = "grey"

[[light]]
type = "directional"
direction = [0.5, -0.866, -0.2]
irradiance = [3.0, 3.0, 3.0]

[environment]
radiance = [0.3, 0.4, 0.5]
"#;

/// Suns, skies and emissive surfaces render on the GPU: a TOML scene under
/// a sun and a sky without a line about falling back; glTF files (the
/// Cornell box with its light as an emissive surface, one without lights,
/// which the loader lights with a white sky, glossy materials included)
/// neither.
#[test]
fn suns_skies_and_emissive_surfaces_render_on_the_gpu() {
    use hikari_core::scene::gltf::export::scene_to_glb;
    let dir = scratch_dir("distant-gpu");
    std::fs::write(dir.join("sun-and-sky.toml"), SUN_AND_SKY).unwrap();
    let mesh_light = scene_to_glb(&hikari_core::test_scenes::cornell_quad_light(32)).unwrap();
    std::fs::write(dir.join("mesh-light.glb"), mesh_light).unwrap();
    std::fs::write(dir.join("unlit.glb"), unlit_glb()).unwrap();
    for file in ["sun-and-sky.toml", "mesh-light.glb", "unlit.glb"] {
        let out =
            hikari(&["render", file, "--resolution", "32", "--photons", "5000", "--passes", "1", "-o", "g.exr"], &dir);
        let err = stderr(&out);
        assert!(out.status.success(), "{file}: {err}");
        let fell_back = err.lines().find(|l| l.contains("rendering with photon-cpu instead"));
        if let Some(line) = fell_back {
            panic!("{file} fell back: {line}");
        }
        let image = hikari_core::output::read_exr(&dir.join("g.exr")).unwrap();
        assert!(image.mean() > 0.0, "{file}: a black image");
    }
}

/// `--environment FILE` lights a file by a sky image (here a glTF file
/// without lights, which would otherwise get the white sky): the GPU
/// renderer says it cannot and photon-cpu renders it, lit; a missing or
/// corrupt image is an error naming it, exit 2, no output.
#[test]
fn an_environment_map_lights_a_gltf_file() {
    let dir = scratch_dir("environment-map");
    std::fs::write(dir.join("unlit.glb"), unlit_glb()).unwrap();
    let (w, h) = (16u32, 8u32);
    let data: Vec<f32> = (0..w * h).flat_map(|i| if i / w < h / 2 { [2.0, 1.5, 1.0] } else { [0.1; 3] }).collect();
    let sky = image::Rgb32FImage::from_raw(w, h, data).unwrap();
    image::DynamicImage::ImageRgb32F(sky).save(dir.join("sky.exr")).unwrap();
    let args =
        ["render", "unlit.glb", "--environment", "sky.exr", "--resolution", "24", "--photons", "5000", "--passes", "1"];
    let out = hikari(&[&args[..], &["-o", "env.exr"]].concat(), &dir);
    let err = stderr(&out);
    assert!(out.status.success(), "{err}");
    assert!(err.contains("environment map"), "{err}");
    assert!(!err.contains("white environment"), "{err}");
    let image = hikari_core::output::read_exr(&dir.join("env.exr")).unwrap();
    assert!(image.mean() > 0.0, "a black image");
    std::fs::write(dir.join("broken.hdr"), b"#?RADIANCE\nnonsense").unwrap();
    for (file, words) in [("missing.exr", "missing.exr"), ("broken.hdr", "broken.hdr")] {
        let out = hikari(&["render", "unlit.glb", "--environment", file, "-o", "bad.png"], &dir);
        let err = stderr(&out);
        assert_eq!(out.status.code(), Some(2), "{file}: {err}");
        assert!(err.contains(words) && err.contains("environment map"), "{file}: {err}");
        assert!(!dir.join("bad.png").exists(), "{file}: an image was written");
    }
}

/// `--renderer vcm` renders in passes (16 by default) with each of its
/// strategy sets; a scene with fog is refused (exit 2, nothing written).
#[test]
fn vertex_connection_and_merging_renders_every_strategy_and_fog() {
    let dir = scratch_dir("vcm");
    let run =
        |args: &[&str]| hikari(&[&["render", "cornell-caustic", "--resolution", "16x16", "-q"], args].concat(), &dir);
    let out = run(&["--renderer", "vcm", "--passes", "16", "-o", "v.exr"]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    assert!(String::from_utf8_lossy(&out.stderr).contains("16 passes"), "{}", String::from_utf8_lossy(&out.stderr));
    for strategies in ["connections", "merging", "light-tracing"] {
        let out = run(&["--renderer", "vcm", "--vcm-strategies", strategies, "--passes", "2", "-o", "s.png"]);
        assert!(out.status.success(), "{strategies}: {}", String::from_utf8_lossy(&out.stderr));
    }
    let image = hikari_core::output::read_exr(&dir.join("v.exr")).unwrap();
    assert!(image.pixels.iter().all(|p| p.is_finite()) && image.mean() > 0.0);
    let out = hikari(
        &["render", "fog-stage", "--resolution", "16x16", "-q", "--renderer", "vcm", "--passes", "8", "-o", "fog.exr"],
        &dir,
    );
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let fog = hikari_core::output::read_exr(&dir.join("fog.exr")).unwrap();
    assert!(fog.pixels.iter().all(|p| p.is_finite()) && fog.mean() > 0.0);
}

/// `--target-error` renders passes until the noise the passes estimate
/// falls to it, showing the estimate; a fraction outside (0, 1) is refused.
#[test]
fn renders_until_the_target_error() {
    let dir = scratch_dir("target");
    let out = hikari(
        &[
            "render",
            "cornell-box",
            "--renderer",
            "path",
            "--spp",
            "1",
            "--resolution",
            "16x16",
            "--target-error",
            "0.2",
            "-o",
            "t.exr",
        ],
        &dir,
    );
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success() && err.contains("stopped by the target error"), "{err}");
    let noise: f64 = err
        .split("estimated noise ")
        .nth(1)
        .and_then(|t| t.split('%').next())
        .and_then(|v| v.parse().ok())
        .expect("the estimate");
    assert!(noise <= 20.0, "{err}");
    let bad = scratch_dir("target-bad");
    assert_fails_with(
        &hikari(&["render", "cornell-box", "--target-error", "1.5", "-o", "t.png"], &bad),
        &bad,
        &["--target-error"],
    );
}

/// With nothing said about when to stop, a render is progressive: passes
/// until the noise they estimate is 2% (or 20 s), on the GPU (which
/// reads its two half-means back) or on the CPU after a line saying why.
/// (A floor and a box under a sun and a sky: about 64 passes; small shadow
/// maps, which lavapipe redraws each pass.)
#[test]
fn the_default_render_stops_when_the_noise_is_two_percent() {
    let dir = scratch_dir("default-stop");
    std::fs::write(dir.join("sun-and-sky.toml"), SUN_AND_SKY).unwrap();
    let args = ["sun-and-sky.toml", "--resolution", "16x16", "--photons", "50000", "--shadow-map-size", "128"];
    let out = hikari(&[&["render"], &args[..], &["-o", "d.exr"]].concat(), &dir);
    let err = stderr(&out);
    assert!(out.status.success(), "{err}");
    assert!(err.contains("until the estimated noise is 2%") && err.contains("--passes 1"), "{err}");
    assert!(err.contains("stopped by the target error"), "{err}");
    let noise: f64 = err
        .split("estimated noise ")
        .last()
        .and_then(|t| t.split('%').next())
        .and_then(|v| v.parse().ok())
        .expect("the estimate");
    assert!(noise <= 2.0, "{err}");
    assert!(dir.join("d.exr").is_file());
}

/// `hikari plot` draws what `render --reference` prints as a PNG chart;
/// a missing file, one without curves or another image type is exit 2 and
/// no file.
#[test]
fn plots_error_curves() {
    let dir = scratch_dir("plot");
    let text = "vcm: pass 4, 1.02 s: relRMSE 0.21 meanratio 1.0\nvcm: pass 16, 4.1 s: relRMSE 0.11 meanratio 1.0\n\
                path: pass 2, 1.1 s: relRMSE 0.4 meanratio 1.0\npath: pass 8, 4.3 s: relRMSE 0.2 meanratio 1.0\n";
    std::fs::write(dir.join("curves.txt"), text).unwrap();
    let out = hikari(&["plot", "curves.txt", "--title", "test", "-o", "c.png"], &dir);
    assert!(out.status.success(), "{}", stderr(&out));
    let chart = image::open(dir.join("c.png")).unwrap();
    assert_eq!((chart.width(), chart.height()), (800, 560));
    std::fs::remove_file(dir.join("c.png")).unwrap();
    std::fs::write(dir.join("empty.txt"), "no curves\n").unwrap();
    for (args, words) in [
        (&["plot", "missing.txt", "-o", "bad.png"][..], &["missing.txt"][..]),
        (&["plot", "empty.txt", "-o", "bad.png"], &["empty.txt", "no error curves"]),
        (&["plot", "curves.txt", "-o", "bad.jpg"], &["bad.jpg", ".png"]),
    ] {
        let out = hikari(args, &dir);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {}", stderr(&out));
        assert_fails_with(&out, &dir, words);
    }
}

/// `hikari bench` prints its rows in the form scripts/bench_ratio.py reads
/// (`LABEL at WxH: F fps (T ms/frame), ...`), stops a row at its budget,
/// and refuses an unknown feature by name.
#[test]
fn bench_rows_keep_the_form_scripts_read() {
    let dir = scratch_dir("bench");
    let args = ["bench", "--frames", "2", "--only", "2,000 photons", "--no-tracing", "--with-features", "glossy"];
    let out = hikari(&args, &dir);
    let text = String::from_utf8_lossy(&out.stdout).to_string();
    assert!(out.status.success(), "{}", stderr(&out));
    let rows: Vec<&str> = text.lines().filter(|l| l.contains(" ms/frame)")).collect();
    assert_eq!(rows.len(), 1, "{text}");
    assert!(
        rows[0].starts_with("cornell-box, 2,000 photons, LOD off at 512x512: ") && rows[0].contains(" fps ("),
        "{text}"
    );
    assert!(text.contains("per pass ("), "{text}");
    let out = hikari(&["bench", "--with-features", "shiny"], &dir);
    assert!(!out.status.success());
    assert!(stderr(&out).contains("\"shiny\" is none of textured"), "{}", stderr(&out));
}

/// On a machine with no window system (no desktop session: no
/// XDG_RUNTIME_DIR, DISPLAY nor WAYLAND_DISPLAY) a render that succeeds
/// prints no error: Mesa's device-select layer, which would ask Wayland for
/// the default GPU, is switched off (#43 item 7).
#[test]
fn a_render_without_a_desktop_session_prints_no_error() {
    let dir = scratch_dir("headless");
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_hikari"))
        .args(["render", "--resolution", "16x16", "--photons", "500", "--passes", "1", "-o", "out.png"])
        .env_remove("XDG_RUNTIME_DIR")
        .env_remove("DISPLAY")
        .env_remove("WAYLAND_DISPLAY")
        .env_remove("NODEVICE_SELECT")
        .current_dir(&dir)
        .output()
        .expect("the binary runs");
    let err = stderr(&out);
    assert!(out.status.success(), "{err}");
    assert!(!err.contains("error"), "{err}");
    assert!(dir.join("out.png").is_file());
}

/// `--aov` writes further channels of an .exr; with a PNG it is a usage
/// error that writes nothing.
#[test]
fn aovs_need_an_exr_output() {
    let dir = scratch_dir("aov");
    let args = ["render", "--resolution", "16x16", "--renderer", "path", "--spp", "1", "--aov", "albedo,depth"];
    let out = hikari(&[&args[..], &["-o", "out.png"]].concat(), &dir);
    assert_eq!(out.status.code(), Some(2), "{}", stderr(&out));
    assert!(stderr(&out).contains("--aov") && !dir.join("out.png").exists());
    let out = hikari(&[&args[..], &["-o", "out.exr"]].concat(), &dir);
    assert!(out.status.success(), "{}", stderr(&out));
    let bytes = std::fs::read(dir.join("out.exr")).unwrap();
    let has = |name: &str| bytes.windows(name.len()).any(|w| w == name.as_bytes());
    assert!(has("Denoising Albedo.R") && has("Depth.Z") && !has("Denoising Normal.X"));
}

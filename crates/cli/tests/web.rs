//! The web page in a real browser: Debian's headless Chromium, WebGPU on
//! SwiftShader, driven by `web/test/drive.mjs` (playwright-core). Each test
//! runs one scenario of the driver and checks what it wrote.
//!
//! They need the built site (`bash scripts/web.sh build`), Chromium and the
//! driver's node modules, which `scripts/test.sh` installs and builds
//! (`bash scripts/web.sh test` runs these tests alone). Without them a
//! test fails saying what is missing, unless HIKARI_SKIP_WEB_TESTS is set.

mod common;

use common::{relative_rms, scratch_dir, stderr};
use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::Mutex;

/// One browser at a time: two would share the machine's two cores.
static BROWSER: Mutex<()> = Mutex::new(());

fn repo() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// Runs `scenario` and returns its result.json (None: skipped on purpose).
fn drive(scenario: &str, dir: &Path, env: &[(&str, &Path)]) -> Option<serde_json::Value> {
    if std::env::var_os("HIKARI_SKIP_WEB_TESTS").is_some() {
        eprintln!("WEB TEST SKIPPED: HIKARI_SKIP_WEB_TESTS is set");
        return None;
    }
    let repo = repo();
    for (path, how) in [
        (repo.join("web/dist/index.html"), "bash scripts/web.sh build"),
        (repo.join("web/test/node_modules/playwright-core"), "npm ci --prefix web/test"),
        (PathBuf::from("/usr/bin/chromium"), "apt-get install chromium"),
    ] {
        assert!(path.exists(), "{} is missing: run `{how}` (scripts/test.sh does)", path.display());
    }
    let _one = BROWSER.lock().unwrap_or_else(|e| e.into_inner());
    let mut command = Command::new("node");
    command.arg(repo.join("web/test/drive.mjs")).arg(scenario).arg(dir);
    for (name, value) in env {
        command.env(name, value);
    }
    let out = command.output().expect("node runs the driver");
    assert!(out.status.success(), "driver failed: {}", stderr(&out));
    let text = std::fs::read_to_string(dir.join("result.json")).expect("the driver writes result.json");
    let result: serde_json::Value = serde_json::from_str(&text).unwrap();
    assert!(result.get("failure").is_none(), "{scenario}: {}\nconsole: {}", result["failure"], result["console"]);
    Some(result)
}

/// Whether the driver runs Chromium with only `--enable-unsafe-webgpu`
/// (`HIKARI_BROWSER=stock`), not with the SwiftShader flags.
fn stock_browser() -> bool {
    std::env::var("HIKARI_BROWSER").is_ok_and(|b| b == "stock")
}

/// Chromium's SwiftShader Vulkan driver (Debian's chromium package).
const SWIFTSHADER_ICD: &str = "/usr/lib/chromium/vk_swiftshader_icd.json";

/// Console messages that are errors or warnings (the page logs its
/// progress as `log`).
fn console_problems(result: &serde_json::Value) -> Vec<String> {
    result["console"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|m| matches!(m["type"].as_str(), Some("error" | "pageerror")))
        .map(|m| m["text"].to_string())
        .collect()
}

/// An image the driver wrote: width, height, then RGBA floats.
fn read_mean(path: &Path) -> (usize, usize, Vec<[f32; 3]>) {
    let bytes = std::fs::read(path).unwrap();
    let floats: Vec<f32> = bytes.chunks(4).map(|b| f32::from_le_bytes(b.try_into().unwrap())).collect();
    let (width, height) = (floats[0] as usize, floats[1] as usize);
    let pixels = floats[2..].chunks(4).map(|p| [p[0], p[1], p[2]]).collect();
    (width, height, pixels)
}

fn exr(path: &Path) -> Vec<[f32; 3]> {
    image::open(path).unwrap().to_rgb32f().pixels().map(|p| p.0).collect()
}

/// The page opens on the default scene by itself, names its adapter, and
/// after 30 frames its mean is `hikari render --passes 30` of the same
/// scene, photons and seeds on the same driver (SwiftShader, natively
/// through Vulkan; the photons traced by the same compute shader, which
/// `trace=gpu` asks for on this software adapter). No errors reach the
/// console meanwhile.
#[test]
fn the_page_converges_to_the_native_render() {
    let frames = std::env::var("HIKARI_FRAMES").unwrap_or("30".into());
    page_against_native_render("web-converge", None, &frames, "gpu");
}

/// Glass on the page: the mirror/glass pass and the caustic map run in the
/// browser (their tables packed into WebGPU's default of 8 storage
/// buffers) and give the native render's frames.
#[test]
fn glass_and_caustics_render_on_the_page_as_natively() {
    page_against_native_render("web-glass", Some("cornell-caustic"), "4", "gpu");
}

/// On a software adapter the page traces its photons on its own thread,
/// as `hikari render --trace auto` does natively (the emulated GPU is the
/// slower tracer there), and its frames are the native CPU tracer's: the
/// tracer gives the same photons on one thread as on many.
#[test]
fn on_a_software_adapter_the_page_traces_on_the_cpu() {
    page_against_native_render("web-cpu-trace", None, "4", "cpu");
}

/// The page's mean after `frames` frames of `scene` (None: the default)
/// against `hikari render --trace TRACE` of the same on the same driver;
/// the page is asked for the GPU tracer with trace=gpu and left to choose
/// for "cpu" (SwiftShader is a software adapter).
fn page_against_native_render(name: &str, scene: Option<&str>, frames: &str, trace: &str) {
    let dir = scratch_dir(name);
    let mut env = vec![("HIKARI_FRAMES", Path::new(frames))];
    if let Some(scene) = scene {
        env.push(("HIKARI_SCENE", Path::new(scene)));
    }
    if trace == "gpu" {
        env.push(("HIKARI_TRACE", Path::new("gpu")));
    }
    let Some(result) = drive("converge", &dir, &env) else { return };
    eprintln!("adapter: {}; first frame after {} ms", result["adapter"], result["firstFrameMs"]);
    assert!(result["adapter"].as_str().unwrap().contains("BrowserWebGpu"), "{}", result["adapter"]);
    assert_eq!(result["frames"].to_string(), frames);
    assert_eq!(result["error"], "");
    assert_eq!(result["tracer"], trace.to_uppercase(), "where the page traced its photons");
    assert_eq!(result["status"], "", "the status line stays after the frames were drawn");
    // Chromium as a user's is (HIKARI_BROWSER=stock, scripts/web.sh test
    // runs the tests both ways) cannot present a WebGPU canvas headless:
    // the frames reach the page through a 2D canvas, and they are lit.
    if stock_browser() {
        assert_eq!(result["presentation"], "copy", "{result}");
        let lit = result["copyLit"].as_f64().expect("the 2D canvas's pixels");
        assert!(lit > 0.5, "{lit} of the 2D canvas's pixels lit");
    } else {
        assert_eq!(result["presentation"], "surface", "{result}");
    }
    let (width, height, web) = read_mean(&dir.join(format!("web-{frames}.f32")));
    assert_eq!((width, height), (48, 36));
    // The same renderer natively on the same driver: Chromium's own
    // SwiftShader Vulkan, through its ICD file. (Against lavapipe the frames
    // differ as two drivers do: 5.8% at one pass, 0.9% at 30, mean 0.1%.)
    let out = Command::new(env!("CARGO_BIN_EXE_hikari"))
        .args(["render", "-q", scene.unwrap_or("cornell-box"), "--renderer", "gpu"])
        .args(["--resolution", "48x36", "--photons", "3000"])
        .args(["--passes", frames, "--trace", trace, "-o", "native.exr"])
        .env("VK_ICD_FILENAMES", SWIFTSHADER_ICD)
        .env_remove("WGPU_BACKEND")
        .current_dir(&dir)
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(stderr(&out).contains("SwiftShader"), "not rendered on SwiftShader: {}", stderr(&out));
    let native = exr(&dir.join("native.exr"));
    let difference = relative_rms(&web, &native);
    eprintln!("web page vs hikari render on SwiftShader, {frames} passes: relative RMS {difference:.2e}");
    assert!(difference < 1e-5, "the page's mean differs from the native render by {difference}");
    assert!(console_problems(&result).is_empty(), "console: {:?}", console_problems(&result));
}

/// A .glb dropped on the page becomes the scene; a broken one shows its
/// located error on the page, and the scene before it stays.
#[test]
fn dropped_files_open_or_say_why_not() {
    let dir = scratch_dir("web-drop");
    let glb = dir.join("fixture.glb");
    std::fs::write(&glb, common::unlit_glb()).unwrap();
    let gltf_dir = dir.join("gltf");
    std::fs::create_dir_all(&gltf_dir).unwrap();
    for (name, bytes) in hikari_core::test_scenes::gltf_textures::checker_gltf_files() {
        std::fs::write(gltf_dir.join(name), bytes).unwrap();
    }
    let Some(result) = drive("drop", &dir, &[("HIKARI_GLB", &glb), ("HIKARI_GLTF_DIR", &gltf_dir)]) else { return };
    assert_eq!(result["afterGood"][0], "fixture.glb");
    assert_eq!(result["afterGood"][1], "");
    let (_, _, dropped) = read_mean(&dir.join("web-dropped.f32"));
    let mean = dropped.iter().flatten().map(|&x| x as f64).sum::<f64>() / (3 * dropped.len()) as f64;
    assert!(mean > 1e-3 && mean.is_finite(), "the dropped scene renders dark: {mean}");
    let [name, error, shown, display] = [0, 1, 2, 3].map(|i| result["afterBroken"][i].as_str().unwrap().to_string());
    assert_eq!(name, "fixture.glb", "the last good scene stays");
    assert!(error.starts_with("broken.glb"), "{error}");
    assert!(error.contains("the last scene stays"), "{error}");
    assert_eq!(shown, error, "the error shows on the page");
    assert_eq!(display, "block");
    assert_eq!(result["framesGoOn"], true);
    // Three files dropped at once: the .gltf, its buffer and its texture.
    assert_eq!(result["afterGltf"][0], "checker.gltf");
    assert_eq!(result["afterGltf"][1], "", "the error went with the good scene");
}

/// A drag moves the camera, the panel's checkbox switches the indirect
/// term off, and "save PNG" downloads a PNG of the frame.
#[test]
fn the_mouse_and_the_panel_work() {
    let dir = scratch_dir("web-controls");
    let Some(result) = drive("controls", &dir, &[]) else { return };
    // The panel shows each pass's time and the noise estimate.
    let passes = result["passTimes"]["passes"].as_array().unwrap();
    let names: Vec<&str> = passes.iter().map(|p| p["pass"].as_str().unwrap()).collect();
    eprintln!("page passes ({}): {passes:?}", result["passTimes"]["timed"]);
    assert!(names.len() >= 5 && names.iter().all(|n| !n.is_empty()), "{names:?}");
    assert!(passes.iter().all(|p| p["ms"].as_f64().is_some_and(|ms| ms >= 0.0 && ms.is_finite())), "{passes:?}");
    assert!(passes.iter().map(|p| p["ms"].as_f64().unwrap()).sum::<f64>() > 0.0, "{passes:?}");
    let noise = result["noise"].as_f64().unwrap();
    assert!(noise > 0.0 && noise < 1.0, "noise estimate {noise}");
    assert!(result["dragChange"].as_f64().unwrap() > 1e-3, "the drag did not move the view: {result}");
    assert!(result["termsBefore"].as_str().unwrap().contains("indirect"));
    assert!(!result["termsAfter"].as_str().unwrap().contains("indirect"), "{}", result["termsAfter"]);
    assert_eq!(result["download"], "cornell-box.png");
    let png = image::open(dir.join("saved.png")).expect("the download is a PNG");
    assert_eq!((png.width(), png.height()), (640, 480));
    assert!(console_problems(&result).is_empty(), "console: {:?}", console_problems(&result));
}

/// A `widgetRect` as the driver wrote it (a Float32Array: an object keyed
/// "0" to "3", empty when the widget was not drawn).
fn widget_rect(value: &serde_json::Value) -> Vec<f64> {
    let entries = value.as_object().unwrap();
    (0..entries.len()).map(|i| entries[&i.to_string()].as_f64().unwrap()).collect()
}

/// On a phone-sized window (390×844 CSS pixels, 2 device pixels each,
/// touch) the canvas fills it and the panel starts folded to its title bar
/// (it would cover the image); a tap on its arrow opens it.
#[test]
fn a_phone_sized_window_shows_the_image_and_a_folded_panel() {
    let dir = scratch_dir("web-phone");
    let Some(result) = drive("phone", &dir, &[]) else { return };
    let canvas: Vec<u64> = result["canvas"].as_array().unwrap().iter().map(|v| v.as_u64().unwrap()).collect();
    // It fills the window; it renders a pixel per CSS pixel (at 2 device
    // pixels per CSS pixel, a quarter of the work).
    assert_eq!(canvas, [390, 844, 390, 844], "CSS size then the canvas's pixels");
    let folded = widget_rect(&result["folded"][0]);
    assert!(widget_rect(&result["folded"][1]).is_empty(), "the panel's contents are drawn: {result}");
    assert!(folded[3] - folded[1] < 40.0, "the folded panel is more than a title bar: {folded:?}");
    let opened = widget_rect(&result["opened"]);
    assert!(opened[3] - opened[1] > 200.0, "the tap did not open the panel: {opened:?}");
    assert_eq!(result["error"], "");
    assert!(console_problems(&result).is_empty(), "console: {:?}", console_problems(&result));
}

/// Without WebGPU the page says so in one line, and shows no canvas.
#[test]
fn without_webgpu_the_page_says_so() {
    let dir = scratch_dir("web-no-webgpu");
    let Some(result) = drive("no-webgpu", &dir, &[]) else { return };
    let message = result["message"].as_str().unwrap();
    assert!(message.starts_with("hikari needs WebGPU"), "{message}");
    assert!(message.contains("Chrome") && !message.contains('\n'), "{message}");
    assert_eq!(result["canvasHidden"], true);
}

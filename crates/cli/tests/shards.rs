//! One render split into shards (`render --shard K/M`) and merged (`hikari
//! merge`): the merge equals one run of all the passes, and parts that do
//! not belong together are refused by name (#20).

mod common;

use common::*;
use std::path::Path;
use std::process::Output;

/// The render every test splits: 7 passes of a small Cornell box.
const BASE: &[&str] =
    &["render", "--resolution", "16x12", "--photons", "1500", "--shadow-map-size", "64", "--passes", "7", "-q"];

fn render(dir: &Path, renderer: &str, extra: &[&str], output: &str) -> Output {
    let mut args = BASE.to_vec();
    args.extend_from_slice(&["--renderer", renderer, "-o", output]);
    args.extend_from_slice(extra);
    hikari(&args, dir)
}

fn ok(out: Output) -> String {
    let err = stderr(&out);
    assert!(out.status.success(), "{err}");
    err
}

fn pixels(path: &Path) -> Vec<f32> {
    let image = image::open(path).unwrap_or_else(|e| panic!("{}: {e}", path.display())).to_rgb32f();
    image.into_raw()
}

/// Renders shards 1..=M of `renderer` and merges them into `merged.exr`.
fn shards_merged(dir: &Path, renderer: &str, shards: u32, env: &[(&str, &str)]) -> Vec<f32> {
    let mut parts = Vec::new();
    for k in 1..=shards {
        let part = format!("{renderer}-{k}-of-{shards}.exr");
        let shard = format!("{k}/{shards}");
        let mut args = BASE.to_vec();
        args.extend_from_slice(&["--renderer", renderer, "--shard", &shard, "-o", &part]);
        ok(command(&args, dir, env));
        parts.push(part);
    }
    let mut args = vec!["merge", "-o", "merged.exr"];
    args.extend(parts.iter().rev().map(String::as_str));
    let err = ok(command(&args, dir, env));
    assert!(err.contains(&format!("7 passes of 7 from {shards} parts")), "{err}");
    pixels(&dir.join("merged.exr"))
}

fn command(args: &[&str], dir: &Path, env: &[(&str, &str)]) -> Output {
    std::process::Command::new(env!("CARGO_BIN_EXE_hikari"))
        .args(args)
        .envs(env.iter().copied())
        .current_dir(dir)
        .output()
        .expect("the binary runs")
}

/// The CPU renderers sum their passes in f64, exactly for these images, so
/// the merge is bit-identical to the single run, however the passes split.
#[test]
fn merged_shards_are_the_single_run_bit_for_bit() {
    let dir = scratch_dir("shards");
    for renderer in ["photon-cpu", "path", "vcm"] {
        ok(render(&dir, renderer, &[], "single.exr"));
        let single = pixels(&dir.join("single.exr"));
        for shards in [1, 2, 3, 7] {
            let merged = shards_merged(&dir, renderer, shards, &[]);
            assert!(merged.iter().zip(&single).all(|(a, b)| a.to_bits() == b.to_bits()), "{renderer}, {shards} shards");
        }
    }
}

/// The GPU keeps its running mean in f32: its merge matches the single run
/// to 1e-6 relative (measured: 2e-7), on Vulkan and on OpenGL.
#[test]
fn merged_gpu_shards_match_the_single_run() {
    for (backend, env) in [("vulkan", &[][..]), ("gl", &[("WGPU_BACKEND", "gl")][..])] {
        let dir = scratch_dir(&format!("gpu-shards-{backend}"));
        let mut args = BASE.to_vec();
        args.extend_from_slice(&["--renderer", "gpu", "-o", "single.exr"]);
        let err = ok(command(&args, &dir, env));
        assert!(err.contains("averaged on the GPU"), "{backend}: {err}");
        let single = pixels(&dir.join("single.exr"));
        for shards in [1, 2, 3, 7] {
            let merged = shards_merged(&dir, "gpu", shards, env);
            let worst = merged
                .iter()
                .zip(&single)
                .map(|(a, b)| ((a - b).abs() / b.abs().max(1e-20)) as f64)
                .fold(0.0, f64::max);
            assert!(worst <= 1e-6, "{backend}, {shards} shards: relative difference {worst}");
        }
    }
}

#[test]
fn parts_that_do_not_belong_together_are_refused_by_name() {
    let dir = scratch_dir("bad-shards");
    for k in 1..=3 {
        ok(render(&dir, "path", &["--shard", &format!("{k}/3")], &format!("part-{k}.exr")));
    }
    ok(render(&dir, "path", &["--shard", "2/3", "--seed", "5"], "seed.exr"));
    ok(render(&dir, "path", &["--shard", "2/3", "--spp", "2"], "spp.exr"));
    let mut other = vec!["render", "cornell-caustic"];
    other.extend_from_slice(&BASE[1..]);
    other.extend_from_slice(&["--renderer", "path", "--shard", "2/3", "-o", "scene.exr"]);
    ok(hikari(&other, &dir));
    ok(render(&dir, "vcm", &["--shard", "2/3"], "vcm.exr"));
    let bytes = std::fs::read(dir.join("part-2.exr")).unwrap();
    std::fs::write(dir.join("truncated.exr"), &bytes[..bytes.len() / 2]).unwrap();
    std::fs::write(dir.join("copy.exr"), &bytes).unwrap();
    for (parts, words) in [
        (&["part-1.exr", "seed.exr", "part-3.exr"][..], &["seed.exr", "setting seed"][..]),
        (&["part-1.exr", "spp.exr", "part-3.exr"], &["spp.exr", "setting spp"]),
        (&["part-1.exr", "scene.exr", "part-3.exr"], &["scene.exr", "scene content"]),
        (&["part-1.exr", "vcm.exr", "part-3.exr"], &["vcm.exr", "renderer"]),
        (&["part-1.exr", "part-3.exr"], &["incomplete", "shard 2/3 missing"]),
        (&["part-1.exr", "part-2.exr", "copy.exr", "part-3.exr"], &["both shard 2/3"]),
        (&["part-1.exr", "truncated.exr", "part-3.exr"], &["truncated.exr"]),
        (&["part-1.exr", "missing.exr"], &["missing.exr"]),
    ] {
        let mut args = vec!["merge", "-o", "merged.png"];
        args.extend_from_slice(parts);
        let out = hikari(&args, &dir);
        assert_eq!(out.status.code(), Some(2), "{parts:?}: {}", stderr(&out));
        assert_fails_with(&out, &dir, words);
        assert!(!dir.join("merged.png").exists());
    }
    // The missing shard rendered, the set is complete.
    std::fs::remove_file(dir.join("part-2.exr")).unwrap();
    ok(render(&dir, "path", &["--shard", "2/3"], "part-2.exr"));
    ok(hikari(&["merge", "part-1.exr", "part-2.exr", "part-3.exr", "-o", "merged.png"], &dir));
    assert!(dir.join("merged.png").is_file());
}

#[test]
fn shard_flags_are_checked() {
    let dir = scratch_dir("shard-flags");
    for (args, words) in [
        (
            &["render", "--renderer", "path", "--shard", "1/2", "--passes", "4", "-o", "a.png"][..],
            &["a.png", ".exr"][..],
        ),
        (&["render", "--renderer", "path", "--shard", "1/2", "-o", "a.exr"], &["--passes"]),
        (&["render", "--renderer", "path", "--shard", "3/2", "--passes", "4", "-o", "a.exr"], &["3/2", "K/M"]),
        (&["render", "--renderer", "path", "--shard", "1/9", "--passes", "4", "-o", "a.exr"], &["more shards"]),
        (&["merge", "-o", "m.exr", "nothing.exr"], &["nothing.exr"]),
    ] {
        let out = hikari(args, &dir);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {}", stderr(&out));
        assert_fails_with(&out, &dir, words);
        assert!(!dir.join("a.exr").exists());
    }
}

/// Shards with a time limit stop after any pass; the merge weighs what
/// each did (the mean of all the passes they rendered). A pass of 64
/// samples per pixel takes longer than the 1 ms limit, so each renders one.
#[test]
fn shards_with_a_time_limit_merge_what_they_rendered() {
    let dir = scratch_dir("timed-shards");
    for k in 1..=2 {
        let err = ok(render(
            &dir,
            "path",
            &["--shard", &format!("{k}/2"), "--time", "0.001", "--spp", "64"],
            &format!("t-{k}.exr"),
        ));
        assert!(err.contains("1 passes of shard"), "{err}");
    }
    let err = ok(hikari(&["merge", "t-1.exr", "t-2.exr", "-o", "merged.exr"], &dir));
    assert!(err.contains("2 passes of 7 from 2 parts"), "{err}");
    // Passes 1 and 2: what a run of --passes 2 makes.
    let mut two = BASE.to_vec();
    two[BASE.len() - 2] = "2";
    two.extend_from_slice(&["--renderer", "path", "--spp", "64", "-o", "two.exr"]);
    ok(hikari(&two, &dir));
    assert_eq!(pixels(&dir.join("merged.exr")), pixels(&dir.join("two.exr")));
}

/// `--frames 0..5` renders the six frames `--at f / fps` renders, one file
/// each; a second run finds them written and renders nothing.
#[test]
fn frames_are_the_renders_at_their_times_and_a_rerun_skips_them() {
    let dir = scratch_dir("frames");
    let base = ["render", "cornell-orbit", "--renderer", "path", "--spp", "4", "--resolution", "12x12", "-q"];
    let mut args = base.to_vec();
    args.extend_from_slice(&["--frames", "0..5", "--fps", "4", "-o", "out-###.exr"]);
    let err = ok(hikari(&args, &dir));
    assert!(err.contains("6 rendered, 0 already written"), "{err}");
    let frames: Vec<_> = (0..=5).map(|f| dir.join(format!("out-{f:03}.exr"))).collect();
    let written: Vec<_> = frames.iter().map(|f| std::fs::metadata(f).unwrap().modified().unwrap()).collect();
    for (f, frame) in frames.iter().enumerate() {
        let at = (f as f64 / 4.0).to_string();
        let mut single = base.to_vec();
        single.extend_from_slice(&["--at", &at, "-o", "at.exr"]);
        ok(hikari(&single, &dir));
        assert_eq!(pixels(frame), pixels(&dir.join("at.exr")), "frame {f}");
    }
    assert_ne!(pixels(&frames[0]), pixels(&frames[3]), "the animation moves");
    let err = ok(hikari(&args, &dir));
    assert!(err.contains("0 rendered, 6 already written"), "{err}");
    let again: Vec<_> = frames.iter().map(|f| std::fs::metadata(f).unwrap().modified().unwrap()).collect();
    assert_eq!(written, again, "finished frames are not overwritten");
    // Without a # in the name there is nowhere to put the frame number.
    let out = hikari(&["render", "cornell-orbit", "--frames", "0..2", "-o", "still.exr"], &dir);
    assert_eq!(out.status.code(), Some(2));
    assert_fails_with(&out, &dir, &["still.exr", "#"]);
    let out = hikari(&["render", "--frames", "5..2", "-o", "x-#.exr"], &dir);
    assert_eq!(out.status.code(), Some(2));
    assert_fails_with(&out, &dir, &["5..2"]);
}

/// `HIKARI_GPU` picks the adapter (a cluster task's own GPU): by name or
/// index it renders there; naming none, it falls back with the adapters seen.
#[test]
fn hikari_gpu_picks_the_adapter() {
    let dir = scratch_dir("hikari-gpu");
    let args = [
        "render",
        "--resolution",
        "8x8",
        "--photons",
        "500",
        "--shadow-map-size",
        "32",
        "--passes",
        "1",
        "-o",
        "a.exr",
    ];
    for wanted in ["0", "llvmpipe"] {
        let err = ok(command(&args, &dir, &[("HIKARI_GPU", wanted)]));
        assert!(err.contains("gpu: llvmpipe"), "HIKARI_GPU={wanted}: {err}");
    }
    let err = ok(command(&args, &dir, &[("HIKARI_GPU", "no-such-gpu")]));
    assert!(err.contains("HIKARI_GPU=no-such-gpu names none of the adapters: 0: llvmpipe"), "{err}");
    assert!(err.contains("photon-cpu"), "{err}");
}

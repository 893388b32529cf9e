//! Scene files that once broke the loader or a renderer, mutants of the
//! built-in scenes and of glTF files, and the bounded structured fuzz run
//! that `scripts/fuzz-ci.sh` starts (`fuzz_for_a_while`, ignored by default).
//!
//! Every input that ever failed is kept in `tests/fuzz_regressions/` (with
//! any OBJ file it names): each must load and render finite, or be rejected
//! with a located error.

use hikari_core::fuzz::{self, Outcome, check_text, cpu_renderers, mutate};
use hikari_core::sampling::Rng;
use hikari_core::scene::builtin;
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

/// A render of 8×8 pixels taking longer than this counts as a hang.
const SLOW: Duration = Duration::from_secs(20);

fn regressions_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fuzz_regressions")
}

#[test]
fn every_regression_input_loads_and_renders_or_is_rejected_with_a_position() {
    fuzz::quiet_panics();
    let dir = regressions_dir();
    let mut files: Vec<PathBuf> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "toml"))
        .collect();
    files.sort();
    assert!(!files.is_empty(), "no regression inputs in {}", dir.display());
    let renderers = cpu_renderers();
    let mut failures = Vec::new();
    let scratch = scratch_dir("regressions");
    for file in dir.read_dir().unwrap().map(|e| e.unwrap().path()).filter(|p| p.extension().is_some_and(|e| e == "glb"))
    {
        let bytes = std::fs::read(&file).unwrap();
        if let Err(why) = fuzz::gltf::check_glb(&bytes, &scratch, &renderers, SLOW) {
            failures.push(format!("{}: {why}", file.display()));
        }
    }
    for file in &files {
        let text = std::fs::read_to_string(file).unwrap();
        let name = file.display().to_string();
        if let Err(why) = check_text(&text, &name, Some(&dir), &renderers, SLOW) {
            failures.push(format!("{name}: {why}"));
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

fn scratch_dir(tag: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("hikari-fuzz-{tag}-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// Runs mutants of the built-in scenes and (every third case) of glTF
/// files, from `seed`, until `cases` are done or `budget` is spent. Failing
/// inputs are written to `out`. Returns the counts (cases, rendered,
/// rejected) and the failures.
fn run(seed: u64, cases: u64, budget: Duration, out: Option<&Path>) -> ((u64, u64, u64), Vec<String>) {
    fuzz::quiet_panics();
    let renderers = cpu_renderers();
    let start = Instant::now();
    let (mut done, mut rendered, mut rejected) = (0, 0, 0);
    let mut failures = Vec::new();
    let glb_seeds = fuzz::gltf::seed_files();
    let scratch = scratch_dir(&format!("run{seed}"));
    while done < cases && start.elapsed() < budget {
        let mut rng = Rng::for_item(seed, done);
        // The outcome, the failing input's file name and its contents given the reason.
        let (outcome, file, contents): (_, _, Box<dyn Fn(&str) -> Vec<u8>>) = if done % 3 == 2 {
            let source = &glb_seeds[(done / 3) as usize % glb_seeds.len()];
            let glb = fuzz::gltf::mutate_glb(source, &mut rng);
            let outcome = fuzz::gltf::check_glb(&glb, &scratch, &renderers, SLOW);
            (outcome, format!("seed{seed}-case{done}.glb"), Box::new(move |_| glb.clone()))
        } else {
            let name = builtin::NAMES[(done % builtin::NAMES.len() as u64) as usize];
            let text = mutate(builtin::source(name).unwrap(), &mut rng);
            // A `builtin:` name: the layered fog's region mesh is the embedded copy.
            let outcome = check_text(&text, &format!("builtin:{name}"), None, &renderers, SLOW);
            let contents = move |why: &str| format!("# {}\n{text}", why.replace('\n', " ")).into_bytes();
            (outcome, format!("seed{seed}-case{done}-{name}.toml"), Box::new(contents))
        };
        match outcome {
            Ok(Outcome::Rendered) => rendered += 1,
            Ok(Outcome::Rejected(_)) => rejected += 1,
            Err(why) => {
                if let Some(out) = out {
                    std::fs::create_dir_all(out).unwrap();
                    std::fs::write(out.join(&file), contents(&why)).unwrap();
                }
                failures.push(format!("{file}: {why}"));
            }
        }
        done += 1;
    }
    ((done, rendered, rejected), failures)
}

#[test]
fn mutants_of_the_builtin_scenes_load_and_render_or_are_rejected() {
    let ((done, rendered, rejected), failures) = run(1, 120, Duration::from_secs(60), None);
    assert!(failures.is_empty(), "{}", failures.join("\n"));
    assert_eq!(done, rendered + rejected);
    // The mutator must not only make broken files.
    assert!(rendered >= done / 10, "{rendered} of {done} mutants rendered");
}

/// The bounded fuzz pass: HIKARI_FUZZ_SECONDS (default 60) of mutants from
/// HIKARI_FUZZ_SEED (default 0), at most HIKARI_FUZZ_CASES; failing inputs go
/// to HIKARI_FUZZ_OUT (default: the target folder's fuzz-failures/).
#[test]
#[ignore = "a minute long: run by scripts/fuzz-ci.sh"]
fn fuzz_for_a_while() {
    let var = |name: &str, default: u64| std::env::var(name).ok().and_then(|v| v.parse().ok()).unwrap_or(default);
    let seed = var("HIKARI_FUZZ_SEED", 0);
    let budget = Duration::from_secs(var("HIKARI_FUZZ_SECONDS", 60));
    let cases = var("HIKARI_FUZZ_CASES", u64::MAX);
    let out = std::env::var("HIKARI_FUZZ_OUT")
        .map(PathBuf::from)
        .unwrap_or_else(|_| PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("fuzz-failures"));
    let start = Instant::now();
    let ((done, rendered, rejected), failures) = run(seed, cases, budget, Some(&out));
    println!(
        "structured fuzz: seed {seed}: {done} mutants in {:.1} s: {rendered} rendered by {} renderers, {rejected} rejected with a located error, {} failed",
        start.elapsed().as_secs_f64(),
        cpu_renderers().len(),
        failures.len()
    );
    assert!(
        failures.is_empty(),
        "{} failures (inputs in {}; add them to tests/fuzz_regressions/):\n{}",
        failures.len(),
        out.display(),
        failures.join("\n")
    );
}

/// glTF mutants alone: none fails, and the mutator does not only make
/// broken files (a share of them loads and renders).
#[test]
fn mutants_of_gltf_files_load_and_render_or_are_rejected() {
    fuzz::quiet_panics();
    let renderers = cpu_renderers();
    let scratch = scratch_dir("gltf-mutants");
    let seeds = fuzz::gltf::seed_files();
    let (mut rendered, mut failures) = (0, Vec::new());
    let cases = 90;
    for case in 0..cases {
        let mut rng = Rng::for_item(2, case);
        let glb = fuzz::gltf::mutate_glb(&seeds[case as usize % seeds.len()], &mut rng);
        match fuzz::gltf::check_glb(&glb, &scratch, &renderers, SLOW) {
            Ok(Outcome::Rendered) => rendered += 1,
            Ok(Outcome::Rejected(_)) => {}
            Err(why) => failures.push(format!("case {case}: {why}")),
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
    assert!(rendered >= cases / 10, "{rendered} of {cases} glTF mutants rendered");
}

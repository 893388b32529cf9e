#!/usr/bin/env bash
# The bounded fuzz pass CI runs after the tests: about a minute of the
# structured scene fuzzer (mutants of the built-in scenes, loaded and
# rendered at 8x8 through photon-cpu and path), with the test executable
# that `cargo test --workspace` has already built (scripts/test-executables.sh),
# so it costs no extra compilation and needs nothing beyond Rust. The regression corpus (crates/core/tests/fuzz_regressions)
# runs in `cargo test` itself.
#
# The run is deterministic for a commit: the seed is the commit count, so
# each commit explores new mutants and any failure reproduces with
#   HIKARI_FUZZ_SEED=N scripts/fuzz-ci.sh
# Failing inputs are written to target/fuzz-failures/ (add them to the corpus).
#
# The coverage-guided loader fuzzer (libFuzzer) is for local runs: see fuzz/README.md.
set -euo pipefail
cd "$(dirname "$0")/.."

seed="${HIKARI_FUZZ_SEED:-$(git rev-list --count HEAD 2>/dev/null || echo 0)}"
target_dir="${CARGO_TARGET_DIR:-target}"
# Absolute: the test runs in crates/core.
case "$target_dir" in /*) ;; *) target_dir="$PWD/$target_dir" ;; esac
export HIKARI_FUZZ_SEED="$seed"
export HIKARI_FUZZ_SECONDS="${HIKARI_FUZZ_SECONDS:-60}"
export HIKARI_FUZZ_OUT="${HIKARI_FUZZ_OUT:-$target_dir/fuzz-failures}"
echo "fuzz-ci: structured scene fuzzer, seed $seed, ${HIKARI_FUZZ_SECONDS} s"
read -r dir exe < <(bash scripts/test-executables.sh crates/core fuzz_scenes "$@") || {
    echo "fuzz-ci: no fuzz_scenes test executable (build with cargo test first)" >&2
    exit 1
}
cd "$dir"
"$exe" --ignored --exact fuzz_for_a_while --nocapture

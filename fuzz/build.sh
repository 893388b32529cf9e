#!/usr/bin/env bash
# Builds the coverage-guided fuzz targets with libFuzzer on stable Rust:
# the same SanitizerCoverage instrumentation cargo-fuzz asks for, through
# stable `-C` flags only (no AddressSanitizer: the code under test is safe
# Rust, and panics are what we look for).
set -euo pipefail
cd "$(dirname "$0")"
export RUSTFLAGS="--cfg fuzzing -Cpasses=sancov-module \
 -Cllvm-args=-sanitizer-coverage-level=4 \
 -Cllvm-args=-sanitizer-coverage-inline-8bit-counters \
 -Cllvm-args=-sanitizer-coverage-pc-table \
 -Cllvm-args=-sanitizer-coverage-trace-compares"
# An explicit --target keeps RUSTFLAGS off build scripts and proc macros.
exec cargo build --release --target-dir target --target "$(rustc -vV | sed -n "s/^host: //p")" "$@"

#!/usr/bin/env bash
# Runs the coverage-guided scene-loader fuzzer (build it first: ./build.sh).
# Extra arguments go to libFuzzer, e.g. ./run.sh -runs=1000000 or
# ./run.sh -max_total_time=3600. The corpus grows in corpus/scene_loader
# (seeded with scenes/*.toml); crashes land in artifacts/.
set -euo pipefail
cd "$(dirname "$0")"
host=$(rustc -vV | sed -n 's/^host: //p')
mkdir -p corpus/scene_loader artifacts
cp -n ../scenes/*.toml corpus/scene_loader/
exec nice "target/$host/release/scene_loader" corpus/scene_loader \
    -dict=toml.dict -max_len=8192 -timeout=10 -rss_limit_mb=4096 \
    -artifact_prefix=artifacts/ -print_final_stats=1 "$@"

#!/usr/bin/env bash
# Runs a coverage-guided fuzzer (build them first: ./build.sh):
#   ./run.sh [scene_loader|gltf_loader] [libFuzzer arguments]
# e.g. ./run.sh -runs=1000000, or ./run.sh gltf_loader -max_total_time=3600.
# The corpus grows in corpus/TARGET (seeded with scenes/*.toml for the
# scene loader, with the glTF files of the repository for the glTF loader);
# crashes land in artifacts/.
set -euo pipefail
cd "$(dirname "$0")"
target=scene_loader
case "${1:-}" in scene_loader | gltf_loader) target=$1 && shift ;; esac
host=$(rustc -vV | sed -n 's/^host: //p')
mkdir -p "corpus/$target" artifacts
if [ "$target" = scene_loader ]; then
    cp -n ../scenes/*.toml "corpus/$target/"
    extra=(-dict=toml.dict -max_len=8192)
else
    find ../scenes ../crates/core/tests/fuzz_regressions -name '*.glb' -exec cp -n {} "corpus/$target/" \;
    extra=(-max_len=65536)
fi
exec nice "target/$host/release/$target" "corpus/$target" \
    "${extra[@]}" -timeout=10 -rss_limit_mb=4096 \
    -artifact_prefix=artifacts/ -print_final_stats=1 "$@"

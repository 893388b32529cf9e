#!/usr/bin/env bash
# Every benchmark row on a real GPU, in one short run (the device tool lends
# one for minutes): builds the release binary, then `hikari bench --large`,
# which prints one table: the seed's 512x512 rows, 1920x1080 with 1 M
# photons, photons re-traced on the CPU and on the GPU every frame, a
# moving light, and the tracing rates of both tracers (200k, 1 M and 4 M
# paths). Meant to finish in under 5 minutes on an H100/H200.
set -euo pipefail
cd "$(dirname "$0")/.."
export XDG_RUNTIME_DIR="${XDG_RUNTIME_DIR:-/tmp/xdg-$UID}"
mkdir -p "$XDG_RUNTIME_DIR"
cargo build --release --quiet
nvidia-smi --query-gpu=name,driver_version --format=csv,noheader 2>/dev/null || true
timeout 280 ./target/release/hikari bench --large --frames "${FRAMES:-20}"

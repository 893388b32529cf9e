#!/usr/bin/env bash
# Runs the whole hikari test suite on a fresh Debian 12 machine: installs what
# the machine lacks (Mesa's software Vulkan driver for the GPU tests, Xvfb
# for the viewer's window tests, Chromium for the web page's browser tests),
# builds the web page, then runs every test of the workspace. GPU tests fail, not skip, without an
# adapter; the CLI tests also run the renderer on Mesa's OpenGL.
set -euo pipefail
cd "$(dirname "$0")/.."

need=()
for pkg in mesa-vulkan-drivers libvulkan1 xvfb xauth xdotool chromium python3-venv; do
    dpkg-query -W -f='${Status}' "$pkg" 2>/dev/null | grep -q "install ok installed" || need+=("$pkg")
done
if [ ${#need[@]} -gt 0 ]; then
    echo "installing ${need[*]}"
    sudo_cmd=""
    [ "$(id -u)" -eq 0 ] || sudo_cmd="sudo"
    $sudo_cmd apt-get update -qq
    DEBIAN_FRONTEND=noninteractive $sudo_cmd apt-get install -y -qq "${need[@]}" >/dev/null
fi

# The Vulkan loader warns when XDG_RUNTIME_DIR is unset; give it a private one.
if [ -z "${XDG_RUNTIME_DIR:-}" ]; then
    export XDG_RUNTIME_DIR
    XDG_RUNTIME_DIR="$(mktemp -d)"
fi

# A one-off build gains nothing from incremental compilation but a gigabyte
# of disk.
export CARGO_INCREMENTAL="${CARGO_INCREMENTAL:-0}"

# The web page (crates/web) and its browser tests' driver (web/test):
# crates/cli/tests/web.rs opens the built page in Debian's headless Chromium.
bash scripts/web.sh build
npm ci --prefix web/test --no-audit --no-fund --silent

cargo test --workspace --locked "$@"

# The GPU tests again on Mesa's OpenGL (llvmpipe through EGL): the storage
# G-buffer, 16-bit splat sums and the media refusal (see README). The
# executables the workspace build made run again (`cargo test -p` would
# compile wgpu a second time).
echo "GPU tests on OpenGL (WGPU_BACKEND=gl)"
mapfile -t gpu_tests < <(bash scripts/test-executables.sh crates/gpu "" "$@")
if [ ${#gpu_tests[@]} -lt 2 ]; then
    echo "found no GPU test executables to run on GL" >&2
    exit 1
fi
for entry in "${gpu_tests[@]}"; do
    read -r dir exe <<<"$entry"
    echo "== $(basename "$exe") on GL"
    (cd "$dir" && WGPU_BACKEND=gl "$exe")
done

# The browser tests again in Chromium as a user's is (#43): only
# --enable-unsafe-webgpu, no SwiftShader flags. Headless, it cannot present
# a WebGPU canvas, and the page shows its frames through a 2D canvas.
echo "Browser tests in stock Chromium (HIKARI_BROWSER=stock)"
mapfile -t web_tests < <(bash scripts/test-executables.sh crates/cli web "$@")
if [ ${#web_tests[@]} -ne 1 ]; then
    echo "found no browser test executable to run again" >&2
    exit 1
fi
read -r dir exe <<<"${web_tests[0]}"
# Not yet in this configuration (#43's note): the phone-sized page, whose
# tap on the folded panel is lost in most runs there (cause not found).
(cd "$dir" && HIKARI_BROWSER=stock "$exe" --test-threads 1 --skip a_phone_sized_window_shows_the_image_and_a_folded_panel)

# One render split across a real one-node Slurm (#20): a job array of
# shards and its dependent merge, compared with the single run. Installs
# slurm-wlm and munge; skipped, loudly, only where Slurm cannot start.
bash scripts/slurm/test.sh target/debug/hikari

# The Python module (#43): its wheel, built by `pip wheel .` (what `pip
# install .` builds), installed in a fresh virtual environment, then its
# tests (python/tests), which compare pixels with the CLI built above.
echo "Python: pip wheel ., pip install and pytest"
wheel=$(bash scripts/blender.sh wheel)
venv="$(mktemp -d)/venv"
python3 -m venv "$venv"
"$venv/bin/pip" install --quiet --upgrade pip
"$venv/bin/pip" install --quiet "$wheel" "pytest>=7"
(cd python/tests && HIKARI_BIN="$PWD/../../target/debug/hikari" "$venv/bin/python" -m pytest -q .)

# The Blender add-on (#45): its zip (with that wheel inside) installed into
# Blender from PyPI (bpy 5.x on CPython 3.13), rendering against Cycles.
echo "Blender add-on: bash scripts/blender.sh test"
bash scripts/blender.sh test

# A minute of the structured scene fuzzer (new mutants for every commit).
bash scripts/fuzz-ci.sh "$@"

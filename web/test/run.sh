#!/usr/bin/env bash
# `bash scripts/web.sh test`: builds the page, installs the browser tests'
# driver, and runs the browser tests (crates/cli/tests/web.rs) alone.
set -euo pipefail
cd "$(dirname "$0")/../.."
if ! [ -x /usr/bin/chromium ]; then
    sudo_cmd=""
    [ "$(id -u)" -eq 0 ] || sudo_cmd="sudo"
    $sudo_cmd apt-get update -qq
    DEBIAN_FRONTEND=noninteractive $sudo_cmd apt-get install -y -qq chromium >/dev/null
fi
bash scripts/web.sh build
npm ci --prefix web/test --no-audit --no-fund --silent
cargo test --workspace --test web "$@"
# Again in Chromium as a user's is (see drive.mjs).
HIKARI_BROWSER=stock cargo test --workspace --test web "$@" -- --skip a_phone_sized_window_shows_the_image_and_a_folded_panel

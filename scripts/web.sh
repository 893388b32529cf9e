#!/usr/bin/env bash
# The web page (docs/web.md): `build` makes the static site in web/dist/,
# `serve [PORT]` serves it on localhost (default 8080), `test` runs the
# browser tests (headless Chromium from Debian, driven by playwright-core).
set -euo pipefail
cd "$(dirname "$0")/.."
DIST=web/dist

# The wasm-bindgen CLI must be the version of the wasm-bindgen crate in
# Cargo.lock (their ABI is private to a version).
wasm_bindgen_cli() {
    local version
    version=$(grep -A1 '^name = "wasm-bindgen"$' Cargo.lock | sed -n 's/^version = "\(.*\)"$/\1/p')
    if ! command -v wasm-bindgen >/dev/null || [ "$(wasm-bindgen --version | cut -d' ' -f2)" != "$version" ]; then
        echo "web: installing wasm-bindgen-cli $version (once)" >&2
        cargo install wasm-bindgen-cli --version "$version" --quiet
    fi
}

build() {
    rustup target list --installed 2>/dev/null | grep -qx wasm32-unknown-unknown ||
        rustup target add wasm32-unknown-unknown
    wasm_bindgen_cli
    # No debug info: it would triple the download.
    CARGO_PROFILE_RELEASE_DEBUG=false cargo build --release --target wasm32-unknown-unknown -p hikari-web
    rm -rf "$DIST"
    mkdir -p "$DIST"
    wasm-bindgen --target web --no-typescript --out-dir "$DIST" --out-name hikari_web \
        target/wasm32-unknown-unknown/release/hikari_web.wasm
    cp web/index.html "$DIST/"
    local raw gz
    raw=$(stat -c %s "$DIST/hikari_web_bg.wasm")
    gz=$(gzip -9 -c "$DIST/hikari_web_bg.wasm" | wc -c)
    echo "web: built $DIST (wasm $((raw / 1024)) KiB, $((gz / 1024)) KiB gzipped)"
}

serve() {
    local port=${1:-8080}
    [ -f "$DIST/index.html" ] || build
    echo "web: serving $DIST on http://localhost:$port/ (Ctrl-C stops)"
    exec python3 -m http.server --bind 127.0.0.1 --directory "$DIST" "$port"
}

case "${1:-}" in
    build) build ;;
    serve) shift; serve "$@" ;;
    test) shift; exec bash web/test/run.sh "$@" ;;
    *) echo "usage: bash scripts/web.sh build | serve [PORT] | test" >&2; exit 2 ;;
esac

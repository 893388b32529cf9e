#!/usr/bin/env bash
# The Blender add-on (docs/blender.md, blender/hikari_blender):
#   wheel  builds the hikari_render wheel (abi3: CPython >= 3.10, Blender's
#          3.11 and 3.13 alike) into target/wheels/
#   build  packs the add-on with that wheel inside into
#          target/blender/hikari_blender-VERSION.zip, which Blender's
#          "Install from Disk" takes (no network, no pip at install time)
#   test   builds the zip, then runs blender/tests in a CPython 3.13 virtual
#          environment with Blender from PyPI (bpy 5.x) and pytest; the
#          tests install the zip as Blender's "Install from Disk" does
set -euo pipefail
cd "$(dirname "$0")/.."
VERSION=$(sed -n 's/^version = "\(.*\)"$/\1/p' Cargo.toml | head -1)
WHEELS=target/wheels

wheel() {
    # An existing wheel of this version is kept unless its sources are newer.
    local found
    found=$(ls "$WHEELS"/hikari_render-"$VERSION"-*.whl 2>/dev/null | head -1 || true)
    if [ -n "$found" ] && [ -z "$(find crates python pyproject.toml Cargo.lock -newer "$found" -type f -print -quit)" ]; then
        echo "$found"
        return
    fi
    local venv
    venv="$(mktemp -d)/venv"
    python3 -m venv "$venv"
    "$venv/bin/pip" install --quiet --upgrade pip >&2
    rm -f "$WHEELS"/hikari_render-*.whl
    "$venv/bin/pip" wheel --quiet --no-deps -w "$WHEELS" . >&2
    ls "$WHEELS"/hikari_render-"$VERSION"-*.whl | head -1
}

build() {
    local whl stage
    whl=$(wheel)
    stage=target/blender/hikari_blender
    rm -rf "$stage"
    mkdir -p "$stage/wheels"
    cp blender/hikari_blender/*.py "$stage/"
    cp "$whl" "$stage/wheels/"
    sed "s|@VERSION@|$VERSION|; s|@WHEEL@|./wheels/$(basename "$whl")|" \
        blender/hikari_blender/blender_manifest.toml >"$stage/blender_manifest.toml"
    local zip=target/blender/hikari_blender-$VERSION.zip
    rm -f "$zip"
    (cd "$stage" && python3 -m zipfile -c "../$(basename "$zip")" ./*)
    echo "$zip"
}

# CPython 3.13, which bpy 5.x needs: on PATH, else pyenv's.
python313() {
    local candidate
    # (pyenv's shim for python3.13 is on PATH even where no 3.13 is chosen:
    # each candidate is run, not just found.)
    for candidate in python3.13 "$HOME"/.pyenv/versions/3.13*/bin/python3.13; do
        if "$candidate" -c 'import sys; assert sys.version_info[:2] == (3, 13)' >/dev/null 2>&1; then
            command -v "$candidate"
            return
        fi
    done
    echo "blender tests: no CPython 3.13 (bpy 5.x needs it): install it, e.g. pyenv install 3.13" >&2
    return 1
}

test() {
    local zip py venv home
    zip=$(build)
    py=$(python313)
    venv="$(mktemp -d)/bpy"
    "$py" -m venv "$venv"
    "$venv/bin/pip" install --quiet --upgrade pip
    # No hikari_render here: the tests install the zip, and its wheel with it.
    "$venv/bin/pip" install --quiet "bpy>=5.0,<6" "pytest>=7" OpenEXR
    # A throwaway Blender user folder for the installed add-on.
    home=$(mktemp -d)
    (cd blender/tests && HOME="$home" HIKARI_BLENDER_ZIP="$PWD/../../$zip" "$venv/bin/python" -m pytest -q "$@" .)
}

case "${1:-}" in
    wheel) wheel ;;
    build) build ;;
    test) shift; test "$@" ;;
    *) echo "usage: bash scripts/blender.sh wheel|build|test [pytest args]" >&2; exit 2 ;;
esac

#!/usr/bin/env bash
# Prints "<package dir> <executable>" for each test executable of the
# workspace's `cargo test` build, optionally only those of one package
# directory (e.g. crates/gpu) and one test target name (e.g. fuzz_scenes).
#
# Why: `cargo test -p PACKAGE` resolves features for that package alone, so
# it compiles wgpu and its dependencies a second time next to the workspace
# build (twice the disk; a CI machine ran out). Running the executables the
# workspace build already made reuses them. Extra arguments after the two
# filters go to cargo (e.g. --release), and must match the build's.
set -euo pipefail
cd "$(dirname "$0")/.."

package_dir="${1:-}"
target_name="${2:-}"
shift $(( $# > 2 ? 2 : $# ))

root="$PWD"
cargo test --workspace --locked --no-run --message-format=json "$@" 2>/dev/null \
    | grep '"reason":"compiler-artifact"' \
    | grep '"test":true' \
    | grep -v '"executable":null' \
    | while IFS= read -r line; do
        manifest="$(sed -n 's/.*"manifest_path":"\([^"]*\)".*/\1/p' <<<"$line")"
        name="$(sed -n 's/.*"target":{[^}]*"name":"\([^"]*\)".*/\1/p' <<<"$line")"
        exe="$(sed -n 's/.*"executable":"\([^"]*\)".*/\1/p' <<<"$line")"
        dir="$(dirname "${manifest#"$root"/}")"
        [ -z "$package_dir" ] || [ "$dir" = "$package_dir" ] || continue
        [ -z "$target_name" ] || [ "$name" = "$target_name" ] || continue
        echo "$dir $exe"
    done

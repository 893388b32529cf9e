#!/usr/bin/env bash
# Side by side: `hikari bench` built from REV against the working tree, on
# this machine, one right after the other, then each row's time ratio
# (working tree / REV), the worst first, and their geometric mean.
#
#   bash scripts/bench-compare.sh REV [BENCH ARGS...]     (default: --frames 3)
#
# REV is built in its own worktree (target/bench-compare/REV) with its own
# target directory, so neither build disturbs the other. Tracing rates
# (million paths per second) count as times through their inverse. Run it
# twice before trusting a single row: on a 2-core VM rows swing by a third.
# Use it before landing any change to a renderer or a shader.
set -euo pipefail
cd "$(dirname "$0")/.."
[ $# -ge 1 ] || { sed -n 2,12p "$0"; exit 2; }
rev="$1"
shift
args=("$@")
[ ${#args[@]} -gt 0 ] || args=(--frames 3)

root="$PWD"
sha="$(git rev-parse --short "$rev^{commit}")"
work="$root/target/bench-compare/$sha"
if [ ! -d "$work/src" ]; then
    mkdir -p "$work"
    git worktree add --detach "$work/src" "$sha" >/dev/null
fi
export XDG_RUNTIME_DIR="${XDG_RUNTIME_DIR:-$(mktemp -d)}"
echo "building $sha and the working tree (release)"
(cd "$work/src" && CARGO_TARGET_DIR="$work/target" cargo build --release --quiet -p hikari-cli)
cargo build --release --quiet -p hikari-cli

out="$root/target/bench-compare"
echo "bench of $sha: ${args[*]}"
"$work/target/release/hikari" bench "${args[@]}" | tee "$out/before.txt"
echo "bench of the working tree: ${args[*]}"
./target/release/hikari bench "${args[@]}" | tee "$out/after.txt"
python3 "$root/scripts/bench_ratio.py" "$out/before.txt" "$out/after.txt" "$sha"

#!/usr/bin/env bash
# Where a path tracer's sample goes, counted rather than timed: the
# instructions and mispredicted branches per path (Valgrind's cachegrind with
# its branch simulator), in total and per function. Counts are the same from
# run to run, where wall time on a shared VM varies 10–25%, so a change of 2%
# is visible (#19 item 2, BENCHMARKS.md "Counted, not timed").
#
# Cycles are estimated as instructions / 3 + 17 × mispredicts (IPC ≈ 3 and
# a mispredict's ≈ 17 cycles): a rough model, as the VM has no hardware
# counters to check it against. Valgrind's CPU has no AVX-512, which hikari
# does not use; its branch predictor is simpler than a real one, so read
# its mispredicts as a comparison between builds.
#
#   bash scripts/count-path.sh                        # cornell-box, target/release/hikari
#   bash scripts/count-path.sh scenes/showcase.glb /tmp/hikari-before
#
# Needs `valgrind` (Debian's package); not run in CI.
set -euo pipefail
SCENE=${1:-cornell-box}
BIN=${2:-target/release/hikari}
SIZE=${SIZE:-128}
SPP=${SPP:-16}
TOP=${TOP:-12}
command -v valgrind >/dev/null || { echo "count-path.sh: needs valgrind (apt install valgrind)" >&2; exit 1; }
[ -x "$BIN" ] || { echo "count-path.sh: $BIN: no such executable (cargo build --release)" >&2; exit 1; }
OUT=$(mktemp -d)
trap 'rm -rf "$OUT"' EXIT
valgrind --tool=cachegrind --branch-sim=yes --cache-sim=no --cachegrind-out-file="$OUT/counts" \
    "$BIN" render "$SCENE" --renderer path --spp "$SPP" --passes 1 --resolution "${SIZE}x${SIZE}" --threads 1 \
    --output "$OUT/image.png" -q 2>"$OUT/log" || { cat "$OUT/log" >&2; exit 1; }
python3 - "$OUT/counts" $((SIZE * SIZE * SPP)) "$TOP" "$SCENE" <<'EOF'
import collections, sys
path, paths, top, scene = sys.argv[1], int(sys.argv[2]), int(sys.argv[3]), sys.argv[4]
events, per_function, function = [], {}, None
for line in open(path):
    if line.startswith("events:"):
        events = line.split()[1:]
    elif line.startswith("fn="):
        function = line[3:].strip()
        per_function.setdefault(function, [0] * len(events))
    elif line[:1].isdigit():
        # A line number, then the counts of each event (trailing zeros left out).
        for i, count in enumerate(line.split()[1:]):
            per_function[function][i] += int(count)
ir, bcm, bim = events.index("Ir"), events.index("Bcm"), events.index("Bim")
total = [sum(v[i] for v in per_function.values()) for i in range(len(events))]
instructions, mispredicts = total[ir] / paths, (total[bcm] + total[bim]) / paths
print(f"{scene}: {paths} paths; per path {instructions:.0f} instructions, {mispredicts:.2f} mispredicted "
      f"branches, about {instructions / 3 + 17 * mispredicts:.0f} cycles")
print("| share of instructions | instructions a path | mispredicts a path | function |")
print("| --- | --- | --- | --- |")
for name, v in sorted(per_function.items(), key=lambda kv: -kv[1][ir])[:top]:
    print(f"| {100 * v[ir] / total[ir]:.1f}% | {v[ir] / paths:.0f} | {(v[bcm] + v[bim]) / paths:.2f} | `{name[:90]}` |")
EOF

#!/usr/bin/env bash
# Error against time (docs/progressive.md): the error (relRMSE, relative to
# the reference's mean, as shared/relerr.py) of progressive photon-cpu, the
# GPU renderer, vertex connection and merging and the path tracer against a long
# path-traced reference, printed at every checkpoint, for each scene, and
# drawn as one chart per scene ($OUT/SCENE-error.png, `hikari plot`). The
# references are made once (kept in $OUT, out of the repository).
#
#   bash scripts/error-curves.sh            # defaults below
#   TIME=120 SIZE=256x256 bash scripts/error-curves.sh
set -euo pipefail
cd "$(dirname "$0")/.."
cargo build --release --locked -q
H=target/release/hikari
OUT=${OUT:-target/error-curves}
SIZE=${SIZE:-96x96}
REF_SPP=${REF_SPP:-16384}
TIME=${TIME:-30}
CHECK=${CHECK:-5}
PHOTONS=${PHOTONS:-100000}
mkdir -p "$OUT"
for scene in ${SCENES:-cornell-box cornell-caustic fog-stage}; do
    ref="$OUT/$scene-$SIZE-ref.exr"
    if [ ! -f "$ref" ]; then
        start=$(date +%s)
        "$H" render "$scene" --resolution "$SIZE" --renderer path --spp "$REF_SPP" --seed 12345 -q -o "$ref"
        echo "$scene: reference, $REF_SPP spp path tracing, $(( $(date +%s) - start )) s"
    fi
    curves="$OUT/$scene-$SIZE-curves.txt"
    : > "$curves"
    for renderer in ${RENDERERS:-photon-cpu gpu vcm path}; do
        extra=()
        [ "$renderer" = path ] && extra=(--spp 16)
        "$H" render "$scene" --resolution "$SIZE" --renderer "$renderer" --photons "$PHOTONS" \
            --time "$TIME" --checkpoint "$CHECK" --reference "$ref" -q -o "$OUT/$scene-$renderer.exr" "${extra[@]}" \
            2> "$OUT/$scene-$renderer.log" | sed "s/^/$renderer: /" | tee -a "$curves" | sed "s/^/$scene /" \
            || echo "$scene $renderer: did not render ($(tail -1 "$OUT/$scene-$renderer.log"))"
    done
    "$H" plot "$curves" --title "$scene, $SIZE, $(nproc) cores" -o "$OUT/$scene-error.png" || true
done

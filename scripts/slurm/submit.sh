#!/usr/bin/env bash
# Submits one hikari render to Slurm as a job array of shards and its merge
# as a dependent job (docs/cluster.md):
#
#   bash scripts/slurm/submit.sh SHARDS PASSES SCENE OUT [hikari render flags…]
#
# e.g. bash scripts/slurm/submit.sh 16 256 /shared/scene.glb /shared/out --renderer path
# The image is OUT/image.exr (IMAGE to change it). HIKARI names the binary
# [hikari on PATH]; sbatch's own options come from its environment
# variables (SBATCH_PARTITION, SBATCH_TIMELIMIT, SBATCH_GRES=gpu:1, …).
# Prints the two job ids.
set -euo pipefail
if [ $# -lt 4 ]; then
    sed -n '2,12p' "$0" >&2
    exit 2
fi
here="$(cd "$(dirname "$0")" && pwd)"
export SHARDS=$1 PASSES=$2 SCENE=$3 OUT=$4
shift 4
HIKARI_FLAGS="$*"
export HIKARI_FLAGS HIKARI="${HIKARI:-hikari}"
mkdir -p "$OUT"
shards=$(sbatch --parsable --chdir="$OUT" --array="1-$SHARDS" "$here/render.sbatch")
merge=$(sbatch --parsable --chdir="$OUT" --dependency="afterok:$shards" "$here/merge.sbatch")
echo "$shards $merge"

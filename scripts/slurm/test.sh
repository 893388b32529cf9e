#!/usr/bin/env bash
# The one-node Slurm test (#20): installs Debian's slurm-wlm and munge where
# missing, starts munged, slurmctld and slurmd on this machine (no systemd,
# everything under a temporary directory, private ports), submits a 4-shard
# job array with its dependent merge (scripts/slurm/submit.sh), checks that
# the merged image is the single run's byte for byte, then deletes a part,
# checks that the merge refuses the incomplete set and names the missing
# shard, re-submits that shard alone and checks the completed merge. Stops
# every daemon and removes its files on the way out.
#
#   bash scripts/slurm/test.sh [path/to/hikari]   (default target/debug/hikari)
#
# Where Slurm cannot start (not root and no sudo, no apt, a daemon that
# will not come up) it says so loudly and exits 0; once it is up, any
# failure fails the test.
set -euo pipefail
cd "$(dirname "$0")/../.."
HIKARI=$(realpath "${1:-target/debug/hikari}")
[ -x "$HIKARI" ] || { echo "no hikari binary at $HIKARI (cargo build first)" >&2; exit 1; }

skip() {
    echo
    echo "######## SLURM TEST SKIPPED: Slurm could not start here: $* ########"
    echo
    exit 0
}

sudo_cmd=""
if [ "$(id -u)" -ne 0 ]; then
    sudo -n true 2>/dev/null || skip "the daemons need root, and this user is not root and has no password-less sudo"
    sudo_cmd="sudo -n"
fi
need=()
for pkg in slurm-wlm munge; do
    dpkg-query -W -f='${Status}' "$pkg" 2>/dev/null | grep -q "install ok installed" || need+=("$pkg")
done
if [ ${#need[@]} -gt 0 ]; then
    echo "installing ${need[*]}"
    { $sudo_cmd apt-get update -qq && DEBIAN_FRONTEND=noninteractive $sudo_cmd apt-get install -y -qq "${need[@]}" >/dev/null; } ||
        skip "apt-get could not install ${need[*]}"
fi

T=$(mktemp -d /tmp/hikari-slurm.XXXXXX)
chmod 755 "$T"
cleanup() {
    for pid in "$T"/slurmd.pid "$T"/slurmctld.pid "$T"/munge/munged.pid; do
        [ -s "$pid" ] && $sudo_cmd kill "$(cat "$pid")" 2>/dev/null || true
    done
    sleep 1
    $sudo_cmd rm -rf "$T"
}
trap cleanup EXIT

# munge: a fresh key and a private socket.
mkdir -p "$T/munge" "$T/state" "$T/spool" "$T/out"
chmod 700 "$T/munge"
$sudo_cmd mungekey -c -k "$T/munge/munge.key" || skip "mungekey could not make a key"
$sudo_cmd munged --force --key-file="$T/munge/munge.key" --socket="$T/munge/munge.socket" \
    --pid-file="$T/munge/munged.pid" --log-file="$T/munge/munged.log" --seed-file="$T/munge/seed" ||
    skip "munged would not start: $(tail -3 "$T/munge/munged.log" 2>/dev/null)"

host=$(hostname -s)
# Ports away from a real Slurm's 6817/6818, different for each run.
port=$((20000 + RANDOM % 20000))
cat >"$T/slurm.conf" <<CONF
ClusterName=hikari-test
SlurmctldHost=$host
SlurmctldPort=$port
SlurmdPort=$((port + 1))
AuthType=auth/munge
AuthInfo=socket=$T/munge/munge.socket
CredType=cred/munge
SlurmUser=root
SlurmdUser=root
StateSaveLocation=$T/state
SlurmdSpoolDir=$T/spool
SlurmctldPidFile=$T/slurmctld.pid
SlurmdPidFile=$T/slurmd.pid
SlurmctldLogFile=$T/slurmctld.log
SlurmdLogFile=$T/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
JobCompType=jobcomp/none
SelectType=select/cons_tres
SelectTypeParameters=CR_CPU
MpiDefault=none
ReturnToService=2
NodeName=$host CPUs=$(nproc) State=UNKNOWN
PartitionName=test Nodes=$host Default=YES MaxTime=INFINITE State=UP
CONF
export SLURM_CONF="$T/slurm.conf"
$sudo_cmd env SLURM_CONF="$SLURM_CONF" slurmctld -c || skip "slurmctld would not start: $(tail -3 "$T/slurmctld.log" 2>/dev/null)"
$sudo_cmd env SLURM_CONF="$SLURM_CONF" slurmd || skip "slurmd would not start: $(tail -3 "$T/slurmd.log" 2>/dev/null)"
for _ in $(seq 60); do
    sinfo -h -o %t 2>/dev/null | grep -qx idle && break
    sleep 0.5
done
sinfo -h -o %t 2>/dev/null | grep -qx idle ||
    skip "the node never came up idle: $(sinfo 2>&1 | tail -1); $(tail -2 "$T/slurmd.log" 2>/dev/null)"
echo "one-node Slurm up on $host (port $port)"

# The render: 8 passes of a small Cornell box, path traced, in 4 shards.
flags=(--renderer path --resolution 24x24 --spp 2)
out="$T/out"
read -r shards merge < <(HIKARI="$HIKARI" bash scripts/slurm/submit.sh 4 8 cornell-box "$out" "${flags[@]}")
echo "submitted: shards job $shards (array 1-4), merge job $merge"
wait_for() {
    for _ in $(seq 240); do
        [ -z "$(squeue -h -j "$1" 2>/dev/null)" ] && return 0
        sleep 0.5
    done
    echo "FAILED: job $1 did not finish in 2 minutes" >&2
    squeue >&2
    tail -n +1 "$out"/*.log >&2 || true
    return 1
}
wait_for "$shards"
if [ -n "$(squeue -h -j "$merge" -t PD -r 2>/dev/null | grep -i never)" ]; then
    echo "FAILED: a shard failed, so the merge will never run" >&2
    tail -n +1 "$out"/*.log >&2 || true
    exit 1
fi
wait_for "$merge"
"$HIKARI" render cornell-box "${flags[@]}" --passes 8 -q -o "$T/single.exr"
if ! cmp "$out/image.exr" "$T/single.exr"; then
    echo "FAILED: the merged image differs from the single run's" >&2
    tail -n +1 "$out"/*.log >&2 || true
    exit 1
fi
echo "the 4-shard job array's merge is the single run's image, byte for byte"

# A lost part: the merge refuses and names it; re-running that shard alone completes the set.
rm "$out/part-3-of-4.exr" "$out/image.exr"
export HIKARI OUT="$out" SHARDS=4 PASSES=8 SCENE=cornell-box HIKARI_FLAGS="${flags[*]}"
if sbatch --wait --chdir="$out" --output="$out/incomplete.log" scripts/slurm/merge.sbatch >/dev/null; then
    echo "FAILED: the merge of an incomplete set succeeded" >&2
    exit 1
fi
grep -q "shard 3/4 missing" "$out/incomplete.log" || { echo "FAILED: the merge did not name shard 3/4:" >&2; cat "$out/incomplete.log" >&2; exit 1; }
[ ! -e "$out/image.exr" ] || { echo "FAILED: the refused merge wrote an image" >&2; exit 1; }
rerun=$(sbatch --parsable --chdir="$out" --array=3 scripts/slurm/render.sbatch)
sbatch --wait --chdir="$out" --dependency="afterok:$rerun" scripts/slurm/merge.sbatch >/dev/null
cmp "$out/image.exr" "$T/single.exr" || { echo "FAILED: the completed merge differs from the single run" >&2; exit 1; }
echo "a lost part was named by the merge, re-rendered alone, and the merge completed: Slurm test passed"

#!/bin/bash
# The sweep job scripts on a real (one-node) Slurm cluster, as .ci/run runs
# them: a grid sweep (EEG decoders) and an e-puck sweep, each submitted with
# submit.sh as 4 shards, must merge to the bytes of the same sweep run
# unsharded; no shard may search the targeting again; and an e-puck shard
# cancelled mid-way and resubmitted alone must change nothing.
#
#   scripts/slurm/test.sh [--install] ERRP   (as root; starts and stops the cluster)
#
# --install first installs Slurm 22.05 and munge with apt-get
# (scripts/slurm/cluster.sh install); without it, Slurm must be installed.
case "${1:-}" in
  -h | --help) awk 'NR > 1 && /^#SBATCH/ { exit } NR > 1 && /^#/ { sub(/^# ?/, ""); print; next } NR > 1 { exit }' "$0"; exit 0 ;;
esac
set -euo pipefail
cd "$(dirname "$0")/../.."
install=false
if [ "${1:-}" = --install ]; then install=true; shift; fi
if [ $# -ne 1 ] || [ ! -x "$1" ]; then
  echo "usage: scripts/slurm/test.sh [--install] ERRP (ERRP: an executable errp program; got ${1:-nothing})" >&2
  exit 2
fi
errp=$(realpath "$1")
here=scripts/slurm
work=$(mktemp -d /tmp/errp-slurm-test.XXXXXX)
export ERRP_SLURM_DIR=$work/cluster SLURM_CONF=$work/cluster/etc/slurm.conf
say() { echo "[slurm test $(date +%T)] $*" >&2; }
cleanup() {
  "$here/cluster.sh" down || true
  rm -rf "$work"
}
if $install; then
  "$here/cluster.sh" install
elif ! command -v slurmctld >/dev/null || ! command -v sbatch >/dev/null; then
  echo "test.sh: Slurm is not installed: pass --install to install it with apt-get (as root)" >&2
  exit 2
fi
"$here/cluster.sh" up
trap cleanup EXIT

# Every job on one CPU, so that two shards run at once on two cores.
opts=(--cpus-per-task=1 --output="$work/logs/%x-%j.out")
mkdir -p "$work/logs"

same() { # same DIR_A DIR_B: the files of a finished sweep, byte for byte
  for f in episodes.csv summary.csv sweep.json sweep.svg sweep.png; do
    cmp "$1/$f" "$2/$f" || { say "$f differs between $1 and $2"; return 1; }
  done
}

all_cached() { # all_cached NAME: every decoder line of every shard log was a cache hit
  local shards lines hits
  mapfile -t shards < <(grep -l "Sweeping .*, shard [0-9]*/4" "$work"/logs/*)
  lines=$(cat "${shards[@]}" | grep -c '  decoder [0-9]*/[0-9]*: accuracy' || true)
  hits=$(cat "${shards[@]}" | grep '  decoder [0-9]*/[0-9]*: accuracy' | grep -c 'targeting cached' || true)
  say "$1: ${#shards[@]} shard logs, $hits of their $lines decoder lines came from the cache"
  [ "${#shards[@]}" = 4 ] && [ "$lines" -gt 0 ] && [ "$hits" = "$lines" ]
}

sweep() { # sweep NAME ARGS: unsharded here, then 4 shards through Slurm
  local name=$1 args=$2
  say "$name: unsharded reference"
  # shellcheck disable=SC2086
  "$errp" sweep $args --no-cache --quiet --threads 2 --out "$work/$name/whole" > /dev/null
  say "$name: prepare -> 4 shards -> merge, through sbatch"
  rm -f "$work"/logs/*
  SWEEP_DIR=$work/$name/slurm SWEEP_ARGS=$args ERRP=$errp \
    "$here/submit.sh" 4 --wait "${opts[@]}" > /dev/null
  grep -h "Prepared" "$work"/logs/* >&2
  same "$work/$name/whole" "$work/$name/slurm/merged"
  all_cached "$name"
  say "$name: merged = unsharded"
}

sweep grid "--task grid --accuracy 0.65,0.75,0.85 --episodes 60 --seed 3"
sweep epuck "--task epuck --accuracy 0.8,0.95 --episodes 24 --seed 3"

# A shard cancelled mid-way (scancel: SIGTERM, rows so far kept), the merge
# cancelled with it (its dependency failed), then the shard resubmitted
# alone and the merge again.
name=epuck-cancel
args="--task epuck --accuracy 0.8,0.95 --episodes 100 --seed 5"
say "$name: unsharded reference"
# shellcheck disable=SC2086
"$errp" sweep $args --no-cache --quiet --threads 2 --out "$work/$name/whole" > /dev/null
dir=$work/$name/slurm
rm -f "$work"/logs/*
read -r prepare array merge < <(SWEEP_DIR=$dir SWEEP_ARGS=$args ERRP=$errp \
  "$here/submit.sh" 4 "${opts[@]}")
rows() { [ -f "$1" ] && echo $(( $(wc -l < "$1") - 1 )) || echo 0; }
for _ in $(seq 1200); do
  [ "$(rows "$dir/shard-3/episodes.csv")" -ge 3 ] && break
  sleep 0.1
done
scancel "${array}_3"
say "$name: cancelled shard 3 (job ${array}_3) with $(rows "$dir/shard-3/episodes.csv") of 50 rows on disk"
for _ in $(seq 300); do
  squeue -h -j "$array,$merge" 2> /dev/null | grep -q . || break
  sleep 0.2
done
state=$(scontrol show job "$merge" 2> /dev/null | sed -n 's/.*JobState=\([A-Z_]*\).*/\1/p')
say "$name: the merge job $merge is ${state:-gone}"
[ ! -e "$dir/merged" ] || { say "a merge ran without shard 3"; exit 1; }
done_rows=$(rows "$dir/shard-3/episodes.csv")
[ "$done_rows" -lt 50 ] || { say "shard 3 finished before it was cancelled"; exit 1; }
[ ! -e "$dir/shard-3/sweep.lock" ] || { say "the cancelled shard left its lock"; exit 1; }
say "$name: resubmitting shard 3 alone, then the merge"
SWEEP_DIR=$dir SWEEP_ARGS=$args ERRP=$errp \
  sbatch --wait --array=3 "${opts[@]}" "$here/sweep.sbatch" shard 4 > /dev/null
SWEEP_DIR=$dir SWEEP_ARGS=$args ERRP=$errp \
  sbatch --wait "${opts[@]}" "$here/sweep.sbatch" merge 4 > /dev/null
same "$work/$name/whole" "$dir/merged"
say "$name: merged after cancel + resubmit = unsharded"
# Two hosts, one pid: two errp processes, each pid 1 in a PID namespace of
# its own and on a host of its own name (UTS namespace), fill one targeting
# cache at the same moment, as two nodes with a shared file system may. The
# temporaries are named by host, pid and a random suffix and created
# exclusively, so neither can clobber the other: both succeed and every
# entry is whole.
cache=$work/two-hosts-cache
say "two hosts with the same pid write one cache"
for host in node-a node-b; do
  unshare --pid --fork --mount-proc --uts sh -c \
    "hostname $host && exec \"$errp\" sweep --task grid --accuracy 0.7,0.8 --seed 9 \
       --prepare-only --cache \"$cache\"" > "$work/$host.log" 2>&1 &
done
wait
grep -h "Prepared" "$work"/node-*.log >&2
entries=$(find "$cache" -name 'grid-lda-online-*.json' | wc -l)
partials=$(find "$cache" -name '.*partial*' | wc -l)
[ "$entries" = 2 ] && [ "$partials" = 0 ] || { say "cache: $entries entries, $partials partials"; exit 1; }
python3 -c 'import json, sys
for p in sys.argv[1:]:
    e = json.load(open(p))
    assert e["request"].startswith("grid-lda-online v1 ") and e["result"]["ratio"] > 0, p' "$cache"/grid-lda-online-*.json
"$errp" sweep --task grid --accuracy 0.7,0.8 --seed 9 --prepare-only --cache "$cache" \
  | grep -q "(0 searched now, 2 already cached)"
say "two hosts, one pid: both prepared, 2 whole entries, read back as cache hits"
say "all Slurm checks passed"

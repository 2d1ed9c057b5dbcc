#!/bin/bash
# Submits an errp sweep to Slurm as three chained jobs: the preparation of
# every level's decoder, the array of N shards after it (afterok), and the
# merge after the whole array (afterok). See sweep.sbatch for what is swept
# (SWEEP_ARGS, SWEEP_DIR, ERRP, ERRP_CACHE_DIR) and the resources.
#
#   scripts/slurm/submit.sh N [--wait] [extra sbatch options...]
#
# --wait returns when the merge has ended, with its exit code (a failed
# shard cancels the merge: resubmit that shard, then the merge, as printed).
# Prints the three job ids on one line ("prepare array merge") on stdout.
case "${1:-}" in
  -h | --help) awk 'NR > 1 && /^#SBATCH/ { exit } NR > 1 && /^#/ { sub(/^# ?/, ""); print; next } NR > 1 { exit }' "$0"; exit 0 ;;
esac
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
if [ $# -lt 1 ]; then
  echo "usage: scripts/slurm/submit.sh N [--wait] [sbatch options...] (N: the number of shards)" >&2
  exit 2
fi
shards=$1
shift
[[ "$shards" =~ ^[1-9][0-9]*$ ]] || { echo "submit.sh: N must be a number of shards >= 1, not $shards" >&2; exit 2; }
wait=()
if [ "${1:-}" = --wait ]; then wait=(--wait); shift; fi
job="$here/sweep.sbatch"
prepare=$(sbatch --parsable "$@" "$job" prepare)
array=$(sbatch --parsable "$@" --dependency=afterok:"$prepare" --array=1-"$shards" "$job" shard "$shards")
echo "submitted: prepare $prepare, shards $array (1-$shards), then the merge" >&2
echo "if shard K fails: sbatch --array=K $job shard $shards; then sbatch $job merge $shards" >&2
if [ ${#wait[@]} -eq 0 ]; then
  merge=$(sbatch --parsable "$@" --cpus-per-task=1 --dependency=afterok:"$array" "$job" merge "$shards")
  echo "$prepare $array $merge"
else
  status=0
  merge=$(sbatch --parsable --wait "$@" --cpus-per-task=1 --dependency=afterok:"$array" \
    "$job" merge "$shards") || status=$?
  echo "$prepare $array $merge"
  exit "$status"
fi

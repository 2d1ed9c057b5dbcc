#!/usr/bin/env bash
# Golden outputs for restructurings: runs a fixed set of `errp` commands and
# records what they print and write, so that a change that should keep
# behaviour can show the same bytes before and after.
#
#   scripts/golden.sh record DIR        run the commands into DIR (built first)
#   scripts/golden.sh compare DIR1 DIR2 same bytes? (recordings: the same
#                                       rows, by scripts/rrd_digest.py, when
#                                       `python` has rerun-sdk: Rerun's ids,
#                                       wall-clock times and chunking differ
#                                       per run)
#
# Every command is seeded; the cache is off, so each run targets afresh.
# The scenarios are the idealised user's (scenarios/variants/*_ideal.toml:
# the shipped scenarios without their [realism] table), so that what a
# change of the simulated user moves is kept out of a restructuring's
# comparison.
case "${1:-}" in
  -h | --help) awk 'NR > 1 && /^#SBATCH/ { exit } NR > 1 && /^#/ { sub(/^# ?/, ""); print; next } NR > 1 { exit }' "$0"; exit 0 ;;
esac
set -euo pipefail
cd "$(dirname "$0")/.."

record() {
  local out=$1
  mkdir -p "$out"
  cargo build --locked --quiet
  local errp=target/debug/errp
  # Rerun's batcher flushes on a timer, so chunk boundaries follow the wall
  # clock; flushing on size alone makes recordings comparable.
  export RERUN_FLUSH_TICK_SECS=1000000
  local n=0
  run() { # run NAME ARGS...: stdout to NAME.txt
    local name=$1
    shift
    n=$((n + 1))
    printf '  %2d %s\n' "$n" "$name" >&2
    "$errp" "$@" > "$out/$name.txt"
  }
  run calibrate calibrate --accuracy 0.7438 --seed 1 --quiet \
    --save "$out/calib.rrd" --export "$out/calib.edf"
  run grid run scenarios/variants/grid_fixed_goals_ideal.toml --seed 1 --quiet --save "$out/grid.rrd"
  run epuck run scenarios/variants/mexico_to_pisa_ideal.toml --seed 1 --quiet --save "$out/epuck.rrd"
  run epuck-20 run scenarios/variants/mexico_to_pisa_ideal.toml --runs 20 --quiet
  run lisbon run scenarios/variants/lisbon_to_tokyo_ideal.toml --runs 3 --seed 2 --quiet
  run grid-free run scenarios/variants/grid_free_goals_ideal.toml --seed 2 --quiet
  run table1 table1 --seed 1 --realism scenarios/variants/grid_fixed_goals_ideal.toml --quiet
  run sweep-grid sweep --scenario scenarios/variants/grid_fixed_goals_ideal.toml --accuracy 0.6,0.8 --param strategy=greedy,info_gain \
    --episodes 40 --seed 1 --no-cache --quiet --out "$out/sweep-grid"
  run sweep-epuck sweep --scenario scenarios/variants/mexico_to_pisa_ideal.toml --accuracy 0.8,0.95 --episodes 6 --seed 1 \
    --no-cache --quiet --out "$out/sweep-epuck"
  for k in 1 2; do
    run "shard-$k" sweep --scenario scenarios/variants/grid_fixed_goals_ideal.toml --accuracy 0.6,0.8 --episodes 40 --seed 1 --no-cache \
      --quiet --shard "$k/2" --out "$out/shard-$k"
  done
  run merge merge "$out/shard-1" "$out/shard-2" --out "$out/merged"
  # The merge prints its output paths: make them relative.
  sed -i "s#$out/##g" "$out"/*.txt
  (cd "$out" && find . -type f ! -name '*.rrd' ! -name SHA256SUMS | LC_ALL=C sort |
    xargs sha256sum > SHA256SUMS)
  echo "recorded $(wc -l < "$out/SHA256SUMS") files in $out" >&2
}

compare() {
  local a=$1 b=$2 status=0
  if ! diff <(cut -c67- "$a/SHA256SUMS") <(cut -c67- "$b/SHA256SUMS") > /dev/null; then
    echo "different file lists" >&2
    status=1
  fi
  while read -r sum file; do
    if ! grep -q "^$sum  $file\$" "$b/SHA256SUMS"; then
      echo "differs: $file" >&2
      status=1
    fi
  done < "$a/SHA256SUMS"
  for rrd in "$a"/*.rrd; do
    local name
    name=$(basename "$rrd")
    if python -c 'import rerun' 2> /dev/null; then
      if [ "$(python scripts/rrd_digest.py "$rrd")" != "$(python scripts/rrd_digest.py "$b/$name")" ]; then
        echo "differs: $name (scripts/rrd_digest.py)" >&2
        status=1
      fi
    else
      echo "skipped: $name (no python with rerun-sdk on PATH)" >&2
    fi
  done
  if [ "$status" = 0 ]; then
    echo "same: $(wc -l < "$a/SHA256SUMS") files and $(ls "$a"/*.rrd | wc -l) recordings" >&2
  fi
  return "$status"
}

case "${1:-}" in
  record) record "$2" ;;
  compare) compare "$2" "$3" ;;
  *)
    echo "usage: scripts/golden.sh record DIR | compare DIR1 DIR2" >&2
    exit 2
    ;;
esac

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
  local errp=${ERRP:-target/debug/errp}
  if [ -z "${ERRP:-}" ]; then
    cargo build --locked --quiet
  fi
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
  # Recordings read back: the tables recomputed and the tidy export.
  run inspect-grid inspect "$out/grid.rrd"
  run inspect-epuck inspect "$out/epuck.rrd" --csv "$out/inspect-epuck"
  # A person's own EEG (an export of a calibration session at 78 %): the
  # grid on it, the e-puck on its hybrid, and a sweep over two of them.
  run own-export calibrate --accuracy 0.78 --seed 1 --quiet --export "$out/s01.edf"
  run own-export-2 calibrate --accuracy 0.7 --seed 2 --quiet --export "$out/s02.edf"
  cp scenarios/recorded/own_eeg.toml scenarios/recorded/own_eeg_epuck.toml "$out/"
  run own-grid run "$out/own_eeg.toml" --quiet --save "$out/own-grid.rrd"
  run own-epuck run "$out/own_eeg_epuck.toml" --runs 2 --quiet
  run sweep-own sweep --scenario "$out/own_eeg.toml" --param "eeg.recording=s01.edf,s02.edf" \
    --episodes 10 --seed 1 --no-cache --quiet --out "$out/sweep-own"
  # What bad input is told: the message and the exit code, for each rule on
  # how a scenario's values combine, from each entry (flag, file key, sweep
  # level, stream option).
  fails() { # fails NAME ARGS...: stderr and the exit code to NAME.err
    local name=$1 code=0
    shift
    n=$((n + 1))
    printf '  %2d %s (refused)\n' "$n" "$name" >&2
    "$errp" "$@" > /dev/null 2> "$out/$name.err" || code=$?
    echo "exit $code" >> "$out/$name.err"
  }
  printf 'task = "grid"\nname = "x"\n[user]\naccuracy = 1.0\n' > "$out/perfect.toml"
  printf 'task = "grid"\nname = "x"\ndecoder = "oracle"\n[user]\naccuracy = 1.0\n' > "$out/oracle.toml"
  printf '[user]\naccuracy = 0.8\n' | cat "$out/own_eeg.toml" - > "$out/own_acc.toml"
  sed 's/^seed = 41/seed = 41\nbank_per_class = 100/' "$out/own_eeg.toml" > "$out/own_bank.toml"
  sed 's/^seed = 41/seed = 41\ndecoder = "oracle"/' "$out/own_eeg.toml" > "$out/own_oracle.toml"
  sed 's/^seed = 3$/seed = 3\naccuracy = 0.8/' "$out/own_eeg_epuck.toml" > "$out/own_epuck_acc.toml"
  sed 's/^task_latency_ms = .*/task_latency_ms = nan/' scenarios/mexico_to_pisa.toml > "$out/latency_nan.toml"
  fails bad-perfect-flag run scenarios/grid_fixed_goals.toml --accuracy 1
  fails bad-perfect-file run "$out/perfect.toml"
  fails bad-perfect-sweep sweep --task grid --accuracy 1 --episodes 2 --no-cache --out "$out/bad-sweep-1"
  fails bad-perfect-epuck run scenarios/mexico_to_pisa.toml --accuracy 1
  fails bad-accuracy-low run scenarios/grid_fixed_goals.toml --accuracy 0.4
  fails bad-epuck-decoder run scenarios/mexico_to_pisa.toml --decoder oracle
  fails bad-epuck-eeg run scenarios/mexico_to_pisa.toml --eeg bank
  fails bad-grid-runs run scenarios/grid_fixed_goals.toml --runs 3
  fails bad-own-accuracy-flag run "$out/own_eeg.toml" --accuracy 0.8
  fails bad-own-eeg-flag run "$out/own_eeg.toml" --eeg bank
  fails bad-own-decoder-flag run "$out/own_eeg.toml" --decoder oracle
  fails bad-own-accuracy-file run "$out/own_acc.toml"
  fails bad-own-eeg-file run "$out/own_bank.toml"
  fails bad-own-oracle-file run "$out/own_oracle.toml"
  fails bad-own-epuck-accuracy run "$out/own_epuck_acc.toml"
  fails bad-own-epuck-flag run "$out/own_eeg_epuck.toml" --accuracy 0.8
  fails bad-own-sweep-accuracy sweep --scenario "$out/own_eeg.toml" --param "eeg.recording=s01.edf,s02.edf" \
    --accuracy 0.7,0.8 --episodes 2 --no-cache --out "$out/bad-sweep-2"
  fails bad-own-sweep-eeg sweep --scenario "$out/own_eeg.toml" --param "eeg.recording=s01.edf,s02.edf" \
    --param eeg=bank --episodes 2 --no-cache --out "$out/bad-sweep-3"
  fails bad-own-sweep-level sweep --task grid --param "eeg.recording=$out/s01.edf" \
    --episodes 2 --no-cache --out "$out/bad-sweep-4"
  fails bad-own-stream stream "$out/own_eeg.toml" --timeout 1
  fails bad-stream-speed stream scenarios/grid_fixed_goals.toml --speed 1000
  fails bad-stream-perfect stream scenarios/grid_fixed_goals.toml --accuracy 1 --timeout 1
  fails bad-latency-nan run "$out/latency_nan.toml"
  fails bad-latency-sweep sweep --task epuck --param realism.task_latency_ms=nan --episodes 2 --no-cache \
    --out "$out/bad-sweep-5"
  fails bad-calibrate calibrate --accuracy 1.2
  fails bad-inspect inspect "$out/nothing.rrd"
  rm -f "$out"/*.toml
  # The merge prints its output paths, a sweep keeps its scenario's: make
  # them relative. What says which build made a file (the binary's path,
  # the source commit) is not compared.
  sed -i "s#$out/##g" "$out"/*.txt "$out"/*.err "$out"/sweep-own/sweep.json
  sed -i -E "s#\(commit [0-9a-f]+(-dirty)?\)#(commit ...)#; s#made by:  [^ ]*errp[^ ]* #made by:  errp #" \
    "$out"/inspect-*.txt
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

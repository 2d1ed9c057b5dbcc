#!/usr/bin/env bash
# The commands behind the figures the README and the guide quote, and their outputs.
#
#   scripts/readme_figures.sh [--check] [--cheap] [NAME...]
#
# Each figure is a command of the release `errp` (or $ERRP), or a script
# ("sh: ..."), whose standard output is kept in docs/figures/NAME.txt; the
# tables of the README and of the guide (docs/guide/) are copied from those
# files and name them. Without --check the outputs are written anew; with
# --check each command runs again and the script fails on any difference (a
# unified diff shows it). --cheap keeps to the figures that take seconds (CI
# runs these); NAME... picks figures by name. Every run is seeded and
# independent of the thread count, so the outputs are exact. The targeting
# cache is a fresh temporary directory, so nothing on the machine changes a result.
set -euo pipefail
cd "$(dirname "$0")/.."

# name | cost (cheap: seconds; slow: minutes) | errp arguments
FIGURES=(
  "epuck_mexico_default|cheap|run scenarios/mexico_to_pisa.toml --runs 200 --quiet"
  "epuck_lisbon_default|cheap|run scenarios/lisbon_to_tokyo.toml --runs 200 --quiet"
  "epuck_mexico_optimistic|cheap|run scenarios/variants/mexico_to_pisa_optimistic.toml --runs 200 --quiet"
  "epuck_lisbon_optimistic|cheap|run scenarios/variants/lisbon_to_tokyo_optimistic.toml --runs 200 --quiet"
  "epuck_mexico_literal|cheap|run scenarios/variants/mexico_to_pisa_literal.toml --runs 200 --quiet"
  "epuck_lisbon_literal|cheap|run scenarios/variants/lisbon_to_tokyo_literal.toml --runs 200 --quiet"
  "epuck_mexico_ideal|cheap|run scenarios/variants/mexico_to_pisa_ideal.toml --runs 200 --quiet"
  "epuck_lisbon_ideal|cheap|run scenarios/variants/lisbon_to_tokyo_ideal.toml --runs 200 --quiet"
  "inspect_equals_run|slow|sh: python3 scripts/inspect_equals_run.py scenarios/mexico_to_pisa.toml 100 5"
  "epuck_user_seed4|cheap|run scenarios/lisbon_to_tokyo.toml --seed 4 --runs 1 --quiet"
  "epuck_representative_seed|slow|sh: python3 scripts/representative_seed.py scenarios/mexico_to_pisa.toml"
  "sweep_epuck|slow|sweep --task epuck --accuracy 0.55:0.95:0.05 --param strategy=greedy,info_gain --episodes 100 --seed 1 --out OUT_DIR --quiet"
  "fit_epuck|slow|fit epuck --out OUT_DIR --quiet"
  "table1|cheap|table1 --seed 1 --quiet"
  "grid_fixed_run|cheap|run scenarios/grid_fixed_goals.toml --quiet"
  "table1_bank|slow|table1 --seed 1 --eeg bank --quiet"
  "table1_ideal|slow|table1 --seed 1 --realism scenarios/variants/grid_fixed_goals_ideal.toml --quiet"
  "table1_oracle|cheap|table1 --seed 1 --decoder oracle --quiet"
  "table1_continuous_shift|slow|table1 --seed 1 --realism scenarios/mexico_to_pisa.toml --quiet"
  "task_shift_bound|slow|sh: scripts/task_shift_bound.sh"
  "fit_grid_task_shift_10ms|slow|sh: f=\$(mktemp --suffix=.toml) && { cat scenarios/grid_fixed_goals.toml; echo 'task_latency_ms = 10'; } > \$f && \$ERRP fit grid --realism \$f --out OUT_DIR --quiet; s=\$?; rm -f \$f; exit \$s"
  "grid_sensitivity|slow|sh: cargo run --release --locked --quiet -p errp_sim --example grid_sensitivity"
  "sweep_grid|slow|sweep --task grid --accuracy 0.55:0.95:0.04 --param strategy=greedy,info_gain,thompson --episodes 200 --seed 1 --out OUT_DIR --quiet"
  "fit_grid|slow|fit grid --out OUT_DIR --quiet"
  "fit_grid_epsilon0|slow|fit grid --epsilon 0 --out OUT_DIR --quiet"
  "fit_grid_trial_latency|slow|fit grid --trial-latency-sd 16.7,19,21.3,25 --out OUT_DIR --quiet"
  "table1_seeds|slow|sh: python3 scripts/table1_seeds.py --seeds 10"
  "realism|cheap|realism --quiet"
  "grid_own_eeg|cheap|sh: d=\$(mktemp -d) && cp scenarios/recorded/own_eeg.toml \$d/ && \$ERRP calibrate --accuracy 0.78 --seed 1 --quiet --export \$d/s01.edf >/dev/null && \$ERRP run \$d/own_eeg.toml --quiet; s=\$?; rm -rf \$d; exit \$s"
  "grid_own_eeg_split|cheap|sh: d=\$(mktemp -d) && cp scenarios/recorded/own_eeg.toml \$d/ && \$ERRP calibrate --accuracy 0.78 --seed 1 --quiet --export \$d/s01.edf >/dev/null && \$ERRP sweep --scenario \$d/own_eeg.toml --param eeg.calibration=0.3,0.5,0.7 --episodes 40 --out \$d/sw --quiet > \$d/out.txt; s=\$?; sed \"s#\$d/##g\" \$d/out.txt; rm -rf \$d; exit \$s"
  "epuck_own_eeg|cheap|sh: d=\$(mktemp -d) && cp scenarios/recorded/own_eeg_epuck.toml \$d/ && \$ERRP calibrate --accuracy 0.78 --seed 1 --quiet --export \$d/s01.edf >/dev/null && \$ERRP run \$d/own_eeg_epuck.toml --quiet > \$d/out.txt && \$ERRP run scenarios/mexico_to_pisa.toml --accuracy 0.6857 --runs 50 --quiet > \$d/synthetic.txt; s=\$?; grep -v '^ *[0-9][0-9]* ' \$d/out.txt; echo '--- the synthetic user at the same cross-validated accuracy, T_e = 0.8:'; grep -E 'calibrated|detector:|reached' \$d/synthetic.txt; rm -rf \$d; exit \$s"
  "sweep_realism|slow|sweep --task grid --accuracy 0.75 --param realism.lapse_rate=0,0.1,0.2 --param realism.background_drift=0,0.3 --param strategy=greedy,thompson --episodes 200 --seed 1 --out OUT_DIR --quiet"
  "python_decoders|slow|sh: \${PYTHON:-target/ci-venv/bin/python} python/examples/decoders_in_the_loop.py 2>/dev/null | sed -E 's/ +\\([0-9.]+ s\\)\$//'"
  "python_cross_validation|slow|sh: \${PYTHON:-target/ci-venv/bin/python} python/examples/cross_validate_decoders.py 2>/dev/null"
  "python_cv_seeds|slow|sh: \${PYTHON:-target/ci-venv/bin/python} python/examples/cross_validate_decoders.py --seeds 12 --draws 10 2>/dev/null"
)

check=false
cheap=false
names=()
for arg in "$@"; do
  case "$arg" in
    --check) check=true ;;
    --cheap) cheap=true ;;
    -h|--help) sed -n '2,15p' "$0"; exit 0 ;;
    -*) echo "error: unknown option $arg (expected --check, --cheap or figure names)" >&2; exit 2 ;;
    *) names+=("$arg") ;;
  esac
done
known=" $(for f in "${FIGURES[@]}"; do printf '%s ' "${f%%|*}"; done)"
for n in "${names[@]}"; do
  if [[ "$known" != *" $n "* ]]; then
    echo "error: no figure named $n (known:$known)" >&2
    exit 2
  fi
done

ERRP=${ERRP:-target/release/errp}
if [ ! -x "$ERRP" ]; then
  cargo build --release --locked --quiet
fi
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
export ERRP_CACHE_DIR="$work/cache"
mkdir -p docs/figures

failed=0
ran=0
for entry in "${FIGURES[@]}"; do
  IFS='|' read -r name cost args <<<"$entry"
  if [ "${#names[@]}" -gt 0 ] && [[ " ${names[*]} " != *" $name "* ]]; then
    continue
  fi
  if $cheap && [ "$cost" != cheap ]; then
    continue
  fi
  args=${args//OUT_DIR/$work/out-$name}
  start=$SECONDS
  if [[ "$args" == "sh: "* ]]; then
    ERRP="$ERRP" bash -c "${args#sh: }" >"$work/$name.out"
  else
    # shellcheck disable=SC2086 # the arguments are words
    "$ERRP" $args >"$work/$name.out"
  fi
  # File paths of this run's temporary directory are not part of a figure.
  grep -v -F "$work" "$work/$name.out" >"$work/$name.txt" || true
  ran=$((ran + 1))
  if $check; then
    if diff -u "docs/figures/$name.txt" "$work/$name.txt"; then
      echo "ok   $name ($((SECONDS - start)) s)"
    else
      echo "DIFF $name: the README's figure docs/figures/$name.txt no longer holds" >&2
      failed=$((failed + 1))
    fi
  else
    cp "$work/$name.txt" "docs/figures/$name.txt"
    echo "wrote docs/figures/$name.txt ($((SECONDS - start)) s)"
  fi
done
if $check; then
  echo "$((ran - failed)) passed, $failed failed"
fi
[ "$failed" -eq 0 ]

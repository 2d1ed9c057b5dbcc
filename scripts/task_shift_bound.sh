#!/usr/bin/env bash
# How far Table 1 lets the grid's task shift go: `errp table1 --seed 1
# --eeg bank` for the shipped grid user (the drifts of [realism]) with the
# ErrP's closed-loop latency shift at 0, 10, 20 and 30 ms, and the goals
# reached of the paper's 40. The shipped shift is the largest of these at
# which the reached goals are not below the idealised user's.
#
#   scripts/task_shift_bound.sh     ($ERRP, default target/release/errp)
case "${1:-}" in
  -h | --help) awk 'NR > 1 && /^#SBATCH/ { exit } NR > 1 && /^#/ { sub(/^# ?/, ""); print; next } NR > 1 { exit }' "$0"; exit 0 ;;
esac
set -euo pipefail
cd "$(dirname "$0")/.."
errp=${ERRP:-target/release/errp}
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
reached() { # the "mean fixed" and "mean free" reached counts of a Table 1
  awk '/^mean fixed/ {split($3, a, "/")} /^mean free/ {split($3, b, "/")}
       END {printf "fixed %2d/20, free %2d/20, all %2d/40\n", a[1], b[1], a[1] + b[1]}'
}
printf 'idealised user       '
"$errp" table1 --seed 1 --eeg bank --realism scenarios/variants/grid_fixed_goals_ideal.toml \
  --quiet | reached
for ms in 0 10 20 30; do
  {
    cat scenarios/variants/grid_fixed_goals_ideal.toml
    printf '\n[realism]\nbackground_drift = 0.13\nalpha_drift = 0.18\ndrift_secs = 1800\n'
    printf 'task_latency_ms = %s\n' "$ms"
  } > "$tmp/shift.toml"
  printf 'drifts, shift %2s ms  ' "$ms"
  "$errp" table1 --seed 1 --eeg bank --realism "$tmp/shift.toml" --quiet | reached
done

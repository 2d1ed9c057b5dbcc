#!/usr/bin/env bash
# How long an e-puck trip takes, by where it starts and where it ends: the
# median time and detections of RUNS seeded runs (defaults: detector, user,
# 95 % decoder) for each start cell x goal cell of the 5 x 5 city grid.
# It answers whether any placement of the paper's cities could make one trip
# much longer than another without changing the decoder (docs/guide/epuck.md,
# "Measured: 200 runs of each city scenario, against the paper's sec. 5.3").
#
#   scripts/epuck_geometry_scan.sh [RUNS] [START_CELLS] [GOAL_CELLS] [HEADING_DEG]
#
# Cells are "column,row" from the bottom left (assets/cities.toml); the
# default starts are the six cells that, up to the square's symmetries,
# stand for all 25 (a corner, its edge neighbour, the middle of an edge, two
# inner cells, the centre), each against every other cell: 144 trips.
# Output: CSV on stdout.
case "${1:-}" in
  -h | --help) awk 'NR > 1 && /^#SBATCH/ { exit } NR > 1 && /^#/ { sub(/^# ?/, ""); print; next } NR > 1 { exit }' "$0"; exit 0 ;;
esac
set -euo pipefail
cd "$(dirname "$0")/.."
runs=${1:-100}
starts=${2:-"0,0 1,0 2,0 1,1 2,1 2,2"}
goals=${3:-"$(for r in 0 1 2 3 4; do for c in 0 1 2 3 4; do printf '%s,%s ' $c $r; done; done)"}
heading=${4:-90}
errp=target/release/errp
[ -x "$errp" ] || cargo build --release --locked --quiet
# City names by cell, row by row from the bottom (assets/cities.toml).
names=("Mexico" "Havana" "Nairobi" "Dubai" "Bangkok" "Bogota" "Lima" "Cairo" "Sydney"
  "Tokyo" "Toronto" "Rio de Janeiro" "Athens" "Beijing" "Delhi" "New York" "Las Vegas"
  "Rome" "Berlin" "Seoul" "Lisbon" "London" "Paris" "Moscow" "Pisa")
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
echo "start_column,start_row,goal_column,goal_row,goal,reached,median_secs,median_detected"
for s in $starts; do
  IFS=, read -r sc sr <<< "$s"
  for g in $goals; do
    IFS=, read -r gc gr <<< "$g"
    [ "$sc,$sr" = "$gc,$gr" ] && continue
    goal=${names[$((gr * 5 + gc))]}
    cat > "$tmp/scan.toml" << TOML
task = "epuck"
name = "geometry scan"
seed = 1
start = [$((sc * 40 + 20)), $((sr * 40 + 20))]
start_heading_deg = $heading
goal = "$goal"
max_secs = 600

[user]
accuracy = 0.95
TOML
    out=$("$errp" run "$tmp/scan.toml" --runs "$runs" --quiet)
    reached=$(sed -n 's#^  reached .* \([0-9]*\) / [0-9]*.*#\1#p' <<< "$out")
    secs=$(awk '/^  median time/ {print $4}' <<< "$out")
    detected=$(awk '/^  median detected/ {print $3}' <<< "$out")
    echo "$sc,$sr,$gc,$gr,$goal,$reached,$secs,$detected"
  done
done

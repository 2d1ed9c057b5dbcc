#!/usr/bin/env bash
# Renders recordings in the real Rerun viewer, headless (Xvfb + Mesa's
# software Vulkan, no GPU), and checks that no view of their shipped layout
# is empty.
#
#   scripts/screenshots.sh OUT_DIR [ERRP]
#       records the calibration, a grid run and the Mexico -> Pisa run with
#       ERRP (default target/debug/errp), renders each to OUT_DIR/*.png and
#       checks them (scripts/check_screenshot.py)
#
# Needs: `rerun` 0.36.3 on PATH (pip install rerun-sdk==0.36.3), Pillow,
# and Debian's xvfb, xdotool and mesa-vulkan-drivers. The viewer exits with 102 once
# the screenshot is written. Port 9877, not the default 9876: a viewer
# already running there would receive the file instead.
set -euo pipefail
out=${1:?usage: scripts/screenshots.sh OUT_DIR [ERRP]}
errp=${2:-target/debug/errp}
cd "$(dirname "$0")/.."
mkdir -p "$out"
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT

"$errp" calibrate --accuracy 0.7438 --seed 1 --quiet --save "$tmp/calibration.rrd" > /dev/null
"$errp" run scenarios/grid_fixed_goals.toml --seed 1 --quiet --save "$tmp/grid.rrd" > /dev/null
"$errp" run scenarios/mexico_to_pisa.toml --seed 1 --quiet --save "$tmp/epuck.rrd" > /dev/null

for name in calibration grid epuck; do
  status=0
  # The window opens in the middle of a larger screen, and the pointer is
  # moved to the screen's corner, off the window, so that no tooltip shows;
  # RUST_LOG=error keeps the viewer's start-up notes (software renderer,
  # container) out of the picture.
  RUST_LOG=error timeout 180 xvfb-run -a -s "-screen 0 2400x1600x24" bash -c \
    'xdotool mousemove 0 0 sleep 600 & sleep 0.5; exec rerun --port 9877 --renderer vulkan \
       --window-size 1600x1000 --screenshot-to "$1" "$2"' \
    _ "$out/$name.png" "$tmp/$name.rrd" > "$tmp/$name.log" 2>&1 || status=$?
  if [ "$status" != 102 ] || [ ! -s "$out/$name.png" ]; then
    echo "error: the viewer did not render $name.rrd (exit $status):" >&2
    tail -20 "$tmp/$name.log" >&2
    exit 1
  fi
  "${PYTHON:-python3}" scripts/check_screenshot.py "$name" "$out/$name.png" --self-test
done

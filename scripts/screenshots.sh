#!/usr/bin/env bash
# Renders recordings in the real Rerun viewer, headless (Xvfb + Mesa's
# software Vulkan, no GPU), and checks that no view of their shipped layout
# is empty.
#
#   scripts/screenshots.sh OUT_DIR [ERRP]
#       records the calibration, a grid run and the Mexico -> Pisa run with
#       ERRP (default target/debug/errp), and two episodes of the Gymnasium
#       e-puck with $PYTHON's errp package (save=), renders each to
#       OUT_DIR/*.png and checks them (scripts/check_screenshot.py)
#
# Needs: `rerun` 0.36.3 on PATH (pip install rerun-sdk==0.36.3), Pillow,
# and Debian's xvfb, xdotool and mesa-vulkan-drivers. The viewer exits with 102 once
# the screenshot is written. Port 9877, not the default 9876: a viewer
# already running there would receive the file instead.
case "${1:-}" in
  -h | --help) awk 'NR > 1 && /^#SBATCH/ { exit } NR > 1 && /^#/ { sub(/^# ?/, ""); print; next } NR > 1 { exit }' "$0"; exit 0 ;;
esac
set -euo pipefail
out=${1:?usage: scripts/screenshots.sh OUT_DIR [ERRP]}
errp=${2:-target/debug/errp}
cd "$(dirname "$0")/.."
mkdir -p "$out"
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT

"$errp" calibrate --accuracy 0.7438 --seed 1 --quiet --save "$tmp/calibration.rrd" > /dev/null
"$errp" run scenarios/grid_fixed_goals.toml --seed 1 --quiet --save "$tmp/grid.rrd" > /dev/null
"$errp" run scenarios/mexico_to_pisa.toml --quiet --save "$tmp/epuck.rrd" > /dev/null
# Two episodes of the Gymnasium e-puck driven by a seeded random agent,
# recorded with save= (needs the errp Python package), and read back.
"${PYTHON:-python3}" - "$tmp/agent.rrd" <<'EOF'
import sys

import gymnasium as gym
import numpy as np

import errp.gym  # noqa: F401  (registers the environments)

env = gym.make("errp/Epuck-v0", save=sys.argv[1], max_episode_steps=120)
rng = np.random.default_rng(1)
for episode in range(2):
    env.reset(seed=episode)
    done = False
    while not done:
        a = 0 if rng.random() < 0.7 else int(rng.integers(1, 3))
        _, _, term, trunc, _ = env.step(a)
        done = term or trunc
env.close()
EOF
"$errp" inspect "$tmp/agent.rrd" > /dev/null

for name in calibration grid epuck agent; do
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

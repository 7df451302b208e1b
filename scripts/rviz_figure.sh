#!/usr/bin/env bash
# Regenerates the README's rviz figure: plays a recorded run (by default the default experiment's bag,
# written by scripts/run_experiment.sh) into rviz with the rig's configuration on a virtual screen
# (xvfb-run, Mesa's software GL), at 1/20 of simulated time so that rviz draws what it is sent, and
# takes a screenshot of rviz on the bag's last state. The figure is replaced only if that worked.
#   scripts/rviz_figure.sh [BAG] [OUT.png]      defaults: results/experiment/latest/run.bag docs/figures/rviz.png
set -euo pipefail
here="$(cd "$(dirname "$0")/.." && pwd)"
bag="$(realpath -m "${1:-$here/results/experiment/latest/run.bag}")"
out="$(realpath -m "${2:-$here/docs/figures/rviz.png}")"
[ -f "$bag" ] || { echo "rviz_figure: no bag at $bag (run scripts/run_experiment.sh first)" >&2; exit 1; }
source "$here/scripts/ros_env.sh"
set +u; source "$RIG_WS/devel/setup.bash"; set -u
rate=0.05
duration=$(rosbag info -y -k duration "$bag")
work="$(mktemp -d /tmp/rviz_figure.XXXXXX)"
# Long enough for rviz to start and the bag to play, with a minute to spare.
export RIG_ROOT="$here" BAG="$bag" RATE="$rate" WORK="$work"
export WAIT_S=$(/usr/bin/python3 -c "print(int(60 + $duration / $rate))")
xvfb-run -a -s "-screen 0 1400x900x24" bash -c '
  set -u
  "$RIG_ROOT/scripts/rig_launch.sh" "$RIG_ROOT/launch/playback.launch" bag:="$BAG" rate:="$RATE" rviz:=true \
    required:=false >"$WORK/launch.log" 2>&1 &
  launch=$!
  for _ in $(seq "$WAIT_S"); do
    grep -qE "player-[0-9]+\] process has (finished|died)" "$WORK/launch.log" && break
    kill -0 "$launch" 2>/dev/null || break
    sleep 1
  done
  sleep 3  # rviz draws the last messages
  grep -qE "player-[0-9]+\] process has finished" "$WORK/launch.log" && import -window root "$WORK/rviz.png"
  # TERM, not INT: a background job of a non-interactive shell starts with SIGINT ignored, which no
  # trap can undo, and the launch (required:=false) would run on with rviz.
  kill -TERM "$launch" 2>/dev/null
  wait "$launch" || true'
if [ ! -s "$work/rviz.png" ]; then
  tail -n 20 "$work/launch.log" >&2
  echo "rviz_figure: the bag did not play out; $out is unchanged (log in $work)" >&2
  exit 1
fi
mv "$work/rviz.png" "$out"
rm -rf "$work"
echo "rviz_figure: wrote $out"

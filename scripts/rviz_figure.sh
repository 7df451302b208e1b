#!/usr/bin/env bash
# Regenerates the README's rviz figure: plays a recorded run (by default the default experiment's bag,
# written by scripts/run_experiment.sh) into rviz with the rig's configuration on a virtual screen
# (xvfb-run, Mesa's software GL), slowly enough that rviz draws what it is sent, and takes a
# screenshot of rviz on the bag's last state.
#   scripts/rviz_figure.sh [BAG] [OUT.png]      defaults: results/experiment/run.bag docs/figures/rviz.png
set -euo pipefail
here="$(cd "$(dirname "$0")/.." && pwd)"
bag="$(realpath "${1:-$here/results/experiment/run.bag}")"
out="$(realpath -m "${2:-$here/docs/figures/rviz.png}")"
[ -f "$bag" ] || { echo "rviz_figure: no bag at $bag (run scripts/run_experiment.sh first)" >&2; exit 1; }
log="$(mktemp /tmp/rviz_figure.XXXXXX.log)"
export BAG="$bag" OUT="$out" LOG="$log"
xvfb-run -a -s "-screen 0 1400x900x24" bash -c '
  "'"$here"'/scripts/rig_launch.sh" "'"$here"'/launch/playback.launch" bag:="$BAG" rate:=0.05 rviz:=true \
    required:=false >"$LOG" 2>&1 &
  launch=$!
  for _ in $(seq 600); do
    grep -q "player-.*process has finished" "$LOG" && break
    kill -0 "$launch" 2>/dev/null || break
    sleep 1
  done
  sleep 3
  import -window root "$OUT"
  kill -INT "$launch" 2>/dev/null; wait "$launch" || true'
grep -q "player-.*process has finished" "$log" || { tail -n 20 "$log"; echo "rviz_figure: the bag did not play out" >&2; exit 1; }
echo "rviz_figure: wrote $out (launch log $log)"

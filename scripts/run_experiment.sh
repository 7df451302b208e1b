#!/usr/bin/env bash
# The README's main command: installs what is missing, builds, runs the default experiment headless
# (scene pmma_2d, side driving, to the first global slip and three more stick-slip cycles) with the
# ROS rig on a private localhost master, records a bag, prints the summary and writes the figures.
# Each run has a folder of its own, results/experiment/<date>_<time>; results/experiment/latest links to
# the last run that succeeded.
#   scripts/run_experiment.sh [roslaunch arg:=value]...   e.g. scene:=$PWD/friction_sim/scenes/pmma_1d_side.yaml
set -euo pipefail
here="$(cd "$(dirname "$0")/.." && pwd)"
"$here/scripts/install_deps.sh"
echo "building (log in .build.log) ..."
"$here/scripts/build.sh" -j2 >"$here/.build.log" 2>&1 || { tail -n 40 "$here/.build.log"; exit 1; }
source "$here/scripts/ros_env.sh"
runs="$RIG_ROOT/results/experiment"
out="$runs/$(date +%Y-%m-%d_%H%M%S)"
mkdir -p "$out"
# roslaunch's chatter is filtered out (grep's status is not the rig's; rig_launch's is). The filter
# ignores Ctrl-C and reads on while rig_launch stops the rig: roslaunch must not lose its output midway.
launch_statuses=(0 0)
"$RIG_ROOT/scripts/rig_launch.sh" "$RIG_ROOT/launch/rig.launch" record:=true bag:="$out/run.bag" "$@" 2>&1 \
  | (trap '' INT; exec grep -vE '^\s*$|killing on exit|shutting down|^started roslaunch server|^process\[|^ROS_MASTER_URI=|^setting /run_id|^done$|REQUIRED process|process has finished|log file:|Initiating shutdown|^=+|SUMMARY|PARAMETERS|NODES|auto-starting|^ \* |^    ') \
  || launch_statuses=("${PIPESTATUS[@]}")
# A run that wrote nothing leaves no folder; one that wrote part of a bag keeps it.
case "${launch_statuses[0]}" in
  0) ;;
  130) rmdir "$out" 2>/dev/null || true; echo "run_experiment: interrupted; no figures written" >&2; exit 130 ;;
  *) rmdir "$out" 2>/dev/null || true; echo "run_experiment: the rig failed (its reasons are above); no figures written" >&2; exit 1 ;;
esac
[ -f "$out/run.bag" ] || { rmdir "$out" 2>/dev/null || true; echo "run_experiment: no bag was written" >&2; exit 1; }
set +u; source "$RIG_WS/devel/setup.bash"; set -u
/usr/bin/python3 "$RIG_ROOT/friction_sim/scripts/rig_report" "$out/run.bag" --out "$out"
ln -sfn "$(basename "$out")" "$runs/latest"
echo "results in $out (results/experiment/latest): $(cd "$out" && echo *)"

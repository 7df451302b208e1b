#!/usr/bin/env bash
# The README's main command: installs what is missing, builds, and runs the default experiment
# (scene pmma_2d, side driving, to the first global slip) with the offline runner.
# Extra arguments go to friction_run, e.g. --set stop.global_events=3.
set -euo pipefail
here="$(cd "$(dirname "$0")/.." && pwd)"
"$here/scripts/install_deps.sh"
"$here/scripts/build.sh" -j2 >"$here/.build.log" 2>&1 || { tail -n 40 "$here/.build.log"; exit 1; }
source "$here/scripts/ros_env.sh"
scene="${SCENE:-$RIG_ROOT/friction_sim/scenes/pmma_2d.yaml}"
exec "$RIG_WS/devel/lib/friction_sim/friction_run" "$scene" --out "$RIG_ROOT/results/$(basename "$scene" .yaml)" "$@"

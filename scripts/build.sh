#!/usr/bin/env bash
# Builds every package of the rig into .build/ (catkin workspace with this repository as its source).
set -euo pipefail
source "$(dirname "$0")/ros_env.sh"
mkdir -p "$RIG_WS"
touch "$RIG_WS/CATKIN_IGNORE"
# FRICTION_WERROR=ON (CI sets it) makes every compiler warning an error, in all three packages.
catkin_make -C "$RIG_WS" --source "$RIG_ROOT" -DCMAKE_BUILD_TYPE=Release \
  -DPYTHON_EXECUTABLE=/usr/bin/python3 -DFRICTION_WERROR="${FRICTION_WERROR:-OFF}" "$@"

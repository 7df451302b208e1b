#!/usr/bin/env bash
# Runs roslaunch with a private master bound to localhost on a free port, so that the rig neither
# disturbs another ROS system on the machine nor listens on the network.
#   scripts/rig_launch.sh launch/rig.launch [arg:=value]...
# Exits 0 only if roslaunch and every node it ran ended cleanly: roslaunch itself exits 0 when a node
# refuses its scene or protocol, so the nodes' exit codes are read from roslaunch's log afterwards and a
# failing node is named, with status 1, so that scripts and sweeps can tell a refused run from a run.
set -euo pipefail
source "$(dirname "$0")/ros_env.sh"
set +u; source "$RIG_WS/devel/setup.bash"; set -u
port=$(/usr/bin/python3 -c 'import socket; s = socket.socket(); s.bind(("127.0.0.1", 0)); print(s.getsockname()[1])')
export ROS_MASTER_URI="http://127.0.0.1:$port" ROS_IP=127.0.0.1 ROS_HOSTNAME=127.0.0.1
export ROS_HOME="${ROS_HOME:-$RIG_WS/ros_home}"
echo "rig_launch: private master at $ROS_MASTER_URI; to reach it from another shell:"
echo "  source $RIG_WS/devel/setup.bash; export ROS_MASTER_URI=$ROS_MASTER_URI ROS_IP=127.0.0.1"

pid_file=$(mktemp)
trap 'rm -f "$pid_file"' EXIT
# roslaunch names its log after its pid. The subshell writes its pid and then becomes roslaunch, which
# thus stays in the foreground, where Ctrl-C reaches it.
launch_status=0
( echo "$BASHPID" >"$pid_file"; exec roslaunch --port "$port" "$@" ) || launch_status=$?
[ "$launch_status" -eq 0 ] || exit "$launch_status"

launch_log=$(ls -t "${ROS_LOG_DIR:-$ROS_HOME/log}"/*/roslaunch-*-"$(cat "$pid_file")".log 2>/dev/null | head -n 1 || true)
if [ -z "$launch_log" ]; then
  echo "rig_launch: roslaunch's log was not found, so the nodes' exit codes are unknown" >&2
  exit 1
fi
# A node that ends by itself with a non-zero code is logged as
#   process has died [pid 8609, exit code 2, cmd /path/to/stage_controller __name:=controller ...
# Nodes stopped by roslaunch at shutdown are logged as killed, not as died.
failures=$(grep -oE 'process has died \[pid [0-9]+, exit code [1-9][0-9]*, cmd [^ ]+' "$launch_log" |
           sed -E 's|.*exit code ([0-9]+), cmd .*/([^/]+)$|\2 (exit code \1)|' || true)
if [ -n "$failures" ]; then
  echo "rig_launch: failed: $(echo "$failures" | paste -sd, - | sed 's/,/, /g'); their messages are above" >&2
  exit 1
fi

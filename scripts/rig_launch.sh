#!/usr/bin/env bash
# Runs roslaunch with a private master bound to localhost on a free port, so that the rig neither
# disturbs another ROS system on the machine nor listens on the network.
#   scripts/rig_launch.sh launch/rig.launch [arg:=value]...
set -euo pipefail
source "$(dirname "$0")/ros_env.sh"
set +u; source "$RIG_WS/devel/setup.bash"; set -u
port=$(/usr/bin/python3 -c 'import socket; s = socket.socket(); s.bind(("127.0.0.1", 0)); print(s.getsockname()[1])')
export ROS_MASTER_URI="http://127.0.0.1:$port" ROS_IP=127.0.0.1 ROS_HOSTNAME=127.0.0.1
export ROS_HOME="${ROS_HOME:-$RIG_WS/ros_home}"
echo "rig_launch: private master at $ROS_MASTER_URI; to reach it from another shell:"
echo "  source $RIG_WS/devel/setup.bash; export ROS_MASTER_URI=$ROS_MASTER_URI ROS_IP=127.0.0.1"
exec roslaunch --port "$port" "$@"

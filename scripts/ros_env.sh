# Sourced by the project's scripts: the ROS 1 environment with the system Python first.
# A pyenv or virtualenv python3 earlier on PATH lacks catkin_pkg and breaks catkin with odd errors.
export PATH="/usr/bin:/bin:/usr/sbin:/sbin:$PATH"
export PYTHON_EXECUTABLE=/usr/bin/python3
if [ -f /opt/ros/noetic/setup.bash ]; then
  # Ubuntu with ROS Noetic from packages.ros.org
  set +u; source /opt/ros/noetic/setup.bash; set -u
fi
RIG_ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
RIG_WS="$RIG_ROOT/.build"
export RIG_ROOT RIG_WS

# Sourced by the project's scripts: the ROS 1 environment with the system Python first.
# A pyenv or virtualenv python3 earlier on PATH lacks catkin_pkg and breaks catkin with odd errors.
export PATH="/usr/bin:/bin:/usr/sbin:/sbin:$PATH"
export PYTHON_EXECUTABLE=/usr/bin/python3
if [ -z "${ROS_DISTRO:-}" ] && [ -f /opt/ros/noetic/setup.bash ]; then
  # Ubuntu with ROS Noetic from packages.ros.org, unless a ROS environment (the user's overlay on it)
  # is set up already: sourcing it again would drop that overlay.
  set +u; source /opt/ros/noetic/setup.bash; set -u
fi
RIG_ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
RIG_WS="$RIG_ROOT/.build"
export RIG_ROOT RIG_WS

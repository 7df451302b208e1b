#!/usr/bin/env bash
# Installs what the rig needs to build, test and run; does nothing when everything is there.
#   Debian 12 (bookworm) and other systems without /opt/ros: Debian's own ROS 1 packages.
#   Ubuntu 20.04 with /opt/ros/noetic (packages.ros.org): the ros-noetic-* packages.
# Runs as root, or through sudo when not root.
set -euo pipefail

common=(build-essential cmake libeigen3-dev libsuitesparse-dev libyaml-cpp-dev libgtest-dev googletest libbenchmark-dev parallel rsync
        python3-matplotlib python3-numpy python3-yaml python3-setuptools xvfb xauth imagemagick libgl1-mesa-dri)
if [ -d /opt/ros/noetic ]; then
  ros=(ros-noetic-catkin ros-noetic-roscpp ros-noetic-rosbag ros-noetic-rostest ros-noetic-roslaunch
       ros-noetic-std-msgs ros-noetic-geometry-msgs ros-noetic-visualization-msgs ros-noetic-rosgraph-msgs
       ros-noetic-std-srvs ros-noetic-rosnode ros-noetic-message-generation ros-noetic-message-runtime
       ros-noetic-rviz ros-noetic-dynamic-reconfigure ros-noetic-tf2-ros ros-noetic-pluginlib ros-noetic-rospy python3-catkin-pkg python3-catkin-lint)
else
  ros=(catkin python3-catkin-pkg ros-core-dev librosbag-dev python3-rosbag python3-rospy python3-rostest
       python3-roslaunch python3-rosnode rosbash ros-message-generation libstd-msgs-dev libstd-srvs-dev
       python3-std-srvs python3-geometry-msgs
       libgeometry-msgs-dev libvisualization-msgs-dev libros-rosgraph-msgs-dev librviz-dev pluginlib-dev
       libdynamic-reconfigure-config-init-mutex-dev python3-dynamic-reconfigure tf2-tools rviz catkin-lint)
fi

missing=()
for package in "${common[@]}" "${ros[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$package" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$package")
  fi
done
if [ ${#missing[@]} -eq 0 ]; then
  echo "install_deps: everything is installed"
  exit 0
fi

as_root=()
if [ "$(id -u)" -ne 0 ]; then
  command -v sudo >/dev/null || { echo "install_deps: need root or sudo to install: ${missing[*]}" >&2; exit 1; }
  as_root=(sudo)
fi
echo "install_deps: installing ${missing[*]}"
"${as_root[@]}" apt-get update -qq
DEBIAN_FRONTEND=noninteractive "${as_root[@]}" apt-get install -y -qq "${missing[@]}"

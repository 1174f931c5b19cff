#!/usr/bin/env bash
# Creates tests/.venv with the independent tools the interop tests use: Cyclone DDS (a DDS peer
# speaking the ROS 2 conventions), rosbags and mcap-ros2-support (independent bag readers/writers).
set -euo pipefail
here="$(cd "$(dirname "$0")/.." && pwd)"
venv="$here/.venv"
# tests call this concurrently: one at a time builds the venv, the others wait
exec 9>"$here/.venv.lock"
flock 9
if [ ! -x "$venv/bin/python" ]; then
  python3 -m venv "$venv"
fi
if [ ! -f "$venv/.complete" ]; then
  "$venv/bin/pip" install --quiet --disable-pip-version-check \
    "cyclonedds==11.0.1" "rosbags>=0.10" "mcap>=1.2" "mcap-ros2-support>=0.5"
  touch "$venv/.complete"
fi
echo "$venv"

#!/usr/bin/env bash
# The node against a real ROS 2 Jazzy peer (rclpy, Fast DDS; tests/.venv-ros from
# setup-venv-ros.sh). Call under `unshare -n` (no DDS traffic leaves the machine).
# Args: ROTOR_TWIN_BIN VENV OUT_DIR
set -u
bin="$1"; v="$2"; out="$3"
here="$(cd "$(dirname "$0")" && pwd)"
ip link set lo up
"$bin" node --ros-args -r __node:=twin_r -r __ns:=/line1 -p model:=linear \
  -p speed_type:=float64 -p use_sim_time:=true > "$out/node.out" 2> "$out/node.err" &
node=$!
sleep 1
# the environment the wheels' own bootstrap would set (ros2-from-pypi.md)
libs="$v/lib"
for d in "$v"/lib/python3.11/site-packages/ros_*.libs; do libs="$libs:$d"; done
env AMENT_PREFIX_PATH="$v" CMAKE_PREFIX_PATH="$v" PATH="$v/bin:$PATH" \
  RMW_IMPLEMENTATION=rmw_fastrtps_cpp LD_LIBRARY_PATH="$libs" _ROS_WHEELS_BOOTSTRAP_COMPLETE=1 \
  ROS_LOG_DIR="$out/ros_log" \
  timeout 120 "$v/bin/python" "$here/rclpy_peer.py" /line1 twin_r > "$out/peer.json" 2> "$out/peer.err"
echo "peer exit $?" >> "$out/peer.err"
kill -INT "$node"
wait "$node"; echo "node exit $?" >> "$out/node.err"

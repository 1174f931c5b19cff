#!/usr/bin/env bash
# The node's ROS 2 parameter services over the bus: set a run-time parameter, read it back, and
# have a start-only one and a bad value refused; the node runs with discovery on this host only,
# and an unknown discovery range is refused. Call under `unshare -n`.
# Args: ROTOR_TWIN_BIN OUT_DIR
set -u
bin="$1"; out="$2"
ip link set lo up
# discovery on this host only (the loopback-only participant)
ROS_AUTOMATIC_DISCOVERY_RANGE=LOCALHOST "$bin" node > "$out/node.out" 2> "$out/node.err" &
node=$!
# the node joins the bus once its film tables are built (seconds, more on a loaded machine)
for _ in $(seq 240); do grep -q "up on ROS domain" "$out/node.err" 2>/dev/null && break; sleep 0.5; done
# service discovery takes longer on a loaded machine (CI runs the node tests side by side): 30 s a call
sleep 1
# service discovery is slower on a loaded machine (CI runs the node tests side by side)
{
  "$bin" param --timeout 30 set state_rate_hz:=50; echo "rc=$?"
  "$bin" param --timeout 30 get state_rate_hz model; echo "rc=$?"
  "$bin" param --timeout 30 set model:=linear; echo "rc=$?"
  "$bin" param --timeout 30 set state_rate_hz:=-1; echo "rc=$?"
  ROS_AUTOMATIC_DISCOVERY_RANGE=NEARBY "$bin" node; echo "rc=$?"
} > "$out/param.out" 2>&1
kill -INT "$node"
wait "$node"

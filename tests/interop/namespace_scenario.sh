#!/usr/bin/env bash
# Two twins on one bus, in two namespaces (as launch_ros names them), each driven by its own peer:
# one publishing best effort (a sensor driver's QoS), one reliable; then one twin's parameter is
# set and both are read back. Call under `unshare -n` (no DDS traffic leaves the machine).
# Args: ROTOR_TWIN_BIN PYTHON OUT_DIR
set -u
bin="$1"; py="$2"; out="$3"
here="$(cd "$(dirname "$0")" && pwd)"
ip link set lo up
"$bin" node --ros-args -r __node:=twin_a -r __ns:=/line1 -p model:=linear --log-level warn --enclave /x > "$out/a.out" 2> "$out/a.err" &
a=$!
"$bin" node --ros-args -r __node:=twin_b -r __ns:=/line2 -p model:=linear > "$out/b.out" 2> "$out/b.err" &
b=$!
sleep 2
# 8,000 rpm = 837.76 rad/s to line 1 (best effort), 8,500 rpm = 890.12 rad/s to line 2 (reliable)
timeout 60 "$py" "$here/peer.py" 6 837.76 --ns /line1 --best-effort > "$out/peer_a.json" 2> "$out/peer_a.err" &
pa=$!
timeout 60 "$py" "$here/peer.py" 6 890.12 --ns /line2 > "$out/peer_b.json" 2> "$out/peer_b.err"
wait "$pa"
{
  "$bin" param --node /line1/twin_a --timeout 30 set state_rate_hz:=50; echo "rc=$?"
  "$bin" param --node /line1/twin_a --timeout 30 get state_rate_hz; echo "rc=$?"
  "$bin" param --node /line2/twin_b --timeout 30 get state_rate_hz; echo "rc=$?"
} > "$out/param.out" 2>&1
kill -INT "$a" "$b"
wait "$a"; echo "node exit $?" >> "$out/a.err"
wait "$b"; echo "node exit $?" >> "$out/b.err"

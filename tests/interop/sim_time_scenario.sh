#!/usr/bin/env bash
# The node in simulation time: a peer publishes /clock at half real time, with one sample 1 h
# ahead after 2 s. Call under `unshare -n`.
# Args: ROTOR_TWIN_BIN PYTHON OUT_DIR
set -u
bin="$1"; py="$2"; out="$3"
here="$(cd "$(dirname "$0")" && pwd)"
ip link set lo up
"$bin" node --ros-args -p model:=linear -p use_sim_time:=true > "$out/node.out" 2> "$out/node.err" &
node=$!
sleep 1
timeout 30 "$py" "$here/peer.py" 6 963.42 --sim-clock 0.5 --clock-outlier > "$out/peer.json" 2> "$out/peer.err"
kill -INT "$node"
wait "$node"

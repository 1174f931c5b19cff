#!/usr/bin/env bash
# Runs the node and Cyclone DDS peers in THIS network namespace (call it under `unshare -n`, so no
# DDS traffic leaves the machine). Args: ROTOR_TWIN_BIN PYTHON OUT_DIR
set -u
bin="$1"; py="$2"; out="$3"
here="$(cd "$(dirname "$0")" && pwd)"
ip link set lo up
rm -rf "$out/bag"
# reading (A) of the seed (Ø55, linear threshold 8,471 rpm): its linear model whirls at 9,200 rpm;
# the built-in reading (B) is linear-stable up to 9,291 rpm
"$bin" node --config "$here/../../config/orc_microturbine_100kw_d55.yaml" --record "$out/bag" --ros-args -p model:=linear -p input_timeout_s:=0.5 -p probe_point_topics:=probe_pulley_end=/plant/probe_b > "$out/node.out" 2> "$out/node.err" &
node=$!
sleep 1
# 9,200 rpm = 963.4 rad/s, above the linear threshold: the linear model whirls and grows
timeout 60 "$py" "$here/peer.py" 7 963.42 --bad --burst 10000 > "$out/peer.json" 2> "$out/peer.err"
# a late subscriber: only the latched warning
timeout 20 "$py" "$here/peer.py" 2 963.42 --warnings-only > "$out/late.json" 2> "$out/late.err"
kill -INT "$node"
wait "$node"
echo "node exit $?" >> "$out/node.err"

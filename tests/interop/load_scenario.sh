#!/usr/bin/env bash
# The node under load_peer.py --bad --no-nan (malformed samples, every 2 s from 1 s) for a few
# seconds, recording.
# Call under `unshare -n`. Args: ROTOR_TWIN_BIN PYTHON OUT_DIR SECONDS
set -u
bin="$1"; py="$2"; out="$3"; seconds="$4"
here="$(cd "$(dirname "$0")" && pwd)"
ip link set lo up
rm -rf "$out/bag"
"$bin" node --record "$out/bag" --ros-args -p model:=linear \
  -p probe_point_topics:=probe_pulley_end=/plant/probe_b > "$out/node.out" 2> "$out/node.err" &
node=$!
sleep 1
timeout 60 "$py" "$here/load_peer.py" "$seconds" --bad --no-nan --ramp 400:900:"$seconds" \
  > "$out/peer.json" 2> "$out/peer.err"
kill -INT "$node"
wait "$node"
echo "node exit $?" >> "$out/node.err"
# the node's diagnostics as recorded: the largest refused_inputs count
"$py" - "$out/bag" > "$out/diagnostics.json" <<'PY'
import json, sys
from pathlib import Path
from rosbags.highlevel import AnyReader
refused = 0
with AnyReader([Path(sys.argv[1])]) as r:
    conns = [c for c in r.connections if c.topic == "/diagnostics"]
    for c, t, raw in r.messages(connections=conns):
        for st in r.deserialize(raw, c.msgtype).status:
            for kv in st.values:
                if kv.key == "refused_inputs":
                    refused = max(refused, int(kv.value))
print(json.dumps({"refused_inputs": refused}))
PY

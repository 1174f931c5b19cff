#!/usr/bin/env bash
# The node in simulation time against stamped_plant_peer.py (a solved plant's stamped keyphasor,
# raw ProbeSignal readings and speed, best effort, paced by the peer's /clock), the live
# calibration every 1 s of the node's clock, recording (its input diagnostics to recorded.json).
# Call under `unshare -n`.
# Args: ROTOR_TWIN_BIN PYTHON OUT_DIR CONFIG PLANT_CSV
set -u
bin="$1"; py="$2"; out="$3"; cfg="$4"; csv="$5"
here="$(cd "$(dirname "$0")" && pwd)"
ip link set lo up
rm -rf "$out/bag"
"$bin" node --config "$cfg" --record "$out/bag" --ros-args -p model:=linear -p use_sim_time:=true \
  -p calibration_period_s:=1.0 > "$out/node.out" 2> "$out/node.err" &
node=$!
sleep 1
timeout 150 "$py" "$here/stamped_plant_peer.py" "$csv" --rate 0.25 --tail-s 60 \
  > "$out/peer.json" 2> "$out/peer.err"
kill -INT "$node"
wait "$node"
echo "node exit $?" >> "$out/node.err"
# the node's last input diagnostics as recorded (its counts of lost and refused inputs)
"$py" - "$out/bag" > "$out/recorded.json" <<'PY'
import json, sys
from pathlib import Path
from rosbags.highlevel import AnyReader
diag = {}
with AnyReader([Path(sys.argv[1])]) as r:
    conns = [c for c in r.connections if c.topic == "/diagnostics"]
    for c, t, raw in r.messages(connections=conns):
        for st in r.deserialize(raw, c.msgtype).status:
            if st.name.endswith(": inputs"):
                diag = {kv.key: kv.value for kv in st.values}
print(json.dumps({"diagnostics": diag}))
PY

#!/usr/bin/env bash
# The node against signal_peer.py (a plant's keyphasor as std_msgs/Header and raw probes as
# std_msgs/Float64, best effort, selected by node parameters), recording. Call under `unshare -n`.
# Args: ROTOR_TWIN_BIN PYTHON OUT_DIR CONFIG SECONDS RPM STOP_KEYPHASOR_AFTER_S LOSS_PER_MILLE
#       UNAPPLY_AFTER_S OIL [PLANT_JSON]
# LOSS_PER_MILLE > 0: the peer's Cyclone DDS drops that share of the datagrams it sends.
# UNAPPLY_AFTER_S > 0: `rotor-twin param set calibration_apply:=false` that long after the peer
# starts (over the parameter services, as `ros2 param set` does).
# OIL = 1: the peer publishes sensor_msgs/Temperature on /plant/oil_temperature (the node's
# rotor_twin/oil_temperature remapped to it), its schedule in signal_peer.py.
# PLANT_JSON: the peer's speed segments and DC displacements (signal_peer.py --plant).
set -u
bin="$1"; py="$2"; out="$3"; cfg="$4"; seconds="$5"; rpm="$6"; stop_kp="$7"; loss="$8"; unapply="$9"; oil="${10:-0}"; plant="${11:-}"
here="$(cd "$(dirname "$0")" && pwd)"
ip link set lo up
rm -rf "$out/bag"
"$bin" node --config "$cfg" --record "$out/bag" --ros-args -p model:=linear \
  -p keyphasor_type:=header -r rotor_twin/keyphasor:=/plant/keyphasor \
  -r rotor_twin/oil_temperature:=/plant/oil_temperature \
  -p probe_signal_topics:=probe_outboard_x=/plant/probe_outboard_x,probe_outboard_y=/plant/probe_outboard_y \
  -p calibration_period_s:=2.0 -p calibration_apply:=true \
  > "$out/node.out" 2> "$out/node.err" &
node=$!
sleep 1
if [ "$loss" != "0" ]; then
  # SPDP every second (default 30 s): a lost announcement is repeated within the discovery wait
  export CYCLONEDDS_URI="<CycloneDDS><Domain><Discovery><SPDPInterval>1s</SPDPInterval></Discovery><Internal><Test><XmitLossiness>$loss</XmitLossiness></Test></Internal></Domain></CycloneDDS>"
fi
param=""
if [ "$unapply" != "0" ]; then
  ( sleep "$unapply"; "$bin" param --timeout 30 set calibration_apply:=false > "$out/param.out" 2>&1 ) &
  param=$!
fi
oil_arg=""
[ "$oil" = "1" ] && oil_arg="--oil-temperature"
[ -n "$plant" ] && oil_arg="$oil_arg --plant $plant"
timeout 120 "$py" "$here/signal_peer.py" "$seconds" "$rpm" --stop-keyphasor-after "$stop_kp" $oil_arg \
  > "$out/peer.json" 2> "$out/peer.err"
unset CYCLONEDDS_URI
[ -n "$param" ] && wait "$param"
sleep 1.2  # one more diagnostics after the last sample
kill -INT "$node"
wait "$node"
echo "node exit $?" >> "$out/node.err"
# the node's last input diagnostics as recorded, and the messages recorded per topic
"$py" - "$out/bag" > "$out/recorded.json" <<'PY'
import json, sys
from pathlib import Path
from rosbags.highlevel import AnyReader
diag, counts, oil = {}, {}, []
with AnyReader([Path(sys.argv[1])]) as r:
    for c in r.connections:
        counts[c.topic] = counts.get(c.topic, 0) + c.msgcount
    conns = [c for c in r.connections if c.topic == "/diagnostics"]
    for c, t, raw in r.messages(connections=conns):
        for st in r.deserialize(raw, c.msgtype).status:
            if st.name.endswith(": inputs"):
                diag = {kv.key: kv.value for kv in st.values}
            if st.name.endswith(": model"):
                v = {kv.key: kv.value for kv in st.values
                     if kv.key.startswith(("oil_", "viscosity_scale"))}
                if v and (not oil or oil[-1] != v):
                    oil.append(v)
calibration = None
with AnyReader([Path(sys.argv[1])]) as r:
    conns = [c for c in r.connections if c.topic == "/rotor_twin/calibration"]
    for c, t, raw in r.messages(connections=conns):
        m = r.deserialize(raw, c.msgtype)
        calibration = {"unbalance_valid": m.unbalance_valid, "unbalance_reason": m.unbalance_reason,
                       "magnitudes": [float(v) for v in m.unbalance_magnitudes],
                       "phases": [float(v) for v in m.unbalance_phases],
                       "viscosity_valid": m.viscosity_valid, "viscosity_reason": m.viscosity_reason,
                       "viscosity_scale": m.viscosity_scale,
                       "viscosity_scale_std": m.viscosity_scale_std, "positions": m.positions,
                       "vectors": m.vectors, "applied": m.applied,
                       "applied_before": (calibration or {}).get("applied_before", False) or m.applied}
print(json.dumps({"diagnostics": diag, "counts": counts, "calibration": calibration, "oil": oil}))
PY

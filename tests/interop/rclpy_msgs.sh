#!/usr/bin/env bash
# Our own message types as real ROS 2 builds them (issue 13): msg/ built by colcon with the rosidl
# generators of ROS 2 Jazzy (PyPI wheels, setup-colcon-msgs.sh), an rclpy peer on Fast DDS that
# publishes RotorSpeed (8,000 rpm, then 9,000 from half-time), Unbalance, Keyphasor, ProbeSignal and ProbeDisplacement serialised by
# rosidl's typesupport and reads every output type of the node (rclpy_msgs_peer.py), a late
# subscriber of the latched warning, and the node's recording: its type hashes against the ones
# rosidl generated. A script, not part of `cargo test` (the colcon build takes minutes).
# Usage (as root; DDS stays in a private network namespace):
#   bash tests/interop/rclpy_msgs.sh [ROTOR_TWIN_BIN] [SECONDS] [OUT_DIR]
# Exits 0 when every check holds; prints the checks and writes OUT_DIR/report.json.
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
repo="$(cd "$here/../.." && pwd)"
bin="${1:-$repo/target/release/rotor-twin}"
seconds="${2:-16}"
out="${3:-$(mktemp -d /tmp/rclpy_msgs.XXXXXX)}"
mkdir -p "$out"
{ read -r venv; read -r install; } < <(bash "$here/setup-colcon-msgs.sh")
libs="$venv/lib:$install/rotor_twin_msgs/lib"
for d in "$venv"/lib/python3.11/site-packages/ros_*.libs; do libs="$libs:$d"; done
rm -rf "$out/bag"
# the built-in machine with raw AC-coupled probes in µm at 45° and 135° at probe_outboard
{ cat "$repo/config/orc_microturbine_100kw.yaml"; echo "proximity_probes:"
  for p in x:45.0 y:135.0; do
    echo "  - {name: probe_outboard_${p%%:*}, station: probe_outboard, angle_deg: ${p#*:}, unit: um, coupling: ac}"
  done; } > "$out/machine.yaml"
unshare -n env OUT="$out" BIN="$bin" SECONDS_RUN="$seconds" SWITCH_S="$((seconds / 2))" HERE="$here" VENV="$venv" \
  LIBS="$libs" SITE="$install/rotor_twin_msgs/lib/python3.11/site-packages" bash -c '
  set -u
  ip link set lo up
  "$BIN" node --config "$OUT/machine.yaml" --record "$OUT/bag" --ros-args -p keyphasor_type:=keyphasor \
    -p calibration_period_s:=2.0 -p forecast_period_s:=3.0 > "$OUT/node.out" 2> "$OUT/node.err" &
  node=$!
  # the node subscribes once its film tables are ready (built on a first run: up to a minute
  # under load): the peer starts when the node says it is up
  for _ in $(seq 1 600); do
    grep -q " up on ROS domain" "$OUT/node.err" 2>/dev/null && break
    sleep 0.2
  done
  sleep 0.5
  env AMENT_PREFIX_PATH="$VENV" PATH="$VENV/bin:$PATH" RMW_IMPLEMENTATION=rmw_fastrtps_cpp \
    LD_LIBRARY_PATH="$LIBS" PYTHONPATH="$SITE" _ROS_WHEELS_BOOTSTRAP_COMPLETE=1 \
    ROS_LOG_DIR="$OUT/ros_log" timeout 120 "$VENV/bin/python" "$HERE/rclpy_msgs_peer.py" \
    "$SECONDS_RUN" 8000 9000 "$SWITCH_S" > "$OUT/peer.json" 2> "$OUT/peer.err"
  echo "peer exit $?" >> "$OUT/peer.err"
  kill -INT "$node"; wait "$node"; echo "node exit $?" >> "$OUT/node.err"'
"$venv/bin/python" - "$out" "$install/rotor_twin_msgs/share/rotor_twin_msgs/msg" <<'PY'
import json, pathlib, sys
out, gen = pathlib.Path(sys.argv[1]), pathlib.Path(sys.argv[2])
peer = json.loads((out / "peer.json").read_text())
checks = []
def check(name, ok, detail):
    checks.append({"check": name, "ok": bool(ok), "detail": detail})
topics = peer["topics"]
for topic in ["/rotor_twin/journal_state", "/rotor_twin/film_state", "/rotor_twin/orbit",
              "/rotor_twin/stability_margin", "/rotor_twin/residual", "/rotor_twin/one_x",
              "/rotor_twin/calibration", "/rotor_twin/forecast", "/rotor_twin/warning (late)"]:
    t = topics.get(topic, {"count": 0, "nan": 0})
    check(f"{topic} decoded by rclpy", t["count"] > 0 and t["nan"] == 0,
          {k: t.get(k) for k in ("type", "count", "nan", "inf", "first")})
kinds = topics.get("/rotor_twin/warning", {}).get("kinds", [])
check("an instability warning at 9,000 rpm (nonlinear model, above its threshold)",
      any(k in ("growing", "whirl", "whip") for k in kinds), kinds)
late = topics.get("/rotor_twin/warning (late)", {})
first = late.get("keys", [None])[0]
check("a subscriber created 2 s before the end gets a warning the node sent before (latched)",
      first is not None and first in topics.get("/rotor_twin/warning", {}).get("keys", []),
      {"late_first": first})
lags = topics.get("/rotor_twin/one_x", {}).get("phase_lags_deg", {}).get("probe_outboard", [])
med = [sorted(x[i] for x in lags)[len(lags) // 2] for i in range(2)] if lags else []
# the peer's probes at 45° and 135° read a 1X circle lagging the keyphasor by 50°
check("node read our Keyphasor and ProbeSignal: median 1X phase lags 95° and 185° within 5°",
      med and abs(med[0] - 95.0) < 5.0 and abs(med[1] - 185.0) < 5.0,
      {"blocks": len(lags), "median_deg": med})
res = topics.get("/rotor_twin/residual", {})
check("node read our ProbeDisplacement (residuals at probe_pulley_end)",
      0.0 < res.get("max_abs_residual", {}).get("probe_pulley_end", 0.0) < 1e-3,
      res.get("max_abs_residual"))
# the node's recording: our types' RIHS01 hashes against rosidl's own
import yaml
meta = yaml.safe_load(next((out / "bag").glob("metadata.yaml")).read_text())
recorded = {t["topic_metadata"]["type"]: t["topic_metadata"].get("type_description_hash", "")
            for t in meta["rosbag2_bagfile_information"]["topics_with_message_count"]}
ours = {k: v for k, v in recorded.items() if k.startswith("rotor_twin_msgs/")}
bad = {}
for typ, h in ours.items():
    j = json.loads((gen / (typ.rsplit("/", 1)[1] + ".json")).read_text())
    want = next(x["hash_string"] for x in j["type_hashes"] if x["type_name"] == typ)
    if h != want:
        bad[typ] = {"recorded": h, "rosidl": want}
check("recorded type hashes of our types equal rosidl's", ours and not bad,
      {"types": len(ours), "different": bad})
counts = {t["topic_metadata"]["name"]: t["message_count"]
          for t in meta["rosbag2_bagfile_information"]["topics_with_message_count"]}
for topic, key in (("/rotor_twin/speed", "speed"), ("/rotor_twin/keyphasor", "keyphasor"),
                   ("/rotor_twin/probe_signal", "probe_signal"), ("/rotor_twin/probe", "probe")):
    check(f"{topic}: recorded / sent by rclpy", counts.get(topic, 0) >= 0.9 * peer["sent"][key],
          f"{counts.get(topic, 0)} / {peer['sent'][key]}")
report = {"checks": checks, "publisher_hashes": peer["publisher_hashes"]}
(out / "report.json").write_text(json.dumps(report, indent=1))
for c in checks:
    print(("ok    " if c["ok"] else "FAIL  ") + c["check"] + ": " + json.dumps(c["detail"])[:300])
sys.exit(0 if all(c["ok"] for c in checks) else 1)
PY

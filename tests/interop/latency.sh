#!/usr/bin/env bash
# Latency benchmark (not a test): speed message → first journal state that reflects it, through
# an independent Cyclone DDS peer, in a private network namespace. Usage (as root):
#   bash tests/interop/latency.sh [SAMPLES] [MODEL]
set -euo pipefail
root="$(cd "$(dirname "$0")/../.." && pwd)"
samples="${1:-200}"; model="${2:-nonlinear}"
py="$(bash "$root/tests/interop/setup-venv.sh")/bin/python"
bin="$root/target/release/rotor-twin"
[ -x "$bin" ] || (cd "$root" && cargo build --release)
rec="$(mktemp -d)/run"
unshare -n bash -c "ip link set lo up
  '$bin' node --record '$rec' --ros-args -p model:=$model -p state_rate_hz:=1000 > /dev/null 2>&1 &
  node=\$!
  sleep 3
  '$py' '$root/tests/interop/latency.py' $samples
  kill -INT \$node; wait \$node"
# the node's own account of keeping up: the /diagnostics it recorded
"$py" - "$rec" <<'PY'
import sys
from rosbags.highlevel import AnyReader
from pathlib import Path
rtf, lag, behind = [], [], 0
with AnyReader([Path(sys.argv[1])]) as r:
    conns = [c for c in r.connections if c.topic in ("/diagnostics", "/rotor_twin/warning")]
    for c, t, raw in r.messages(connections=conns):
        m = r.deserialize(raw, c.msgtype)
        if c.topic == "/diagnostics":
            v = {kv.key: kv.value for kv in m.status[0].values}
            rtf.append(float(v["real_time_factor"])); lag.append(float(v["lag_s"]))
        elif m.kind == "falling_behind":
            behind += 1
if rtf:
    print(f"node diagnostics: {len(rtf)} reports, real-time factor min {min(rtf):.3f} median {sorted(rtf)[len(rtf)//2]:.3f}, lag max {max(lag):.4f} s, falling_behind warnings {behind}")
PY

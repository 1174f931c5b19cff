#!/usr/bin/env bash
# Benchmark (not a test): does the node keep real time with the forecast on? The node runs in a
# private network namespace with `forecast_period_s:=PERIOD` (0: off) while an independent
# Cyclone DDS peer sends a speed for SECONDS; afterwards its own /diagnostics and the forecasts
# it published are read from its recording. Usage (as root):
#   bash tests/interop/forecast_load.sh [PERIOD_S] [SECONDS] [SPEED_RPM]
set -euo pipefail
root="$(cd "$(dirname "$0")/../.." && pwd)"
period="${1:-2}"; seconds="${2:-30}"; rpm="${3:-8800}"
py="$(bash "$root/tests/interop/setup-venv.sh")/bin/python"
bin="$root/target/release/rotor-twin"
[ -x "$bin" ] || (cd "$root" && cargo build --release)
rec="$(mktemp -d)/run"
rad_s="$(python3 -c "import math; print($rpm * math.pi / 30)")"
unshare -n bash -c "ip link set lo up
  '$bin' node --record '$rec' --ros-args -p forecast_period_s:=$period > /dev/null 2>&1 &
  node=\$!
  sleep 3
  timeout $((seconds + 30)) '$py' '$root/tests/interop/peer.py' $seconds $rad_s > /dev/null 2>&1 || true
  kill -INT \$node; wait \$node"
"$py" - "$rec" "$period" <<'PY'
import sys
from pathlib import Path
from rosbags.highlevel import AnyReader
rtf, lag, behind, fc, fstat = [], [], 0, [], None
with AnyReader([Path(sys.argv[1])]) as r:
    topics = ("/diagnostics", "/rotor_twin/warning", "/rotor_twin/forecast")
    conns = [c for c in r.connections if c.topic in topics]
    for c, t, raw in r.messages(connections=conns):
        m = r.deserialize(raw, c.msgtype)
        if c.topic == "/diagnostics":
            for s in m.status:
                v = {kv.key: kv.value for kv in s.values}
                if s.name.endswith(": model") and "real_time_factor" in v:
                    rtf.append(float(v["real_time_factor"])); lag.append(float(v["lag_s"]))
                elif s.name.endswith(": forecast"):
                    fstat = (s.level, s.message, v)
        elif c.topic == "/rotor_twin/warning" and m.kind == "falling_behind":
            behind += 1
        elif c.topic == "/rotor_twin/forecast":
            fc.append(m)
# leave out the first 5 reports (discovery, the twin not started yet)
rtf, lag = rtf[5:], lag[5:]
print(f"forecast_period_s {sys.argv[2]}: {len(rtf)} model reports after the first 5: real-time factor min {min(rtf):.3f} median {sorted(rtf)[len(rtf)//2]:.3f}, lag max {max(lag):.4f} s, falling_behind warnings {behind}")
if fc:
    d = sorted(f.compute_duration for f in fc)
    nl = [f.nonlinear_threshold_speed * 30 / 3.141592653589793 for f in fc if f.nonlinear_threshold_found]
    print(f"forecasts published: {len(fc)}, compute duration median {d[len(d)//2]:.2f} s, max {d[-1]:.2f} s; expected states {sorted(set(f.expected_state for f in fc))}; nonlinear threshold {('%.0f–%.0f rpm' % (min(nl), max(nl))) if nl else 'above the probes'}, linear {fc[-1].linear_threshold_speed * 30 / 3.141592653589793:.0f} rpm")
if fstat:
    print(f"last forecast status: level {fstat[0]}, '{fstat[1]}', {fstat[2]}")
PY

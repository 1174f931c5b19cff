"""Drives a fleet of rotor-twin nodes and collects their own account of keeping up.

Usage: fleet_peer.py N SECONDS SPEED_RAD_S
Publishes rotor_twin_msgs/RotorSpeed at 20 Hz to /fleet1 … /fleetN (each node's namespace), reads
/diagnostics (the status `fleetK/rotor_twin: model` of each node: real_time_factor, lag_s) and each
node's latched warning topic (falling_behind). The statistics leave out the reports of the first
WARMUP_S = 5 s (discovery, and windows in which the twin had not started yet). Prints one JSON object per node. Run it only inside
the private network namespace of the nodes (unshare -n), as tests/interop/fleet.sh does.
"""
import json
import os
import sys
import time
from dataclasses import dataclass

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "tests", "interop"))
from peer import Header, InstabilityWarning, RotorSpeed, Time  # noqa: E402

from cyclonedds.core import Policy, Qos  # noqa: E402
from cyclonedds.domain import DomainParticipant  # noqa: E402
from cyclonedds.idl import IdlStruct  # noqa: E402
from cyclonedds.idl.types import sequence, uint8  # noqa: E402
import cyclonedds.idl.annotations as annotate  # noqa: E402
from cyclonedds.pub import DataWriter  # noqa: E402
from cyclonedds.sub import DataReader  # noqa: E402
from cyclonedds.topic import Topic  # noqa: E402
from cyclonedds.util import duration  # noqa: E402


@dataclass
@annotate.final
class KeyValue(IdlStruct, typename="diagnostic_msgs::msg::dds_::KeyValue_"):
    key: str
    value: str


@dataclass
@annotate.final
class DiagnosticStatus(IdlStruct, typename="diagnostic_msgs::msg::dds_::DiagnosticStatus_"):
    level: uint8
    name: str
    message: str
    hardware_id: str
    values: sequence[KeyValue]


@dataclass
@annotate.final
class DiagnosticArray(IdlStruct, typename="diagnostic_msgs::msg::dds_::DiagnosticArray_"):
    header: Header
    status: sequence[DiagnosticStatus]


def main():
    n, seconds, speed = int(sys.argv[1]), float(sys.argv[2]), float(sys.argv[3])
    dp = DomainParticipant(0)
    cdr = Policy.DataRepresentation(use_cdrv0_representation=True)
    reliable = Qos(Policy.Reliability.Reliable(duration(seconds=1)), Policy.History.KeepLast(100), cdr)
    latched = Qos(Policy.Reliability.Reliable(duration(seconds=1)), Policy.History.KeepLast(1),
                  Policy.Durability.TransientLocal, cdr)
    names = [f"fleet{k}" for k in range(1, n + 1)]
    speeds = [DataWriter(dp, Topic(dp, f"rt/{ns}/rotor_twin/speed", RotorSpeed), qos=reliable) for ns in names]
    warnings = [DataReader(dp, Topic(dp, f"rt/{ns}/rotor_twin/warning", InstabilityWarning), qos=latched)
                for ns in names]
    diagnostics = DataReader(dp, Topic(dp, "rt/diagnostics", DiagnosticArray), qos=reliable)
    warmup_s = 5.0
    out = {ns: {"reports": 0, "rtf": [], "lag_s": [], "falling_behind": 0, "falling_behind_warmup": 0,
                "warn_levels": 0} for ns in names}
    start = time.time()
    while time.time() - start < seconds:
        now = time.time_ns()
        stamp = Header(Time(now // 1_000_000_000, now % 1_000_000_000), "")
        for w in speeds:
            w.write(RotorSpeed(stamp, speed, 0.0))
        for m in diagnostics.take(N=1000):
            for s in m.status:
                ns = s.name.split("/")[0]
                if ns in out and s.name.endswith(": model") and time.time() - start > warmup_s:
                    v = {kv.key: kv.value for kv in s.values}
                    o = out[ns]
                    o["reports"] += 1
                    o["rtf"].append(float(v["real_time_factor"]))
                    o.setdefault("raw", []).append((round(time.time() - start, 2), v["real_time_factor"], v["lag_s"], v["step_overruns"], v["worst_step_us"], v.get("wakes")))
                    o["lag_s"].append(float(v["lag_s"]))
                    if "wakes" in v:
                        o.setdefault("wakes", []).append(int(v["wakes"]))
                    o["warn_levels"] += int(s.level != 0)
        for ns, r in zip(names, warnings):
            for m in r.take(N=100):
                if m.kind == "falling_behind":
                    # by the warning's own stamp: in the warm-up (the 20 starting together, the
                    # first speed arriving while tables load and discovery runs) or after it
                    stamped_s = m.header.stamp.sec + m.header.stamp.nanosec * 1e-9
                    late = stamped_s - start > warmup_s
                    out[ns]["falling_behind" if late else "falling_behind_warmup"] += 1
                kinds = out[ns].setdefault("warnings", {})
                kinds[m.kind] = kinds.get(m.kind, 0) + 1
        time.sleep(0.05)
    for ns in names:
        o = out[ns]
        rtf, lag = o["rtf"], o["lag_s"]
        print(json.dumps({
            "twin": ns, "reports": o["reports"],
            "rtf_min": min(rtf) if rtf else None,
            "rtf_median": sorted(rtf)[len(rtf) // 2] if rtf else None,
            "rtf_below_0_99": sum(r < 0.99 for r in rtf),
            "lag_max_s": max(lag) if lag else None,
            "wakes_median": sorted(o["wakes"])[len(o["wakes"]) // 2] if o.get("wakes") else None,
            "non_ok_reports": o["warn_levels"], "falling_behind": o["falling_behind"],
            "falling_behind_warmup": o["falling_behind_warmup"],
            "warnings": o.get("warnings", {}),
            "raw": o.get("raw", []) if os.environ.get("FLEET_RAW") else None,
        }))


if __name__ == "__main__":
    main()

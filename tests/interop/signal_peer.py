"""A plant's raw signals, live, in standard types only (issue 12), for the rotor-twin node.

Usage: signal_peer.py SECONDS RPM [--stop-keyphasor-after S] [--oil-temperature] [--plant FILE]
Publishes best effort (REP 2003 SensorDataQoS, as sensor drivers do):
  - /plant/keyphasor std_msgs/Header, one event a revolution, stamped with the event's time (the
    plant's shaft angle 0), sent at the first probe tick after it; none after
    --stop-keyphasor-after S (the shaft keeps turning);
  - /plant/probe_outboard_x and /plant/probe_outboard_y std_msgs/Float64, the gap (µm) of the
    probes at 45° and 135°, 16 samples a revolution: 1000 µm less a forward 1X circle of 2 µm
    lagging the keyphasor by BETA = 50°, so the probe at α reads a displacement
    2 µm·cos(ψ − (BETA + α)), its phase lag BETA + α (95° and 185°). Each value is computed for
    the instant it is written (a Float64 carries no stamp: the node takes its receive time);
  - /rotor_twin/speed rotor_twin_msgs/RotorSpeed at 100 Hz;
  - with --oil-temperature, /plant/oil_temperature sensor_msgs/Temperature (°C) at 10 Hz:
    OIL_HOT_C for the first half of the run, then OIL_C until 1 s before the end, then one NaN
    and one absurd OIL_ABSURD_C (0.2 s apart) and nothing more (the node must keep OIL_C).
Listens to /rotor_twin/one_x (rotor_twin_msgs/OneXVectors) and the warnings; prints JSON: what it
sent per topic, every OneXVectors received (stamp s, lags, amplitudes, reason), warnings.
With CYCLONEDDS_URI asking for XmitLossiness, Cyclone drops that share of the datagrams it sends:
a lossy best-effort link. Run it only inside a private network namespace (unshare -n).
With --plant FILE (JSON {"segments": [{"t_s", "rpm", "dc_um": [x, y]}, ...]}) the shaft runs
at each segment's speed from its start time on (the angle continuous, the keyphasor at each
whole revolution of it) and each probe's reading also carries that segment's DC displacement
along its axis (µm; DC-coupled probes: the journal's mean position), instead of RPM throughout
and no DC displacement.
"""
import json
import math
import sys
import time
from dataclasses import dataclass

sys.path.insert(0, __file__.rsplit("/", 1)[0])
from peer import Header, InstabilityWarning, RotorSpeed, Time  # noqa: E402
from peer_common import wait_matched  # noqa: E402
from cyclonedds.core import Qos, Policy
from cyclonedds.domain import DomainParticipant
from cyclonedds.idl import IdlStruct
from cyclonedds.idl.types import float64, uint32, sequence
import cyclonedds.idl.annotations as annotate
from cyclonedds.pub import DataWriter
from cyclonedds.sub import DataReader
from cyclonedds.topic import Topic
from cyclonedds.util import duration

BETA_DEG = 50.0
OIL_HOT_C, OIL_C, OIL_ABSURD_C = 60.0, 50.0, 1000.0
PROBES = (("probe_outboard_x", 45.0), ("probe_outboard_y", 135.0))


@dataclass
@annotate.final
class Float64(IdlStruct, typename="std_msgs::msg::dds_::Float64_"):
    data: float64


@dataclass
@annotate.final
class Temperature(IdlStruct, typename="sensor_msgs::msg::dds_::Temperature_"):
    header: Header
    temperature: float64
    variance: float64


def oil_schedule(seconds):
    """(time s, °C) of every Temperature the peer sends in a run of `seconds`."""
    out = [(0.1 * k, OIL_HOT_C if 0.1 * k < seconds / 2 else OIL_C)
           for k in range(int(round((seconds - 1.0) / 0.1)))]
    return out + [(seconds - 1.0, float("nan")), (seconds - 0.8, OIL_ABSURD_C)]


@dataclass
@annotate.final
class OneXVectors(IdlStruct, typename="rotor_twin_msgs::msg::dds_::OneXVectors_"):
    header: Header
    station: str
    speed: float64
    revolutions: uint32
    samples: uint32
    axis_angles: sequence[float64]
    measured_amplitudes: sequence[float64]
    measured_phase_lags_deg: sequence[float64]
    predicted_amplitudes: sequence[float64]
    predicted_phase_lags_deg: sequence[float64]
    phase_lag_errors_deg: sequence[float64]
    phase_null_reason: str


class Shaft:
    """The shaft's speed segments: angle, keyphasor events and DC displacements against time."""

    def __init__(self, segments):
        self.seg, psi = [], 0.0
        for i, g in enumerate(segments):
            omega = g["rpm"] * math.pi / 30.0
            if i:
                t_prev, _, w_prev, _ = self.seg[-1]
                psi += w_prev * (g["t_s"] - t_prev)
            self.seg.append((g["t_s"], psi, omega, g["dc_um"]))

    def at(self, t):
        """(t_start, psi_start, omega, dc_um) of the segment at time t (s)."""
        return next(g for g in reversed(self.seg) if g[0] <= t or g is self.seg[0])

    def psi(self, t):
        t_s, psi_s, omega, _ = self.at(t)
        return psi_s + omega * (t - t_s)

    def event_s(self, k):
        """When the shaft angle reaches 2πk (s)."""
        target = 2.0 * math.pi * k
        for i, (t_s, psi_s, omega, _) in enumerate(self.seg):
            if i + 1 == len(self.seg) or self.seg[i + 1][1] > target:
                return t_s + (target - psi_s) / omega


def stamp(ns):
    return Header(Time(ns // 1_000_000_000, ns % 1_000_000_000), "")


def main():
    seconds, rpm = float(sys.argv[1]), float(sys.argv[2])
    stop_kp = float(sys.argv[sys.argv.index("--stop-keyphasor-after") + 1]) \
        if "--stop-keyphasor-after" in sys.argv else 1e9
    best_effort = Qos(Policy.Reliability.BestEffort, Policy.History.KeepLast(100),
                      Policy.DataRepresentation(use_cdrv0_representation=True))
    reliable = Qos(Policy.Reliability.Reliable(duration(seconds=1)), Policy.History.KeepLast(1000),
                   Policy.DataRepresentation(use_cdrv0_representation=True))
    latched = Qos(Policy.Reliability.Reliable(duration(seconds=1)), Policy.History.KeepLast(1),
                  Policy.Durability.TransientLocal, Policy.DataRepresentation(use_cdrv0_representation=True))
    dp = DomainParticipant(0)
    kp_w = DataWriter(dp, Topic(dp, "rt/plant/keyphasor", Header), qos=best_effort)
    probe_w = [(DataWriter(dp, Topic(dp, f"rt/plant/{name}", Float64), qos=best_effort),
                math.radians(BETA_DEG + alpha), name) for name, alpha in PROBES]
    speed_w = DataWriter(dp, Topic(dp, "rt/rotor_twin/speed", RotorSpeed), qos=best_effort)
    oil = oil_schedule(seconds) if "--oil-temperature" in sys.argv else []
    oil_w = DataWriter(dp, Topic(dp, "rt/plant/oil_temperature", Temperature), qos=best_effort) \
        if oil else None
    one_x = DataReader(dp, Topic(dp, "rt/rotor_twin/one_x", OneXVectors), qos=reliable)
    warnings = DataReader(dp, Topic(dp, "rt/rotor_twin/warning", InstabilityWarning), qos=latched)
    # discovery: every writer matched by the node's reader before the first sample (a lossy link
    # can drop discovery datagrams too, and a loaded machine starts the node late), then 0.5 s for
    # the node's side of the match
    wait_matched([kp_w, speed_w] + [w for w, _, _ in probe_w] + ([oil_w] if oil_w else []),
                 timeout_s=60.0, who="signal_peer")
    time.sleep(0.5)
    segments = [{"t_s": 0.0, "rpm": rpm, "dc_um": [0.0, 0.0]}]
    if "--plant" in sys.argv:
        with open(sys.argv[sys.argv.index("--plant") + 1]) as f:
            segments = json.load(f)["segments"]
    shaft = Shaft(segments)
    sent = {"/plant/keyphasor": 0, "/rotor_twin/speed": 0}
    sent.update({f"/plant/{name}": 0 for name, _ in PROBES})
    if oil:
        sent["/plant/oil_temperature"] = 0
    out = {"sent": sent, "one_x": [], "warnings": {}, "t0_ns": 0, "keyphasor_stopped_at_s": None}
    t0 = time.time_ns()
    out["t0_ns"] = t0
    next_event, next_speed, next_tick = 0, 0.0, 0.0
    while True:
        now = time.time_ns()
        t = (now - t0) * 1e-9
        if t >= seconds:
            break
        _, _, omega, dc = shaft.at(t)
        while t0 + shaft.event_s(next_event) * 1e9 <= now:
            ev = t0 + round(shaft.event_s(next_event) * 1e9)
            if (ev - t0) * 1e-9 < stop_kp:
                kp_w.write(stamp(ev))
                sent["/plant/keyphasor"] += 1
            elif out["keyphasor_stopped_at_s"] is None:
                out["keyphasor_stopped_at_s"] = (ev - t0) * 1e-9
            next_event += 1
        while oil and oil[0][0] <= t:
            oil_w.write(Temperature(stamp(now), oil.pop(0)[1], 0.0))
            sent["/plant/oil_temperature"] += 1
        if t >= next_speed:
            speed_w.write(RotorSpeed(stamp(now), omega, 0.0))
            sent["/rotor_twin/speed"] += 1
            next_speed += 0.01
        for j, (w, lag, name) in enumerate(probe_w):
            psi = shaft.psi((time.time_ns() - t0) * 1e-9)
            w.write(Float64(1000.0 - dc[j] - 2.0 * math.cos(psi - lag)))
            sent[f"/plant/{name}"] += 1
        read(one_x, warnings, out, t0)
        next_tick += 2.0 * math.pi / omega / 16
        time.sleep(max(0.0, t0 * 1e-9 + next_tick - time.time()))
    # the last samples may still be unacknowledged (reliable writers): wait for the node's acks
    for w in [kp_w, speed_w] + [w for w, _, _ in probe_w] + ([oil_w] if oil_w else []):
        w.wait_for_acks(duration(seconds=5))
    time.sleep(1.0)
    read(one_x, warnings, out, t0)
    print(json.dumps(out))



def read(one_x, warnings, out, t0):
    for s in one_x.take(N=1000):
        out["one_x"].append({
            "t_s": (s.header.stamp.sec * 1_000_000_000 + s.header.stamp.nanosec - t0) * 1e-9,
            "station": s.station, "speed": s.speed, "samples": s.samples,
            "measured_amplitudes": list(s.measured_amplitudes),
            "measured_phase_lags_deg": list(s.measured_phase_lags_deg),
            "predicted_phase_lags_deg": list(s.predicted_phase_lags_deg),
            "phase_lag_errors_deg": list(s.phase_lag_errors_deg),
            "reason": s.phase_null_reason})
    for s in warnings.take(N=100):
        seen = out["warnings"].setdefault(s.kind, [])
        if len(seen) < 20 and s.evidence not in seen:
            seen.append(s.evidence)


if __name__ == "__main__":
    main()

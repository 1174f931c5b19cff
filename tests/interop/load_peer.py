"""A load peer for the rotor-twin node: sustained probes, a speed ramp and bad samples mixed in.

Usage: load_peer.py SECONDS [--probe-hz 4000] [--ramp LO:HI:PERIOD_S] [--bad [--no-nan]]
  Every 10 ms: one rotor_twin_msgs/RotorSpeed on /rotor_twin/speed (a triangle ramp LO → HI → LO
  rad/s over PERIOD_S, default 400:900:60), PROBE_HZ/100 ProbeDisplacement samples on
  /rotor_twin/probe (station probe_outboard) and one geometry_msgs/PointStamped on /plant/probe_b.
  --bad: every 100th speed NaN, every 1000th stamped 1 h in the future, and every 2 s one
  malformed sample on each of the speed, probe and point topics: the right type name with a 1-byte
  body (from a second participant), which the node cannot decode.
Listens to the journal states and warnings; prints what it sent and saw as JSON:
  sent_speeds (valid and NaN ones: every one of them decodes and is recorded), sent_probes,
  sent_points, malformed, journal, nonfinite, warnings (distinct kinds and evidences),
  speed_after_malformed (journal speeds seen after the first malformed sample: min, max),
  last_sent_speed, last_journal_speed.
Run it only inside a private network namespace (unshare -n), as the node.
"""
import json
import math
import sys
import time
from dataclasses import dataclass

sys.path.insert(0, __file__.rsplit("/", 1)[0])
from peer import (Header, InstabilityWarning, JournalState, Point, PointStamped,  # noqa: E402
                  ProbeDisplacement, RotorSpeed, Time)
from cyclonedds.core import Qos, Policy
from cyclonedds.domain import DomainParticipant
from cyclonedds.idl import IdlStruct
from cyclonedds.idl.types import uint8
import cyclonedds.idl.annotations as annotate
from cyclonedds.pub import DataWriter
from cyclonedds.sub import DataReader
from cyclonedds.topic import Topic
from cyclonedds.util import duration
from peer_common import wait_matched  # noqa: E402


def one_byte(typename):
    """A type with the given ROS type name and a 1-byte body: on the wire, a malformed sample."""
    @dataclass
    @annotate.final
    class OneByte(IdlStruct, typename=typename):
        b: uint8
    return OneByte


BadSpeed = one_byte("rotor_twin_msgs::msg::dds_::RotorSpeed_")
BadProbe = one_byte("rotor_twin_msgs::msg::dds_::ProbeDisplacement_")
BadPoint = one_byte("geometry_msgs::msg::dds_::PointStamped_")


def arg(name, default):
    return sys.argv[sys.argv.index(name) + 1] if name in sys.argv else default


def stamp(ns):
    return Header(Time(ns // 1_000_000_000, ns % 1_000_000_000), "")


def ramp(t, lo, hi, period):
    """Triangle wave lo → hi → lo over one period (rad/s)."""
    phase = (t / period) % 1.0
    return lo + (hi - lo) * (2 * phase if phase < 0.5 else 2 * (1 - phase))


def main():
    seconds = float(sys.argv[1])
    probe_hz = float(arg("--probe-hz", "4000"))
    lo, hi, period = (float(x) for x in arg("--ramp", "400:900:60").split(":"))
    bad = "--bad" in sys.argv
    nan = "--no-nan" not in sys.argv
    qos = Qos(Policy.Reliability.Reliable(duration(seconds=1)), Policy.History.KeepLast(1000),
              Policy.DataRepresentation(use_cdrv0_representation=True))
    latched = Qos(Policy.Reliability.Reliable(duration(seconds=1)), Policy.History.KeepLast(1),
                  Policy.Durability.TransientLocal, Policy.DataRepresentation(use_cdrv0_representation=True))
    dp = DomainParticipant(0)
    speed_w = DataWriter(dp, Topic(dp, "rt/rotor_twin/speed", RotorSpeed), qos=qos)
    probe_w = DataWriter(dp, Topic(dp, "rt/rotor_twin/probe", ProbeDisplacement), qos=qos)
    point_w = DataWriter(dp, Topic(dp, "rt/plant/probe_b", PointStamped), qos=qos)
    journal = DataReader(dp, Topic(dp, "rt/rotor_twin/journal_state", JournalState), qos=qos)
    warnings = DataReader(dp, Topic(dp, "rt/rotor_twin/warning", InstabilityWarning), qos=latched)
    # the malformed samples come from a second participant (one participant has one type per topic)
    bad_dp = DomainParticipant(0)
    bad_w = [(DataWriter(bad_dp, Topic(bad_dp, name, ty), qos=qos), ty) for name, ty in
             [("rt/rotor_twin/speed", BadSpeed), ("rt/rotor_twin/probe", BadProbe),
              ("rt/plant/probe_b", BadPoint)]] if bad else []
    # a reliable, volatile writer drops what it writes before the node's reader matches: every
    # counted sample must be sent after the match (then 0.5 s for the node's side of it)
    wait_matched([speed_w, probe_w, point_w], timeout_s=30.0, who="load_peer")
    time.sleep(0.5)
    out = {"sent_speeds": 0, "sent_probes": 0, "sent_points": 0, "malformed": 0, "journal": 0,
           "nonfinite": 0, "warnings": {}, "speed_after_malformed": None,
           "last_sent_speed": None, "last_journal_speed": None}
    start = time.time()
    next_tick = start
    tick = 0
    while time.time() - start < seconds:
        t = time.time() - start
        now = time.time_ns()
        v = ramp(t, lo, hi, period)
        speed_stamp = now + (3600 * 10**9 if bad and tick % 1000 == 999 else 0)
        value = float("nan") if bad and nan and tick % 100 == 50 else v
        speed_w.write(RotorSpeed(stamp(speed_stamp), value, 0.0))
        out["sent_speeds"] += 1
        if value == value and speed_stamp == now:
            out["last_sent_speed"] = v
        # the probes owed by the elapsed time: a late tick sends more, the rate holds on average
        while out["sent_probes"] < probe_hz * t:
            a = 2.0e-5 * math.sin(2 * math.pi * 50 * t)
            probe_w.write(ProbeDisplacement(stamp(now), "probe_outboard", a, -a))
            out["sent_probes"] += 1
        point_w.write(PointStamped(stamp(now), Point(1.0e-5, -2.0e-5, 0.0)))
        out["sent_points"] += 1
        if bad and tick % 200 == 100:
            for w, ty in bad_w:
                w.write(ty(7))
                out["malformed"] += 1
        read(journal, warnings, out)
        tick += 1
        next_tick += 0.01
        time.sleep(max(0.0, next_tick - time.time()))
    # the last samples may still be unacknowledged: wait for the node's acks before exiting
    for w in (speed_w, probe_w, point_w):
        w.wait_for_acks(duration(seconds=5))
    time.sleep(0.5)
    read(journal, warnings, out)
    print(json.dumps(out))


def read(journal, warnings, out):
    for s in journal.take(N=10000):
        out["journal"] += 1
        vals = [s.x, s.y, s.vx, s.vy, s.eccentricity_ratio, s.attitude, s.speed]
        out["nonfinite"] += sum(1 for v in vals if not math.isfinite(v))
        out["last_journal_speed"] = s.speed
        if out["malformed"] > 0:
            r = out["speed_after_malformed"] or [s.speed, s.speed]
            out["speed_after_malformed"] = [min(r[0], s.speed), max(r[1], s.speed)]
    for s in warnings.take(N=100):
        seen = out["warnings"].setdefault(s.kind, [])
        if len(seen) < 20 and s.evidence not in seen:
            seen.append(s.evidence)


if __name__ == "__main__":
    main()

"""A Cyclone DDS peer of the rotor-twin node on another host, for the Zenoh route (zenoh_route.sh).

Usage: zenoh_peer.py latency SAMPLES THROUGHPUT_S [--announce] [--first-reply-timeout S]
       zenoh_peer.py silence SECONDS [--announce]
  latency: waits for the first JournalState (sending speeds every 50 ms until one arrives) and 3 s, then
    sends SAMPLES new speeds (BASE + k*0.001 rad/s, one every 50 ms) and times the first
    JournalState carrying each (as latency.py does); then counts the JournalStates that arrive in
    THROUGHPUT_S seconds, and per bearing the states missing from their sequence of stamps.
  silence: sends speeds at 20 Hz for SECONDS and counts the JournalStates that arrive (the route
    is closed: the answer must be 0).
  --announce: publish ros_discovery_info (rmw_dds_common/ParticipantEntitiesInfo, as every rmw
    does) naming this peer as the ROS node /zenoh_peer with its writer and reader. A DDS-to-Zenoh
    bridge (zenoh-plugin-ros2dds) routes only the endpoints some ROS node declares there.
Prints one JSON object. Run it only inside a private network namespace.
"""
import json
import statistics
import sys
import time
from dataclasses import dataclass

sys.path.insert(0, __file__.rsplit("/", 1)[0])
from peer import Header, JournalState, RotorSpeed, Time  # noqa: E402
from latency import speed_latencies, summary  # noqa: E402
from cyclonedds.core import Policy, Qos  # noqa: E402
from cyclonedds.domain import DomainParticipant  # noqa: E402
from cyclonedds.idl import IdlStruct  # noqa: E402
from cyclonedds.idl.types import array, sequence, uint8  # noqa: E402
import cyclonedds.idl.annotations as annotate  # noqa: E402
from cyclonedds.pub import DataWriter  # noqa: E402
from cyclonedds.sub import DataReader  # noqa: E402
from cyclonedds.topic import Topic  # noqa: E402
from cyclonedds.util import duration  # noqa: E402

BASE = 837.76  # rad/s, 8,000 rpm: below the microturbine's whip threshold
WARMUP_S = 3.0  # after the first reply: the twin's start (it falls behind at first under load)


# rmw_dds_common (Jazzy: 16-byte GIDs), the graph topic every rmw writes
@dataclass
@annotate.final
class Gid(IdlStruct, typename="rmw_dds_common::msg::dds_::Gid_"):
    data: array[uint8, 16]


@dataclass
@annotate.final
class NodeEntitiesInfo(IdlStruct, typename="rmw_dds_common::msg::dds_::NodeEntitiesInfo_"):
    node_namespace: str
    node_name: str
    reader_gid_seq: sequence[Gid]
    writer_gid_seq: sequence[Gid]


@dataclass
@annotate.final
class ParticipantEntitiesInfo(IdlStruct, typename="rmw_dds_common::msg::dds_::ParticipantEntitiesInfo_"):
    gid: Gid
    node_entities_info_seq: sequence[NodeEntitiesInfo]


def gid(entity):
    return Gid(list(entity.guid.bytes))


def announce(dp, writers, readers):
    qos = Qos(Policy.Reliability.Reliable(duration(seconds=1)), Policy.Durability.TransientLocal,
              Policy.History.KeepLast(1), Policy.DataRepresentation(use_cdrv0_representation=True))
    w = DataWriter(dp, Topic(dp, "ros_discovery_info", ParticipantEntitiesInfo), qos=qos)
    node = NodeEntitiesInfo("/", "zenoh_peer", [gid(r) for r in readers], [gid(x) for x in writers])
    w.write(ParticipantEntitiesInfo(gid(dp), [node]))
    return w


class Peer:
    def __init__(self, announce_node):
        self.dp = DomainParticipant(0)
        qos = Qos(Policy.Reliability.Reliable(duration(seconds=1)), Policy.History.KeepLast(100),
                  Policy.DataRepresentation(use_cdrv0_representation=True))
        self.w = DataWriter(self.dp, Topic(self.dp, "rt/rotor_twin/speed", RotorSpeed), qos=qos)
        # one reader, keeping the newest 100 (as latency.py: no backlog in the timing). A second,
        # deeper reader of the topic in this participant received nothing through the bridge
        # (zenoh-plugin-ros2dds 1.9.0; not investigated), so the throughput is read by this one
        # too: "missing" counts what the route and this reader's depth lost together.
        self.r = DataReader(self.dp, Topic(self.dp, "rt/rotor_twin/journal_state", JournalState), qos=qos)
        self.graph = announce(self.dp, [self.w], [self.r]) if announce_node else None

    def send(self, v):
        now = time.time_ns()
        self.w.write(RotorSpeed(Header(Time(now // 1_000_000_000, now % 1_000_000_000), ""), v, 0.0))


def first_reply(p, timeout_s):
    t0 = time.time()
    while time.time() - t0 < timeout_s:
        if p.r.take(N=100):
            return time.time() - t0
        p.send(BASE)
        time.sleep(0.05)
    return None


def throughput(p, seconds):
    """Counts JournalStates for `seconds` s, and per bearing the states missing in their sequence."""
    while p.r.take(N=5000):
        pass
    stamps = {}
    n = 0
    t0 = time.perf_counter()
    while time.perf_counter() - t0 < seconds:
        batch = p.r.take(N=5000)
        for s in batch:
            stamps.setdefault(s.bearing, set()).add(s.header.stamp.sec * 10**9 + s.header.stamp.nanosec)
        n += len(batch)
        if not batch:
            time.sleep(0.001)
    elapsed = time.perf_counter() - t0
    # per bearing, the states missing between consecutive stamps (the node publishes one every
    # whole number of model steps, so the interval is the median gap, not exactly 1/state_rate_hz)
    missing = {}
    span_s = max(((max(ts) - min(ts)) * 1e-9 for ts in stamps.values()), default=0.0)
    for b, ts in stamps.items():
        ts = sorted(ts)
        gaps = [t1 - t0 for t0, t1 in zip(ts, ts[1:])]
        dt = statistics.median(gaps) if gaps else 0
        missing[b] = sum(round(g / dt) - 1 for g in gaps) if dt > 0 else None
    return {"received": n, "seconds": round(elapsed, 3), "per_s": round(n / elapsed, 1),
            "bearings": len(stamps), "missing": missing,
            # model time covered by the stamps over the wall time: the node's pace as seen from here
            "model_s": round(span_s, 3), "model_over_wall": round(span_s / elapsed, 3)}


def main():
    mode = sys.argv[1]
    p = Peer("--announce" in sys.argv)
    if mode == "silence":
        seconds = float(sys.argv[2])
        n = 0
        t0 = time.time()
        while time.time() - t0 < seconds:
            p.send(BASE)
            n += len(p.r.take(N=1000))
            time.sleep(0.05)
        print(json.dumps({"mode": "silence", "seconds": seconds, "journal_states": n}))
        return
    samples, tput_s = int(sys.argv[2]), float(sys.argv[3])
    timeout = float(sys.argv[sys.argv.index("--first-reply-timeout") + 1]) \
        if "--first-reply-timeout" in sys.argv else 60.0
    first = first_reply(p, timeout)
    out = {"mode": "latency", "first_reply_s": first}
    if first is not None:
        time.sleep(WARMUP_S)
        p.r.take(N=20000)
        out.update({"sent": samples, **summary(speed_latencies(p.send, p.r, BASE, samples)),
                    "throughput": throughput(p, tput_s)})
    print(json.dumps(out))


if __name__ == "__main__":
    main()

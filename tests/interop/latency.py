"""Latency of the rotor-twin node: from a speed message to the first journal state that carries it.

Usage: latency.py SAMPLES [BASE_RAD_S]
Sends a new speed (BASE + k·0.001 rad/s) every 50 ms after the first reply arrives and times the
first JournalState whose speed equals it. Prints median, p99 and the samples' count as JSON.
Run inside the node's private network namespace.
"""
import json
import statistics
import sys
import time

sys.path.insert(0, __file__.rsplit("/", 1)[0])
from peer import Header, JournalState, RotorSpeed, Time  # noqa: E402
from cyclonedds.core import Qos, Policy
from cyclonedds.domain import DomainParticipant
from cyclonedds.pub import DataWriter
from cyclonedds.sub import DataReader
from cyclonedds.topic import Topic
from cyclonedds.util import duration


def speed_latencies(send, reader, base, samples):
    """Sends BASE + k*0.001 rad/s (k = 1..SAMPLES, one every 50 ms) through `send` and times the
    first JournalState from `reader` carrying each; returns the times in ms, sorted."""
    lat = []
    for k in range(1, samples + 1):
        v = base + 0.001 * k
        t0 = time.perf_counter()
        send(v)
        got = None
        while time.perf_counter() - t0 < 1.0 and got is None:
            for s in reader.take(N=1000):
                if abs(s.speed - v) < 1e-9:
                    got = time.perf_counter() - t0
                    break
            if got is None:
                time.sleep(0.0002)
        if got is not None:
            lat.append(got * 1e3)
        time.sleep(0.05)
    return sorted(lat)


def summary(lat):
    return {"samples": len(lat), "median_ms": statistics.median(lat) if lat else None,
            "p99_ms": lat[min(len(lat) - 1, int(0.99 * len(lat)))] if lat else None,
            "max_ms": lat[-1] if lat else None}


def main():
    samples = int(sys.argv[1])
    base = float(sys.argv[2]) if len(sys.argv) > 2 else 837.76
    dp = DomainParticipant(0)
    qos = Qos(Policy.Reliability.Reliable(duration(seconds=1)), Policy.History.KeepLast(100),
              Policy.DataRepresentation(use_cdrv0_representation=True))
    w = DataWriter(dp, Topic(dp, "rt/rotor_twin/speed", RotorSpeed), qos=qos)
    r = DataReader(dp, Topic(dp, "rt/rotor_twin/journal_state", JournalState), qos=qos)

    def send(v):
        now = time.time_ns()
        w.write(RotorSpeed(Header(Time(now // 1_000_000_000, now % 1_000_000_000), ""), v, 0.0))

    # wait until matched and the twin runs: send until the first reply
    deadline = time.time() + 20
    while time.time() < deadline and not r.take(N=100):
        send(base)
        time.sleep(0.05)
    time.sleep(1.0)
    r.take(N=10000)
    print(json.dumps(summary(speed_latencies(send, r, base, samples))))


if __name__ == "__main__":
    main()

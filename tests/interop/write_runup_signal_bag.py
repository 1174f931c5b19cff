"""Writes a rosbag2 MCAP bag with PyPI `rosbags` (an independent writer) of a RUN-UP in standard
types only (issue 16, the measured Bode plot): the speed ramps linearly from N0 to N1 rpm over
SECONDS; a keyphasor as std_msgs/Header on /plant/keyphasor, one event a revolution (the stamp is
the event: shaft angle 0, solved exactly from the ramp); one std_msgs/Float64 raw proximity-probe
gap (µm, AC) per probe on /plant/<station>_<x|y> at 5 kHz; no speed topic. The shaft whirls on
a forward 1X circle whose radius and lag depend on the speed N:
    A(N) = 2 µm + 2 µm · s,   β(N) = 30° + 90° · s,   s = (N − N0)/(N1 − N0),
so the probe at angle α (45° and 135°) reads the displacement A cos(ψ − (β + α)): its 1X
amplitude is A(N) and its phase lag β(N) + α. A 0.5 µm forward 0.5X circle is added (its
leakage into 1X is what the Hann window has to keep out). The gap is 1000 µm minus the
displacement.

Usage: write_runup_signal_bag.py OUT_DIR SECONDS N0_RPM N1_RPM
Prints the message counts per topic as JSON.
"""
import json
import math
import sys
from pathlib import Path

from rosbags.rosbag2 import StoragePlugin, Writer
from rosbags.typesys import Stores, get_typestore

out, seconds = Path(sys.argv[1]), float(sys.argv[2])
n0, n1 = float(sys.argv[3]), float(sys.argv[4])
store = get_typestore(Stores.ROS2_JAZZY)
Float64 = store.types["std_msgs/msg/Float64"]
Header = store.types["std_msgs/msg/Header"]
Time = store.types["builtin_interfaces/msg/Time"]

t0 = 1_767_225_600_000_000_000  # 2026-01-01T00:00:00Z, ns
w0 = n0 * math.pi / 30.0
acc = (n1 - n0) * math.pi / 30.0 / seconds  # rad/s²


def angle(t):
    return w0 * t + 0.5 * acc * t * t


def speed_rpm(t):
    return n0 + (n1 - n0) * t / seconds


events = []  # (ns, topic, message, type)
k = 0
while True:
    # ψ(t) = 2πk: t = (−ω0 + sqrt(ω0² + 2 a 2πk)) / a
    t = (-w0 + math.sqrt(w0 * w0 + 2 * acc * 2 * math.pi * k)) / acc if acc else 2 * math.pi * k / w0
    if t > seconds:
        break
    ns = t0 + round(t * 1e9)
    stamp = Time(sec=ns // 1_000_000_000, nanosec=ns % 1_000_000_000)
    events.append((ns, "/plant/keyphasor", Header(stamp=stamp, frame_id="keyphasor"), "std_msgs/msg/Header"))
    k += 1
probes = []
for station in ("probe_pulley_end", "probe_outboard"):
    for suffix, alpha in (("x", 45.0), ("y", 135.0)):
        probes.append((f"/plant/{station}_{suffix}", math.radians(alpha)))
dt = 1.0 / 5000.0
k = 0
while k * dt <= seconds:
    t = k * dt
    ns = t0 + round(t * 1e9)
    psi = angle(t)
    s = (speed_rpm(t) - n0) / (n1 - n0)
    a_um, beta = 2.0 + 2.0 * s, math.radians(30.0 + 90.0 * s)
    for topic, alpha in probes:
        d_um = a_um * math.cos(psi - beta - alpha) + 0.5 * math.cos(0.5 * psi - alpha)
        events.append((ns, topic, Float64(data=1000.0 - d_um), "std_msgs/msg/Float64"))
    k += 1
events.sort(key=lambda e: e[0])

counts = {}
with Writer(out, version=9, storage_plugin=StoragePlugin.MCAP) as writer:
    conns = {"/plant/keyphasor": writer.add_connection("/plant/keyphasor", "std_msgs/msg/Header", typestore=store)}
    for topic, _ in probes:
        conns[topic] = writer.add_connection(topic, "std_msgs/msg/Float64", typestore=store)
    for ns, topic, msg, msgtype in events:
        writer.write(conns[topic], ns, store.serialize_cdr(msg, msgtype))
        counts[topic] = counts.get(topic, 0) + 1
print(json.dumps(counts))

"""Writes a rosbag2 MCAP bag with PyPI `rosbags` (an independent writer) carrying a plant's raw
signals in standard types only (issue 12): a keyphasor as std_msgs/Header on /plant/keyphasor
(one event a revolution, the stamp is the event: shaft angle 0), and one std_msgs/Float64 raw
proximity-probe gap (µm, AC) per probe on /plant/<station>_<x|y>, 16 samples a revolution, no
speed topic. The shaft whirls on a forward 1X circle of 2 µm radius lagging the keyphasor by
BETA = 50°, so the probe at angle α (45° and 135°) reads a displacement 2 µm·cos(ψ − (BETA + α)):
its phase lag is BETA + α. The gap is 1000 µm minus that displacement.

With --oil-temperature-c C also sensor_msgs/Temperature (°C) on /plant/oil_temperature, 10 a
second at C, then one NaN 1 ms after the last (a bad sample the replay must refuse, keeping C).

Usage: write_signal_bag.py OUT_DIR SECONDS SPEED_RPM [--oil-temperature-c C]
Prints the message counts per topic as JSON.
"""
import json
import math
import sys
from pathlib import Path

from rosbags.rosbag2 import StoragePlugin, Writer
from rosbags.typesys import Stores, get_typestore

BETA_DEG = 50.0
out, seconds, rpm = Path(sys.argv[1]), float(sys.argv[2]), float(sys.argv[3])
store = get_typestore(Stores.ROS2_JAZZY)
Float64 = store.types["std_msgs/msg/Float64"]
Header = store.types["std_msgs/msg/Header"]
Temperature = store.types["sensor_msgs/msg/Temperature"]
oil_c = float(sys.argv[sys.argv.index("--oil-temperature-c") + 1]) \
    if "--oil-temperature-c" in sys.argv else None
Time = store.types["builtin_interfaces/msg/Time"]

t0 = 1_767_225_600_000_000_000  # 2026-01-01T00:00:00Z, ns
omega = rpm * math.pi / 30.0
period = 2 * math.pi / omega
events = []  # (ns, topic, message, type)
k = 0
while k * period <= seconds:
    ns = t0 + round(k * period * 1e9)
    stamp = Time(sec=ns // 1_000_000_000, nanosec=ns % 1_000_000_000)
    events.append((ns, "/plant/keyphasor", Header(stamp=stamp, frame_id="keyphasor"), "std_msgs/msg/Header"))
    k += 1
probes = []
for station in ("probe_pulley_end", "probe_outboard"):
    for suffix, alpha in (("x", 45.0), ("y", 135.0)):
        probes.append((f"/plant/{station}_{suffix}", math.radians(BETA_DEG + alpha)))
dt = period / 16
k = 0
while k * dt <= seconds:
    ns = t0 + round(k * dt * 1e9)
    psi = omega * k * dt
    for topic, lag in probes:
        d_um = 2.0 * math.cos(psi - lag)
        events.append((ns, topic, Float64(data=1000.0 - d_um), "std_msgs/msg/Float64"))
    k += 1
if oil_c is not None:
    k, values = 0, []
    while k * 0.1 <= seconds:
        values.append((t0 + round(k * 0.1e9), oil_c))
        k += 1
    values.append((values[-1][0] + 1_000_000, float("nan")))
    for ns, c in values:
        stamp = Time(sec=ns // 1_000_000_000, nanosec=ns % 1_000_000_000)
        events.append((ns, "/plant/oil_temperature",
                       Temperature(header=Header(stamp=stamp, frame_id="oil_supply"),
                                   temperature=c, variance=0.0),
                       "sensor_msgs/msg/Temperature"))
events.sort(key=lambda e: e[0])

counts = {}
with Writer(out, version=9, storage_plugin=StoragePlugin.MCAP) as writer:
    conns = {"/plant/keyphasor": writer.add_connection("/plant/keyphasor", "std_msgs/msg/Header", typestore=store)}
    for topic, _ in probes:
        conns[topic] = writer.add_connection(topic, "std_msgs/msg/Float64", typestore=store)
    if oil_c is not None:
        conns["/plant/oil_temperature"] = writer.add_connection(
            "/plant/oil_temperature", "sensor_msgs/msg/Temperature", typestore=store)
    for ns, topic, msg, msgtype in events:
        writer.write(conns[topic], ns, store.serialize_cdr(msg, msgtype))
        counts[topic] = counts.get(topic, 0) + 1
print(json.dumps(counts))

"""Writes a rosbag2 MCAP bag with PyPI `rosbags` (an independent writer), in the standard types a
plant's recording carries: speed as std_msgs/Float64 in rpm on /plant/speed_rpm (100 Hz), probe
pairs as geometry_msgs/PointStamped (x, y in m) on /plant/probe_a and /plant/probe_b (16 samples a
revolution: a 2 µm forward 1X circle about a static offset), and an unrelated /plant/oil_temp.

Usage: write_bag.py OUT_DIR SECONDS SPEED_RPM
Prints the message counts per topic as JSON.
"""
import json
import math
import sys
from pathlib import Path

from rosbags.rosbag2 import StoragePlugin, Writer
from rosbags.typesys import Stores, get_typestore

out, seconds, rpm = Path(sys.argv[1]), float(sys.argv[2]), float(sys.argv[3])
store = get_typestore(Stores.ROS2_JAZZY)
Float64 = store.types["std_msgs/msg/Float64"]
PointStamped = store.types["geometry_msgs/msg/PointStamped"]
Point = store.types["geometry_msgs/msg/Point"]
Header = store.types["std_msgs/msg/Header"]
Time = store.types["builtin_interfaces/msg/Time"]

t0 = 1_767_225_600_000_000_000  # 2026-01-01T00:00:00Z, ns
omega = rpm * math.pi / 30.0
events = []  # (ns, topic, message, type)
k = 0
while k * 0.01 <= seconds:
    events.append((t0 + round(k * 0.01e9), "/plant/speed_rpm", Float64(data=rpm), "std_msgs/msg/Float64"))
    k += 1
dt = 2 * math.pi / omega / 16
k = 0
while k * dt <= seconds:
    ns = t0 + round(k * dt * 1e9)
    a = omega * k * dt
    stamp = Time(sec=ns // 1_000_000_000, nanosec=ns % 1_000_000_000)
    for topic, (x0, y0) in (("/plant/probe_a", (2e-6, -20e-6)), ("/plant/probe_b", (1e-6, -18e-6))):
        p = Point(x=x0 + 2e-6 * math.cos(a), y=y0 + 2e-6 * math.sin(a), z=0.0)
        events.append((ns, topic, PointStamped(header=Header(stamp=stamp, frame_id=topic), point=p), "geometry_msgs/msg/PointStamped"))
    k += 1
events.append((t0 + 5_000_000, "/plant/oil_temp", Float64(data=45.0), "std_msgs/msg/Float64"))
events.sort(key=lambda e: e[0])

counts = {}
with Writer(out, version=9, storage_plugin=StoragePlugin.MCAP) as writer:
    conns = {}
    for topic, msgtype in (("/plant/speed_rpm", "std_msgs/msg/Float64"), ("/plant/probe_a", "geometry_msgs/msg/PointStamped"), ("/plant/probe_b", "geometry_msgs/msg/PointStamped"), ("/plant/oil_temp", "std_msgs/msg/Float64")):
        conns[topic] = writer.add_connection(topic, msgtype, typestore=store)
    for ns, topic, msg, msgtype in events:
        writer.write(conns[topic], ns, store.serialize_cdr(msg, msgtype))
        counts[topic] = counts.get(topic, 0) + 1
print(json.dumps(counts))

"""Reads a rosbag2 MCAP bag with two independent readers and prints what each saw, as JSON.

Usage: read_bag.py BAG_DIR_OR_MCAP [--stream]
  rosbags (AnyReader, types from the bag's own schemas) and mcap + mcap-ros2-support (decoder).
  --stream: read the .mcap as a stream (no summary needed: a recording cut off by a kill).
"""
import json
import sys
from pathlib import Path

path = Path(sys.argv[1])
stream = "--stream" in sys.argv
out = {}

mcap_file = path if path.suffix == ".mcap" else next(path.glob("*.mcap"))
from mcap.reader import make_reader
from mcap.stream_reader import StreamReader
from mcap.records import Channel, Message, Schema
from mcap_ros2.decoder import DecoderFactory

counts, first = {}, {}
if stream:
    channels, schemas = {}, {}
    factory = DecoderFactory()
    decoders = {}
    with open(mcap_file, "rb") as f:
        try:
            for record in StreamReader(f, skip_magic=False).records:
                if isinstance(record, Schema):
                    schemas[record.id] = record
                elif isinstance(record, Channel):
                    channels[record.id] = record
                elif isinstance(record, Message):
                    ch = channels[record.channel_id]
                    if ch.id not in decoders:
                        decoders[ch.id] = factory.decoder_for(ch.message_encoding, schemas[ch.schema_id])
                    msg = decoders[ch.id](record.data)
                    counts[ch.topic] = counts.get(ch.topic, 0) + 1
                    first.setdefault(ch.topic, {k: getattr(msg, k) for k in msg.__slots__ if isinstance(getattr(msg, k), (int, float, str, bool))})
        except Exception as e:  # a truncated file ends in a broken record
            out["stream_error"] = type(e).__name__
    out["mcap_stream"] = {"counts": counts, "first": first}
else:
    with open(mcap_file, "rb") as f:
        reader = make_reader(f, decoder_factories=[DecoderFactory()])
        out["profile"] = reader.get_header().profile
        for schema, channel, message, decoded in reader.iter_decoded_messages():
            counts[channel.topic] = counts.get(channel.topic, 0) + 1
            first.setdefault(channel.topic, {"type": schema.name, **{k: getattr(decoded, k) for k in decoded.__slots__ if isinstance(getattr(decoded, k), (int, float, str, bool))}})
    out["mcap_ros2"] = {"counts": counts, "first": first}

    from rosbags.highlevel import AnyReader
    counts = {}
    types = {}
    with AnyReader([path]) as reader:
        for conn, timestamp, raw in reader.messages():
            msg = reader.deserialize(raw, conn.msgtype)
            counts[conn.topic] = counts.get(conn.topic, 0) + 1
            types[conn.topic] = conn.msgtype
    out["rosbags"] = {"counts": counts, "types": types}

def finite(v):
    """JSON has no NaN or infinity: a recorded bad input is shown as text."""
    if isinstance(v, float) and (v != v or v in (float("inf"), float("-inf"))):
        return str(v)
    if isinstance(v, dict):
        return {k: finite(x) for k, x in v.items()}
    return v


print(json.dumps(finite(out)))

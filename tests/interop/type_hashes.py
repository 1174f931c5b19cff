"""Prints, as JSON, the RIHS01 type hashes of a rosbag2 MCAP bag's topics as the bag states them
(MCAP channel metadata `topic_type_hash`, metadata.yaml `type_description_hash`) beside the hashes
rosbags computes independently: for rotor_twin_msgs from the .msg files in MSG_DIR, for the
standard types from rosbags' own ROS 2 Jazzy type store.

Usage: type_hashes.py BAG_DIR MSG_DIR
"""
import json
import sys
from pathlib import Path

from ruamel.yaml import YAML
from mcap.reader import make_reader
from rosbags.typesys import Stores, get_typestore, get_types_from_msg

bag, msg_dir = Path(sys.argv[1]), Path(sys.argv[2])
store = get_typestore(Stores.ROS2_JAZZY)
ours = {}
for f in sorted(msg_dir.glob("*.msg")):
    ours.update(get_types_from_msg(f.read_text(), f"rotor_twin_msgs/msg/{f.stem}"))
store.register(ours)

out = {}
with open(next(bag.glob("*.mcap")), "rb") as f:
    summary = make_reader(f).get_summary()
    for ch in summary.channels.values():
        schema = summary.schemas[ch.schema_id]
        out[ch.topic] = {
            "type": schema.name,
            "mcap": ch.metadata.get("topic_type_hash", ""),
            "rosbags": store.hash_rihs01(schema.name),
        }
meta = YAML(typ="safe").load((bag / "metadata.yaml").read_text())  # rosbags' own YAML library
for t in meta["rosbag2_bagfile_information"]["topics_with_message_count"]:
    tm = t["topic_metadata"]
    out.setdefault(tm["name"], {})["yaml"] = tm["type_description_hash"]
out["_our_types"] = sorted(ours)
print(json.dumps(out))

#!/usr/bin/env python3
"""The ROS 2 bag tests' .db3 writer: the dump of write_bag.mjs (CDR bytes
serialized by @foxglove/rosmsg2-serialization) put into rosbag2's sqlite3
tables with Python's own sqlite3 module.

    python3 write_db3.py DUMP OUT.db3 [--without TABLE]
"""
import json
import sqlite3
import sys


def main():
    dump, out = sys.argv[1], sys.argv[2]
    without = sys.argv[4] if len(sys.argv) > 4 and sys.argv[3] == "--without" else None
    index = json.load(open(dump + ".json"))
    data = open(dump + ".bin", "rb").read()
    db = sqlite3.connect(out)
    if without != "topics":
        db.execute(
            "CREATE TABLE topics(id INTEGER PRIMARY KEY, name TEXT NOT NULL, "
            "type TEXT NOT NULL, serialization_format TEXT NOT NULL, "
            "offered_qos_profiles TEXT NOT NULL)"
        )
        for k, t in enumerate(index["topics"]):
            db.execute(
                "INSERT INTO topics VALUES (?, ?, ?, ?, '')",
                (k + 1, t["name"], t["type"], t["serialization_format"]),
            )
    if without != "messages":
        db.execute(
            "CREATE TABLE messages(id INTEGER PRIMARY KEY, topic_id INTEGER NOT NULL, "
            "timestamp INTEGER NOT NULL, data BLOB NOT NULL)"
        )
        for m in index["messages"]:
            db.execute(
                "INSERT INTO messages(topic_id, timestamp, data) VALUES (?, ?, ?)",
                (
                    m["topic"] + 1,
                    int(m["timestamp"]),
                    data[m["offset"] : m["offset"] + m["length"]],
                ),
            )
    db.commit()
    db.close()


if __name__ == "__main__":
    main()

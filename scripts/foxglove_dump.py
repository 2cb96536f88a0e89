#!/usr/bin/env python3
"""Read a Foxglove file written by `sweeptrace replay --foxglove` with Python's `mcap` package.

Checks the channels (topic, schema name, encodings), that the summary's
statistics match the messages read, that each channel's messages are in
log_time order (the contact queries' two channels, present only for a
trace with contact queries, are written after the sweeps: readers merge
the channels by time) and that every message and schema is JSON; with
--sweeps/--scenes/--contact-queries, the counts.
With --dump FILE, writes one JSON line per schema record
({"schema", "encoding", "data"}) and then one per message ({"topic",
"schema", "log_time", "data"}) for tests/foxglove/validate.mjs. Exits 1 on
any problem. With --trace the file is a sweeptrace trace in JSON (its own
channels, /scene, /sweep, /expected and the contact channels, instead of
the Foxglove file's), dumped the same way so that validate.mjs holds every
message to the schema the trace embeds.

    python3 scripts/foxglove_dump.py OUT.mcap [--sweeps N] [--scenes N] [--dump FILE.jsonl]
    python3 scripts/foxglove_dump.py TRACE.mcap --trace --dump FILE.jsonl
"""

import argparse
import json
import sys

from mcap.reader import make_reader

CHANNELS = {
    "/mesh": "foxglove.SceneUpdate",
    "/balls": "foxglove.SceneUpdate",
    "/sweeps": "foxglove.SceneUpdate",
    "/contacts": "foxglove.SceneUpdate",
    "/expected_outcome": "foxglove.SceneUpdate",
    "/ghosts": "foxglove.SceneUpdate",
    "/decisions": "foxglove.Log",
    "/numbers": "sweeptrace.SweepNumbers",
}
# Present only when the trace has contact queries.
CONTACT_CHANNELS = {
    "/contact_queries": "foxglove.SceneUpdate",
    "/contact_decisions": "foxglove.Log",
}
PER_SWEEP = ["/balls", "/sweeps", "/contacts", "/expected_outcome", "/ghosts", "/decisions", "/numbers"]


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("file")
    parser.add_argument("--sweeps", type=int)
    parser.add_argument("--scenes", type=int)
    parser.add_argument("--contact-queries", type=int)
    parser.add_argument("--dump")
    parser.add_argument("--trace", action="store_true",
                        help="a sweeptrace trace (JSON encoding), not a Foxglove file")
    args = parser.parse_args()
    problems = []
    dump = open(args.dump, "w", encoding="utf-8") if args.dump else None

    with open(args.file, "rb") as f:
        reader = make_reader(f)
        summary = reader.get_summary()
        if summary is None:
            print(f"{args.file}: no summary", file=sys.stderr)
            return 1
        topics = {}
        for channel in summary.channels.values():
            schema = summary.schemas.get(channel.schema_id)
            topics[channel.topic] = schema.name if schema else None
            if schema is not None and schema.encoding != "jsonschema":
                problems.append(f"{channel.topic}: schema encoding {schema.encoding!r}")
            if channel.message_encoding != "json":
                problems.append(f"{channel.topic}: message encoding {channel.message_encoding!r}")
        if args.trace:
            names = set(topics.values())
            if not names or not all(n and n.startswith("sweeptrace.") for n in names):
                problems.append(f"channels {topics}: not a sweeptrace trace's")
        elif topics != CHANNELS and topics != {**CHANNELS, **CONTACT_CHANNELS}:
            problems.append(f"channels {topics}, expected {CHANNELS} (and {CONTACT_CHANNELS} with contact queries)")
        for schema in summary.schemas.values():
            try:
                data = json.loads(schema.data)
            except ValueError as e:
                problems.append(f"schema {schema.name}: not JSON: {e}")
                continue
            if dump:
                dump.write(json.dumps({"schema": schema.name, "encoding": schema.encoding, "data": data}) + "\n")

        counts = {}
        last = {}
        for schema, channel, message in reader.iter_messages(log_time_order=False):
            counts[channel.topic] = counts.get(channel.topic, 0) + 1
            before = last.get(channel.topic)
            if before is not None and message.log_time < before:
                problems.append(f"{channel.topic}: message at log_time {message.log_time} after one at {before}")
            last[channel.topic] = message.log_time
            try:
                data = json.loads(message.data)
            except ValueError as e:
                problems.append(f"{channel.topic}: message at log_time {message.log_time} is not JSON: {e}")
                continue
            if dump:
                dump.write(json.dumps({"topic": channel.topic, "schema": schema.name,
                                       "log_time": message.log_time, "data": data}) + "\n")
        stats = summary.statistics.channel_message_counts if summary.statistics else {}
        for cid, n in stats.items():
            topic = summary.channels[cid].topic
            if counts.get(topic, 0) != n:
                problems.append(f"{topic}: {counts.get(topic, 0)} messages read, statistics say {n}")

    if dump:
        dump.close()
    if args.sweeps is not None:
        for topic in PER_SWEEP:
            # After the first scene, each scene also clears the four scene-entity channels.
            extra = max((args.scenes or 1) - 1, 0) if topic not in ("/decisions", "/numbers") else 0
            if counts.get(topic, 0) != args.sweeps + extra:
                problems.append(f"{topic}: {counts.get(topic, 0)} messages, expected {args.sweeps + extra}")
    if args.contact_queries is not None:
        for topic in CONTACT_CHANNELS:
            if counts.get(topic, 0) != args.contact_queries:
                problems.append(f"{topic}: {counts.get(topic, 0)} messages, expected {args.contact_queries}")
    if args.scenes is not None and counts.get("/mesh", 0) != args.scenes:
        problems.append(f"/mesh: {counts.get('/mesh', 0)} messages, expected {args.scenes}")

    for p in problems:
        print(f"{args.file}: {p}", file=sys.stderr)
    if problems:
        return 1
    print(f"{args.file}: ok ({', '.join(f'{t} {n}' for t, n in sorted(counts.items()))})")
    return 0


if __name__ == "__main__":
    sys.exit(main())

#!/usr/bin/env python3
"""Read a trace recorded by sweeptrace with Python's `mcap` package and check it.

Checks the header's library string, the `sweeptrace` metadata record, the
schema names and encodings of the three channels, that every message is
JSON, and the message counts (against the summary's statistics and, when
given, against --scenes/--sweeps/--expected). Exits 1 on any mismatch.

    venv/bin/python scripts/read_with_python.py TRACE.mcap [--scenes N] [--sweeps N] [--expected N]
"""

import argparse
import json
import sys

from mcap.reader import make_reader

CHANNELS = {
    "/scene": "sweeptrace.Scene",
    "/sweep": "sweeptrace.Sweep",
    "/expected": "sweeptrace.Outcome",
}


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("trace")
    parser.add_argument("--scenes", type=int)
    parser.add_argument("--sweeps", type=int)
    parser.add_argument("--expected", type=int)
    args = parser.parse_args()
    problems = []

    with open(args.trace, "rb") as f:
        reader = make_reader(f)
        header = reader.get_header()
        if not header.library.startswith("sweeptrace "):
            problems.append(f"library is {header.library!r}, expected 'sweeptrace <version>'")
        metadata = {m.name: m.metadata for m in reader.iter_metadata()}
        if metadata.get("sweeptrace", {}).get("format_version") != "1":
            problems.append(f"metadata record 'sweeptrace' lacks format_version = '1': {metadata}")
        summary = reader.get_summary()
        if summary is None:
            problems.append("the trace has no summary")
            summary_counts = {}
        else:
            seen = set()
            for channel in summary.channels.values():
                seen.add(channel.topic)
                want = CHANNELS.get(channel.topic)
                if want is None:
                    continue
                schema = summary.schemas.get(channel.schema_id)
                if schema is None or schema.name != want:
                    problems.append(f"{channel.topic}: schema {schema.name if schema else None!r}, expected {want!r}")
                elif schema.encoding != "jsonschema":
                    problems.append(f"{channel.topic}: schema encoding {schema.encoding!r}, expected 'jsonschema'")
                else:
                    json.loads(schema.data)  # the schema document is JSON
                if channel.message_encoding != "json":
                    problems.append(f"{channel.topic}: message encoding {channel.message_encoding!r}, expected 'json'")
            for topic in CHANNELS:
                if topic not in seen:
                    problems.append(f"channel {topic} is missing")
            stats = summary.statistics.channel_message_counts if summary.statistics else {}
            summary_counts = {summary.channels[cid].topic: n for cid, n in stats.items()}

        counts = {}
        for _schema, channel, message in reader.iter_messages(log_time_order=False):
            counts[channel.topic] = counts.get(channel.topic, 0) + 1
            try:
                json.loads(message.data)
            except ValueError as e:
                problems.append(f"{channel.topic}: message at log_time {message.log_time} is not JSON: {e}")

    for topic in CHANNELS:
        if summary_counts and summary_counts.get(topic, 0) != counts.get(topic, 0):
            problems.append(f"{topic}: {counts.get(topic, 0)} messages read, statistics say {summary_counts.get(topic, 0)}")
    for topic, want in [("/scene", args.scenes), ("/sweep", args.sweeps), ("/expected", args.expected)]:
        if want is not None and counts.get(topic, 0) != want:
            problems.append(f"{topic}: {counts.get(topic, 0)} messages, expected {want}")

    for p in problems:
        print(f"{args.trace}: {p}", file=sys.stderr)
    if problems:
        return 1
    print(f"{args.trace}: ok ({', '.join(f'{t} {n}' for t, n in sorted(counts.items()))})")
    return 0


if __name__ == "__main__":
    sys.exit(main())

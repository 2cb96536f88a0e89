#!/usr/bin/env python3
"""Read a trace recorded by sweeptrace with Python's `mcap` package and check it.

Checks the header's library string, the `sweeptrace` metadata record, the
`sweeptrace.expected_source` record when there is one (at most one; keys
`engine`, not empty, `version` and `setting.<name>`; with --engine, that it
names that engine, --engine-version and exactly the --setting NAME=VALUE
given; with --no-expected-source, that there is none), the schema names and
encodings of the three channels, that every message is a map in the
channels' message encoding (`json`, or with --encoding cbor, CBOR decoded
with `cbor2`, whose numbers must then be 8-byte doubles or integers), and
the message counts (against the summary's statistics and, when given,
against --scenes/--sweeps/--expected/--contacts/--expected-contacts; the
two contact channels are optional, checked alike when present, and every
contact message must have a 3-number centre or a list of contacts). Exits
1 on any mismatch.

    venv/bin/python scripts/read_with_python.py TRACE.mcap [--scenes N] [--sweeps N] [--expected N]
        [--contacts N] [--expected-contacts N]
        [--engine NAME [--engine-version V] [--setting NAME=VALUE ...] | --no-expected-source]
        [--encoding json|cbor]
"""

import argparse
import json
import struct
import sys

from mcap.reader import make_reader

CHANNELS = {
    "/scene": "sweeptrace.Scene",
    "/sweep": "sweeptrace.Sweep",
    "/expected": "sweeptrace.Outcome",
}
# Channels a trace has only when it holds contact queries (checked alike
# when present).
OPTIONAL_CHANNELS = {
    "/contact": "sweeptrace.Contact",
    "/expected_contacts": "sweeptrace.Contacts",
}


SOURCE = "sweeptrace.expected_source"


def setting_arg(text):
    """NAME=VALUE as a pair."""
    name, equals, value = text.partition("=")
    if not equals or not name:
        raise argparse.ArgumentTypeError(f"expected NAME=VALUE, got {text!r}")
    return name, value


def check_source(sources, args):
    """The problems of the expected-source records, against the options."""
    if len(sources) > 1:
        return [f"{len(sources)} metadata records {SOURCE!r}, at most one allowed"]
    if args.no_expected_source:
        return [f"a metadata record {SOURCE!r} is present: {sources[0]}"] if sources else []
    if not sources:
        return [f"no metadata record {SOURCE!r}"] if args.engine is not None else []
    entries = sources[0]
    problems = [f"{SOURCE}: unknown key {key!r}" for key in entries
                if key not in ("engine", "version") and not key.startswith("setting.")]
    if not entries.get("engine"):
        problems.append(f"{SOURCE}: no engine, or an empty one: {entries}")
    if args.engine is not None:
        settings = {k[len("setting."):]: v for k, v in entries.items() if k.startswith("setting.")}
        want = dict(args.setting)
        got = (entries.get("engine"), entries.get("version", ""), settings)
        if got != (args.engine, args.engine_version, want):
            problems.append(f"{SOURCE}: {got}, expected {(args.engine, args.engine_version, want)}")
    return problems


def cbor_doubles_only(data):
    """Whether every float of the CBOR item `data` is an 8-byte double.

    cbor2 decodes half, single and double floats alike, so the bytes are
    walked here: the writer must never shorten a float."""
    pos = 0

    def item():
        nonlocal pos
        initial = data[pos]
        pos += 1
        major, info = initial >> 5, initial & 0x1F
        if major == 7:
            if info in (25, 26):
                return False
            if info == 27:
                struct.unpack(">d", data[pos:pos + 8])
                pos += 8
            return True
        if info < 24:
            value = info
        else:
            size = {24: 1, 25: 2, 26: 4, 27: 8}[info]
            value = int.from_bytes(data[pos:pos + size], "big")
            pos += size
        if major in (2, 3):
            pos += value
            return True
        if major == 4:
            return all([item() for _ in range(value)])
        if major == 5:
            return all([item() for _ in range(2 * value)])
        if major == 6:
            return item()
        return True

    return item() and pos == len(data)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("trace")
    parser.add_argument("--scenes", type=int)
    parser.add_argument("--sweeps", type=int)
    parser.add_argument("--expected", type=int)
    parser.add_argument("--contacts", type=int, help="/contact messages")
    parser.add_argument("--expected-contacts", type=int, help="/expected_contacts messages")
    parser.add_argument("--engine", help="the expected source's engine")
    parser.add_argument("--engine-version", default="", help="its version ('' when absent)")
    parser.add_argument("--setting", action="append", default=[], metavar="NAME=VALUE",
                        type=setting_arg,
                        help="one of its settings (all of them must be given)")
    parser.add_argument("--no-expected-source", action="store_true")
    parser.add_argument("--encoding", choices=["json", "cbor"], default="json",
                        help="the message encoding the three channels must use")
    args = parser.parse_args()
    if args.encoding == "cbor":
        import cbor2
        decode = cbor2.loads
    else:
        decode = json.loads
    problems = []

    with open(args.trace, "rb") as f:
        reader = make_reader(f)
        header = reader.get_header()
        if not header.library.startswith("sweeptrace "):
            problems.append(f"library is {header.library!r}, expected 'sweeptrace <version>'")
        records = list(reader.iter_metadata())
        metadata = {m.name: m.metadata for m in records}
        if metadata.get("sweeptrace", {}).get("format_version") != "1":
            problems.append(f"metadata record 'sweeptrace' lacks format_version = '1': {metadata}")
        sources = [m.metadata for m in records if m.name == SOURCE]
        problems += check_source(sources, args)
        summary = reader.get_summary()
        if summary is None:
            problems.append("the trace has no summary")
            summary_counts = {}
        else:
            seen = set()
            for channel in summary.channels.values():
                seen.add(channel.topic)
                want = CHANNELS.get(channel.topic, OPTIONAL_CHANNELS.get(channel.topic))
                if want is None:
                    continue
                schema = summary.schemas.get(channel.schema_id)
                if schema is None or schema.name != want:
                    problems.append(f"{channel.topic}: schema {schema.name if schema else None!r}, expected {want!r}")
                elif schema.encoding != "jsonschema":
                    problems.append(f"{channel.topic}: schema encoding {schema.encoding!r}, expected 'jsonschema'")
                else:
                    json.loads(schema.data)  # the schema document is JSON
                if channel.message_encoding != args.encoding:
                    problems.append(f"{channel.topic}: message encoding {channel.message_encoding!r}, expected {args.encoding!r}")
            for topic in CHANNELS:
                if topic not in seen:
                    problems.append(f"channel {topic} is missing")
            stats = summary.statistics.channel_message_counts if summary.statistics else {}
            summary_counts = {summary.channels[cid].topic: n for cid, n in stats.items()}

        counts = {}
        for _schema, channel, message in reader.iter_messages(log_time_order=False):
            counts[channel.topic] = counts.get(channel.topic, 0) + 1
            if channel.topic not in CHANNELS and channel.topic not in OPTIONAL_CHANNELS:
                continue
            try:
                value = decode(message.data)
            except ValueError as e:
                problems.append(f"{channel.topic}: message at log_time {message.log_time} is not {args.encoding}: {e}")
                continue
            if not isinstance(value, dict):
                problems.append(f"{channel.topic}: message at log_time {message.log_time} is not a map: {value!r}")
            elif channel.topic == "/contact" and not (
                    isinstance(value.get("centre"), list) and len(value["centre"]) == 3):
                problems.append(f"{channel.topic}: message at log_time {message.log_time}: centre {value.get('centre')!r} is not 3 numbers")
            elif channel.topic == "/expected_contacts" and not isinstance(value.get("contacts"), list):
                problems.append(f"{channel.topic}: message at log_time {message.log_time}: contacts {value.get('contacts')!r} is not a list")
            elif channel.topic == "/sweep" and not isinstance(value.get("radius"), float):
                problems.append(f"{channel.topic}: message at log_time {message.log_time}: radius {value.get('radius')!r} is not a float")
            if args.encoding == "cbor" and not cbor_doubles_only(message.data):
                problems.append(f"{channel.topic}: message at log_time {message.log_time} has a float shorter than 8 bytes")

    for topic in [*CHANNELS, *OPTIONAL_CHANNELS]:
        if summary_counts and summary_counts.get(topic, 0) != counts.get(topic, 0):
            problems.append(f"{topic}: {counts.get(topic, 0)} messages read, statistics say {summary_counts.get(topic, 0)}")
    for topic, want in [("/scene", args.scenes), ("/sweep", args.sweeps), ("/expected", args.expected),
                        ("/contact", args.contacts), ("/expected_contacts", args.expected_contacts)]:
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

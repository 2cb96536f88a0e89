#!/usr/bin/env python3
"""Rewrite a trace with Python's `mcap` so that its two chunks overlap in log time.

A multi-threaded recorder writes such files: each thread fills a chunk of
its own, so messages of different chunks interleave in time. Chunk 1 gets
the messages of every channel up to the first sweep, then those of the
even frames; chunk 2 those of the odd frames. Every message keeps its
channel, log time and bytes. Writes two files: one with the summary
(chunk indexes, statistics), and the same data section with the summary
left out (the footer points at no summary).

    venv/bin/python scripts/write_out_of_order.py IN.mcap WITH_SUMMARY.mcap WITHOUT_SUMMARY.mcap
"""

import json
import struct
import sys

from mcap.reader import make_reader
from mcap.writer import CompressionType, Writer

MAGIC = b"\x89MCAP0\r\n"
OP_FOOTER = 0x02
OP_DATA_END = 0x0F


def frame_of(data):
    try:
        return json.loads(data).get("frame")
    except ValueError:
        return None


def rewrite(source, target):
    with open(source, "rb") as f:
        reader = make_reader(f)
        header = reader.get_header()
        messages = list(reader.iter_messages(log_time_order=True))
    with open(target, "wb") as out:
        writer = Writer(out, compression=CompressionType.ZSTD, chunk_size=1 << 30)
        writer.start(profile=header.profile, library=header.library)
        schema_ids, channel_ids = {}, {}
        for schema, channel, _ in messages:
            if schema is not None and schema.id not in schema_ids:
                schema_ids[schema.id] = writer.register_schema(
                    schema.name, schema.encoding, schema.data
                )
            if channel.id not in channel_ids:
                channel_ids[channel.id] = writer.register_channel(
                    channel.topic,
                    channel.message_encoding,
                    schema_ids.get(channel.schema_id, 0),
                    channel.metadata,
                )
        first, odd = [], []
        for _, channel, message in messages:
            frame = frame_of(message.data) if channel.topic != "/scene" else None
            (odd if frame is not None and frame % 2 == 1 else first).append((channel, message))
        for group in (first, odd):
            for channel, message in group:
                writer.add_message(
                    channel_ids[channel.id],
                    message.log_time,
                    message.data,
                    message.publish_time,
                    message.sequence,
                )
            # One chunk per group: the recorder's threads.
            writer._Writer__finalize_chunk()
        writer.finish()


def without_summary(source, target):
    """The data section of `source` up to its Data End record, then a footer
    that points at no summary."""
    with open(source, "rb") as f:
        data = f.read()
    at = len(MAGIC)
    while True:
        opcode = data[at]
        (length,) = struct.unpack_from("<Q", data, at + 1)
        at += 9 + length
        if opcode == OP_DATA_END:
            break
    footer = struct.pack("<BQQQI", OP_FOOTER, 20, 0, 0, 0)
    with open(target, "wb") as f:
        f.write(data[:at] + footer + MAGIC)


def main():
    source, with_summary, plain = sys.argv[1:4]
    rewrite(source, with_summary)
    without_summary(with_summary, plain)


if __name__ == "__main__":
    main()

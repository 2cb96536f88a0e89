#!/usr/bin/env python3
"""Write tests/fixtures/python_written.mcap with Python's `mcap` package.

This is the format page's example made runnable: a trace written by another
program from docs/TRACE_FORMAT.md alone. The Rust tests read the fixture and
check every value, so keep the values below in sync with tests/trace_io.rs.

    python3 -m venv venv && venv/bin/pip install mcap
    venv/bin/python scripts/write_python_fixture.py [OUT.mcap] [--encoding json|cbor]

With --encoding cbor (needs `cbor2`) the three trace channels are CBOR
(`message_encoding` `cbor`, the same JSON Schemas): the same trace, which
the tests write to a temporary file and read like the fixture.
"""

import argparse
import json
from pathlib import Path

from mcap.writer import CompressionType, Writer

ROOT = Path(__file__).resolve().parent.parent


def schema(name):
    return (ROOT / "schemas" / f"{name}.schema.json").read_bytes()


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("out", nargs="?", type=Path,
                        default=ROOT / "tests" / "fixtures" / "python_written.mcap")
    parser.add_argument("--encoding", choices=["json", "cbor"], default="json")
    args = parser.parse_args()
    if args.encoding == "cbor":
        import cbor2
        encode = cbor2.dumps
    else:
        encode = lambda msg: json.dumps(msg).encode()  # noqa: E731
    with open(args.out, "wb") as f:
        writer = Writer(f, compression=CompressionType.LZ4)
        writer.start(profile="", library="python fixture for sweeptrace")
        writer.add_metadata("recorder", {"engine": "python", "units": "m"})
        ids = {}
        for topic, name, file in [
            ("/scene", "sweeptrace.Scene", "scene"),
            ("/sweep", "sweeptrace.Sweep", "sweep"),
            ("/expected", "sweeptrace.Outcome", "outcome"),
        ]:
            schema_id = writer.register_schema(name=name, encoding="jsonschema", data=schema(file))
            ids[topic] = writer.register_channel(topic=topic, message_encoding=args.encoding,
                                                 schema_id=schema_id)
        # A foreign channel: readers skip it and count it.
        ids["/debug"] = writer.register_channel(topic="/debug", message_encoding="json", schema_id=0)

        def log(topic, t, msg):
            data = json.dumps(msg).encode() if topic == "/debug" else encode(msg)
            writer.add_message(channel_id=ids[topic], log_time=t, publish_time=t, data=data)

        # The triangle of the worked examples, front normal +z.
        log("/scene", 0, {
            "name": "triangle",
            "vertices": [[0.0, 0.0, 0.0], [4.0, 0.0, 0.0], [0.0, 4.0, 0.0]],
            "triangles": [[0, 1, 2]],
        })
        frame_nanos = 16_666_667
        # Worked example 1 (face), 2 (edge), 3 (vertex), then a miss.
        sweeps = [
            ([1.0, 1.0, 3.0], [1.0, 1.0, -3.0]),
            ([2.0, -0.3, 3.0], [2.0, -0.3, -3.0]),
            ([-0.3, -0.2, 3.0], [-0.3, -0.2, -3.0]),
            ([10.0, 10.0, 3.0], [10.0, 10.0, 2.0]),
        ]
        expected = [
            {"alpha": 5 / 12, "kind": "face", "triangle": 0, "normal": [0.0, 0.0, 1.0]},
            {"alpha": 13 / 30, "kind": "edge", "triangle": 0, "feature": 0},
            {"alpha": 0.44226, "kind": "vertex"},
            {"alpha": 1.0, "kind": "none", "triangle": None, "feature": None, "normal": None, "contact": None},
        ]
        for frame, ((p0, p1), outcome) in enumerate(zip(sweeps, expected)):
            t = (frame + 1) * frame_nanos
            log("/sweep", t, {"frame": frame, "radius": 0.5, "p0": p0, "p1": p1})
            log("/expected", t, {"frame": frame, "ball": 0, **outcome})
            log("/debug", t, {"note": f"frame {frame}"})
        # A second ball in the last frame.
        t = 4 * frame_nanos
        log("/sweep", t, {"frame": 3, "ball": 1, "radius": 0.25, "p0": [1.0, 1.0, 1.0], "p1": [1.0, 1.0, 0.0]})
        writer.finish()


if __name__ == "__main__":
    main()

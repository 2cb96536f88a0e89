#!/usr/bin/env python3
"""The smallest engine for sweeptrace's engine protocol (docs/ENGINE_PROTOCOL.md):
it answers "no collision" to every sweep. Used to measure the protocol's
overhead (BENCHMARKS.md); `check` with it reports every hit as a divergence."""

import json
import sys

for line in sys.stdin:
    message = json.loads(line)
    if message["type"] == "sweep":
        answer = {"frame": message["frame"], "ball": message["ball"], "alpha": 1.0, "kind": "none"}
        sys.stdout.write(json.dumps(answer) + "\n")
        sys.stdout.flush()

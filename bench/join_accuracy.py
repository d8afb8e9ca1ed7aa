#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""Joins results files of bench/run_accuracy.sh into one, for bench/make_accuracy.py.

    python3 bench/join_accuracy.py OUT.jsonl FIRST.jsonl MORE.jsonl ...

OUT gets FIRST's field-scene lines (ballistic, gas, charged), then every file's walled lines, each
file's rounds renumbered after the previous files' and tagged with "results_file", the file they
come from. For a run of extra interleaved rounds of the cheap walled points
(WALLED_DTS=60 FIELD_SCENES=0 bash bench/run_accuracy.sh) beside a run of the whole ladder:
make_accuracy.py then gives each code and dt the median of all its rounds and pairs exact mode with
Box2D round by round.
"""

import json
import os
import sys


def main():
    if len(sys.argv) < 3:
        sys.exit(__doc__)
    out, files = sys.argv[1], sys.argv[2:]
    lines, offset = [], 0
    for k, path in enumerate(files):
        top = -1
        with open(path) as f:
            for text in f:
                if not text.strip():
                    continue
                r = json.loads(text)
                if r.get("scene") != "walled":
                    if k == 0:
                        lines.append(r)
                    continue
                top = max(top, r.get("round", 0))
                lines.append(dict(r, round=r.get("round", 0) + offset, results_file=os.path.basename(path)))
        offset += top + 1
    with open(out, "w") as f:
        for r in lines:
            f.write(json.dumps(r) + "\n")


if __name__ == "__main__":
    main()

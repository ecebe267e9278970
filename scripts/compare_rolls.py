#!/usr/bin/env python3
"""Compares facyl_detect's answers on frames taken upright and by a rolled camera.

usage: compare_rolls.py UPRIGHT.jsonl ROLLED.jsonl [ROLLED.jsonl ...]
  e.g. for r in 0 90 180; do build/apps/facyl_detect --roll $r FRAMES... > roll_$r.jsonl; done
       scripts/compare_rolls.py roll_0.jsonl roll_90.jsonl roll_180.jsonl
For each rolled run: frames with an error, and frames whose number of objects or of cylinders
differs from the upright answer by more than one (listed with both counts).
"""
import json
import sys


def load(path):
    frames = {}
    for line in open(path):
        if line.startswith("{"):
            o = json.loads(line)
            frames[o["file"]] = o
    return frames


def counts(o):
    objects = o.get("objects") or []
    return len(objects), sum(bool(d.get("is_cylinder")) for d in objects)


def main(upright_path, rolled_paths):
    upright = load(upright_path)
    for path in rolled_paths:
        rolled = load(path)
        errors, off = 0, []
        for f, o in sorted(upright.items()):
            r = rolled.get(f)
            if r is None or "error" in r:
                errors += 1
                continue
            (n0, c0), (n1, c1) = counts(o), counts(r)
            if abs(n0 - n1) > 1 or abs(c0 - c1) > 1:
                off.append("%s objects %d->%d cylinders %d->%d" % (f, n0, n1, c0, c1))
        print("%s: %d frames, %d with an error, %d off by more than one object or cylinder"
              % (path, len(upright), errors, len(off)))
        for line in off:
            print("  " + line)


if __name__ == "__main__":
    if len(sys.argv) < 3:
        print(__doc__)
        sys.exit(2)
    main(sys.argv[1], sys.argv[2:])

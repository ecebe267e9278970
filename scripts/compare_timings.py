#!/usr/bin/env python3
"""Compares the stage timings of two facyl_detect commands, run in alternated pairs.

    python3 scripts/compare_timings.py PAIRS 'COMMAND_A' 'COMMAND_B'

Each command must print facyl_detect's JSON lines (one per frame, with "timing_ms"). Every
run is summarised by the median of each timing over its frames; the commands run PAIRS times
each, the order swapped every pair (on a shared machine the second of two back-to-back runs
can be faster by 10 % or more). Prints, per timing, the median run of A and of B, the median
of the per-pair ratios B/A and in how many pairs B was faster.

Example (the build before a change against the one after, frames seen 5 times each):
    M=../shared/data/real/mosd; F="$M/learn0.pcd $M/learn20.pcd $M/learn40.pcd"
    python3 scripts/compare_timings.py 12 \\
      "LD_LIBRARY_PATH=... /tmp/before/apps/facyl_detect --repeat 5 $F" \\
      "build/apps/facyl_detect --repeat 5 $F"
"""
import json
import statistics
import subprocess
import sys


def run(command):
    out = subprocess.run(command, shell=True, capture_output=True, text=True)
    rows = [json.loads(line) for line in out.stdout.splitlines() if line.startswith("{")]
    rows = [r for r in rows if "timing_ms" in r]
    if not rows:
        sys.exit(f"compare_timings: no JSON line with timing_ms from: {command}\n{out.stderr}")
    keys = rows[0]["timing_ms"].keys()
    return {k: statistics.median(r["timing_ms"][k] for r in rows) for k in keys}


def main():
    if len(sys.argv) != 4 or not sys.argv[1].isdigit() or int(sys.argv[1]) < 1:
        sys.exit(__doc__)
    pairs, commands = int(sys.argv[1]), sys.argv[2:4]
    runs = ([], [])
    for i in range(pairs):
        for j in (0, 1) if i % 2 == 0 else (1, 0):
            runs[j].append(run(commands[j]))
    for key in runs[0][0]:
        a = [r[key] for r in runs[0]]
        b = [r[key] for r in runs[1]]
        ratios = [y / x for x, y in zip(a, b) if x > 0]
        ratio = f"{statistics.median(ratios):.3f}" if ratios else "n/a"
        faster = sum(r < 1 for r in ratios)
        print(f"{key:24s} A {statistics.median(a):7.2f}  B {statistics.median(b):7.2f}  "
              f"B/A {ratio}  (B faster in {faster}/{len(ratios)})")


if __name__ == "__main__":
    main()

#!/usr/bin/python3
"""Asserts failure rates in facyl_bench's fits.csv (the benchmark's quick test).

Usage: test/bench_expect.py DIR 'SETTING SWEEP LEVEL METHOD OP PERCENT' ...
  e.g. 'practical outliers 5 pcl-ransac >= 50': at least 50% of pcl-ransac's fits fail there.
A failure is what facyl_bench counts: no cylinder, or an axis error above 10 degrees. Prints
every rate it checks; exits 1 when one does not hold (or names no fit), 2 for bad usage.
"""
import csv
import os
import sys


def main():
    if len(sys.argv) < 3:
        sys.exit(__doc__)
    fits = {}  # (setting, sweep, level, method) -> [failed]
    with open(os.path.join(sys.argv[1], "fits.csv")) as f:
        for row in csv.DictReader(f):
            key = (row["setting"], row["sweep"], float(row["level"]), row["method"])
            failed = row["found"] != "1" or float(row["axis_error_deg"]) > 10.0
            fits.setdefault(key, []).append(failed)
    ok = True
    for expectation in sys.argv[2:]:
        words = expectation.split()
        if len(words) != 6 or words[4] not in ("<=", ">="):
            print(f"bench_expect: cannot read '{expectation}'", file=sys.stderr)
            sys.exit(2)
        setting, sweep, level, method, op, percent = words
        runs = fits.get((setting, sweep, float(level), method), [])
        if not runs:
            print(f"FAIL {expectation}: no such fits")
            ok = False
            continue
        rate = 100.0 * sum(runs) / len(runs)
        holds = rate <= float(percent) if op == "<=" else rate >= float(percent)
        print(f"{'ok  ' if holds else 'FAIL'} {setting} {sweep} {level} {method}: "
              f"{sum(runs)}/{len(runs)} failed ({rate:.1f}%), expected {op} {percent}%")
        ok = ok and holds
    sys.exit(0 if ok else 1)


if __name__ == "__main__":
    main()

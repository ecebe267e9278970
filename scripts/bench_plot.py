#!/usr/bin/python3
"""Draws facyl_bench's figure, laid out like the paper's Fig. 10.

Usage: scripts/bench_plot.py DIR   (reads DIR/fits.csv, writes DIR/fig10_<setting>.png)

Rows: axis, radius and position error (log scale), then the failure rate (axis error > 10 deg
or no cylinder); columns: noise, lid outliers, occlusion. One line per method: the median, with
a band from the 25th to the 75th percentile. A fit that found no cylinder counts as an infinite
error, so a median missing from a panel means most fits failed there (see the last row).
"""
import csv
import math
import os
import sys
from collections import defaultdict

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def quantile(values, q):
    v = sorted(values)
    return v[int(q * (len(v) - 1) + 0.5)]


def main():
    if len(sys.argv) != 2:
        sys.exit(__doc__)
    folder = sys.argv[1]
    path = os.path.join(folder, "fits.csv")
    if not os.path.exists(path):
        sys.exit(f"bench_plot: no {path}; run facyl_bench --out {folder} first")
    data = defaultdict(list)  # (setting, sweep, method, level) -> [(axis, radius, position)]
    with open(path) as f:
        for row in csv.DictReader(f):
            found = row["found"] == "1"
            err = tuple(float(row[k]) if found else math.inf
                        for k in ("axis_error_deg", "radius_error_m", "position_error_m"))
            data[(row["setting"], row["sweep"], row["method"], float(row["level"]))].append(err)
    settings = sorted({k[0] for k in data})
    sweeps = [("noise", "noise (sigma / radius)"), ("outliers", "lid outliers (eq. 5)"),
              ("occlusion", "occlusion (eq. 6)")]
    rows = [("axis error (deg)", 1.0), ("radius error (mm)", 1000.0),
            ("position error (mm)", 1000.0)]
    for setting in settings:
        methods = sorted({k[2] for k in data if k[0] == setting})
        fig, axes = plt.subplots(4, 3, figsize=(15, 14), sharex="col")
        for c, (sweep, label) in enumerate(sweeps):
            for r, (name, scale) in enumerate(rows):
                ax = axes[r][c]
                for method in methods:
                    levels = sorted(k[3] for k in data if k[:3] == (setting, sweep, method))
                    if not levels:
                        continue
                    med, lo, hi = [], [], []
                    for level in levels:
                        values = [e[r] * scale for e in data[(setting, sweep, method, level)]]
                        med.append(quantile(values, 0.5))
                        lo.append(quantile(values, 0.25))
                        hi.append(quantile(values, 0.75))
                    x = [100 * v for v in levels]
                    (line,) = ax.plot(x, med, marker="o", markersize=3, label=method)
                    ax.fill_between(x, lo, hi, color=line.get_color(), alpha=0.12)
                ax.set_yscale("log")
                ax.grid(True, which="both", alpha=0.3)
                if c == 0:
                    ax.set_ylabel(name)
            ax = axes[3][c]
            for method in methods:
                levels = sorted(k[3] for k in data if k[:3] == (setting, sweep, method))
                if not levels:
                    continue
                rate = []
                for level in levels:
                    fits = data[(setting, sweep, method, level)]
                    rate.append(100.0 * sum(1 for e in fits if not e[0] <= 10.0) / len(fits))
                ax.plot([100 * v for v in levels], rate, marker="o", markersize=3, label=method)
            ax.set_ylim(-3, 103)
            ax.grid(True, alpha=0.3)
            ax.set_xlabel(label + " (%)")
            if c == 0:
                ax.set_ylabel("failures (%)")
        axes[0][0].legend(fontsize=8, loc="upper left")
        fig.suptitle(f"facyl_bench, setting '{setting}': median and 25-75% band per level")
        fig.tight_layout()
        out = os.path.join(folder, f"fig10_{setting}.png")
        fig.savefig(out, dpi=90)
        print(f"bench_plot: wrote {out}")


if __name__ == "__main__":
    main()

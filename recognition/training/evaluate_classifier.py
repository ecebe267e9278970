#!/usr/bin/python3
"""Precision-recall curves and AUC of facyl's p_cylinder against the paper's inlier ratio
(eq. 4), like the paper's Fig. 11b, on the sets the tools wrote:

  --sim CSV     test_predictions.csv of train_classifier.py (held-out simulated objects)
  --mosd CSV    facyl_tabletop_eval --mosd DIR --csv CSV (rows of set "mosd": the labelled
                objects of learn33-44; cylinder and cylinder_handle are positives)
  --uw CSV      facyl_crops --uw DIR --model M OUT (OUT/objects.csv, source "uw")

    /usr/bin/python3 recognition/training/evaluate_classifier.py --sim ... --mosd ... \
        --uw ... --plot docs/classifier_pr.png

Prints one line per set and score: objects, positives, ROC AUC, average precision.
"""
import argparse
import csv
import math
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from train_classifier import average_precision, pr_curve, roc_auc  # noqa: E402


def number(text, fallback=0.0):
    try:
        v = float(text)
    except ValueError:
        return fallback
    return fallback if math.isnan(v) else v


def sim_set(path):
    rows = list(csv.DictReader(open(path, newline="")))
    y = [int(r["label"]) for r in rows]
    return {"p_cylinder": [number(r["p_cylinder"]) for r in rows],
            "p_network": [number(r["p_network"]) for r in rows],
            "inlier ratio (eq. 4)": [number(r["inlier_ratio"]) for r in rows]}, y


def mosd_set(path):
    rows = [r for r in csv.DictReader(open(path, newline="")) if r["set"] == "mosd"]
    y = [1 if r["kind"] in ("cylinder", "cylinder_handle") else 0 for r in rows]
    return {"p_cylinder": [number(r["p_cylinder"]) for r in rows],
            "p_network": [number(r["p_network"]) for r in rows],
            "inlier ratio (eq. 4)": [number(r["inlier_ratio"]) if r["fitted"] == "1" else 0.0
                                     for r in rows]}, y


def uw_set(path):
    rows = [r for r in csv.DictReader(open(path, newline="")) if r["source"] == "uw"]
    y = [int(r["label"]) for r in rows]
    return {"p_network": [number(r["p_network"]) for r in rows],
            "inlier ratio (eq. 4)": [number(r["inlier_ratio"]) if r["fitted"] == "1" else 0.0
                                     for r in rows]}, y


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--sim")
    ap.add_argument("--mosd")
    ap.add_argument("--uw")
    ap.add_argument("--plot", help="PNG of the precision-recall curves")
    args = ap.parse_args()
    sets = []
    if args.sim:
        sets.append(("simulated, held out", *sim_set(args.sim)))
    if args.mosd:
        sets.append(("mOSD learn33-44 (real)", *mosd_set(args.mosd)))
    if args.uw:
        sets.append(("UW RGB-D crops (real)", *uw_set(args.uw)))
    if not sets:
        sys.exit("evaluate_classifier: give --sim, --mosd and/or --uw")
    print("| set | score | objects | cylinders | ROC AUC | average precision |")
    print("|---|---|---|---|---|---|")
    for name, scores, y in sets:
        for score, s in scores.items():
            print(f"| {name} | {score} | {len(y)} | {sum(y)} | {roc_auc(s, y):.3f} | "
                  f"{average_precision(s, y):.3f} |")
    if args.plot:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        fig, axes = plt.subplots(1, len(sets), figsize=(4.2 * len(sets), 3.8), squeeze=False)
        for ax, (name, scores, y) in zip(axes[0], sets):
            for score, s in scores.items():
                p, r = pr_curve(s, y)
                ax.plot(r, p, label=f"{score} (AUC {roc_auc(s, y):.2f})")
            ax.set_title(f"{name}: {len(y)} objects", fontsize=9)
            ax.set_xlabel("recall")
            ax.set_ylabel("precision")
            ax.set_ylim(0, 1.02)
            ax.legend(fontsize=7, loc="lower left")
        fig.tight_layout()
        fig.savefig(args.plot, dpi=110)
        print(f"evaluate_classifier: wrote {args.plot}")


if __name__ == "__main__":
    main()

#!/usr/bin/python3
"""Precision-recall curves and AUC of facyl's p_cylinder against the paper's inlier ratio
(eq. 4), like the paper's Fig. 11b, on the sets the tools wrote:

  --sim CSV     test_predictions.csv of train_classifier.py (held-out simulated objects)
  --mosd CSV    facyl_tabletop_eval --mosd DIR --csv CSV (rows of set "mosd": the labelled
                objects of learn33-44; cylinder and cylinder_handle are positives)
  --uw CSV      facyl_crops --uw DIR --model M OUT (OUT/objects.csv, source "uw")
  --rgbd JSONL  facyl_detect [--model M] ../shared/data/real/rgbd/*/*.pcd > JSONL, scored with
                --rgbd-labels (labels.csv of that folder), matched as score_frames.py does: a
                label goes to the smallest output box holding its pixel (u, v). Two sets:
                "labelled objects" (cylinder labels against box and bowl labels) and "output
                objects" (every object the recognizer reported: those on a cylinder label
                against those on box or bowl labels, on nothing labelled, or in frames
                without a cylinder; fragments count by their box centre). Objects on
                cylinder_handle and other labels only are listed apart (--list).

    /usr/bin/python3 recognition/training/evaluate_classifier.py --sim ... --mosd ... \
        --uw ... --rgbd ... --rgbd-labels ... --plot docs/classifier_pr.png

Prints one line per set and score: objects, positives, ROC AUC, average precision.
"""
import argparse
import csv
import json
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


def rgbd_objects(jsonl, labels_csv):
    """(frame, label or None, classes, detection) for every labelled object and every output
    object of the rgbd frames; matching as ../shared/tools/score_frames.py."""
    labels, boxes = {}, {}
    for r in csv.DictReader(open(labels_csv, newline="")):
        labels.setdefault(r["frame"], [])
        boxes.setdefault(r["frame"], [])
        if r["class"] == "none":
            continue
        labels[r["frame"]].append(r)
        boxes[r["frame"]].append((r["class"], [float(r[k]) for k in ("u0", "v0", "u1", "v1")]))
    out = {}
    for line in open(jsonl):
        line = line.strip()
        if line.startswith("{"):
            o = json.loads(line)
            f = o.get("file", "")
            key = os.path.basename(os.path.dirname(f)) + "/" + os.path.splitext(os.path.basename(f))[0]
            out.setdefault(key, o)
    inside = lambda b, u, v: b[0] <= u <= b[2] and b[1] <= v <= b[3]
    area = lambda b: (b[2] - b[0]) * (b[3] - b[1])
    labelled, output = [], []
    for frame, labs in sorted(labels.items()):
        dets = [d for d in (out.get(frame) or {}).get("objects") or [] if d.get("bbox")]
        matched = [set() for _ in dets]
        for r in labs:
            u, v = float(r["u"]), float(r["v"])
            hits = [i for i, d in enumerate(dets) if inside(d["bbox"], u, v)]
            best = min(hits, key=lambda i: area(dets[i]["bbox"])) if hits else None
            labelled.append((frame, r, best is not None and dets[best]))
            if best is not None:
                matched[best].add(r["class"])
        for d, cl in zip(dets, matched):
            if not cl:
                b = d["bbox"]
                cu, cv = (b[0] + b[2]) / 2, (b[1] + b[3]) / 2
                cl = {c for c, lb in boxes[frame] if inside(lb, cu, cv)}
            output.append((frame, cl, d))
    return labelled, output


def rgbd_sets(jsonl, labels_csv, listing):
    labelled, output = rgbd_objects(jsonl, labels_csv)
    score = lambda d, k: number(str(d.get(k))) if d else 0.0
    sets = []
    rows = [(f, r, d) for f, r, d in labelled if r["class"] in ("cylinder", "box", "bowl")]
    y = [1 if r["class"] == "cylinder" else 0 for _, r, _ in rows]
    sets.append(("rgbd frames (real), labelled objects",
                 {"p_cylinder": [score(d, "p_cylinder") for _, _, d in rows],
                  "p_network": [score(d, "p_network") for _, _, d in rows]}, y))
    keep = [(f, c, d) for f, c, d in output if "cylinder" in c or not c or c - {"cylinder_handle", "other"}]
    y = [1 if "cylinder" in c else 0 for _, c, _ in keep]
    sets.append(("rgbd frames (real), output objects",
                 {"p_cylinder": [score(d, "p_cylinder") for _, _, d in keep],
                  "p_network": [score(d, "p_network") for _, _, d in keep]}, y))
    for cls in ("cylinder_handle", "other"):
        p = [score(d, "p_cylinder") for _, r, d in labelled if r["class"] == cls]
        called = sum(bool(d and d.get("is_cylinder")) for _, r, d in labelled if r["class"] == cls)
        print(f"rgbd {cls} labels: {len(p)}, called cylinders {called}, p_cylinder mean "
              f"{np.mean(p) if p else float('nan'):.3f}, >= 0.3: {sum(v >= 0.3 for v in p)}")
    if listing:
        for f, r, d in labelled:
            print(f"rgbd label {f} {r['object']} ({r['class']}): p_network {score(d, 'p_network'):.3f} "
                  f"p_cylinder {score(d, 'p_cylinder'):.3f}{' CYLINDER' if d and d.get('is_cylinder') else ''}"
                  f"{'' if d else ' (not found)'}")
        for f, c, d in output:
            if not c or c - {"cylinder", "cylinder_handle", "other"}:
                print(f"rgbd output {f} {d['bbox']} ({','.join(sorted(c)) or 'unlabelled'}): p_network "
                      f"{score(d, 'p_network'):.3f} p_cylinder {score(d, 'p_cylinder'):.3f}"
                      f"{' CYLINDER' if d.get('is_cylinder') else ''}")
    return sets


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--sim")
    ap.add_argument("--mosd")
    ap.add_argument("--uw")
    ap.add_argument("--rgbd", help="facyl_detect output (JSON lines) on the rgbd frames")
    ap.add_argument("--rgbd-labels", help="labels.csv of the rgbd frames")
    ap.add_argument("--list", action="store_true", help="print every rgbd object's scores")
    ap.add_argument("--plot", help="PNG of the precision-recall curves")
    args = ap.parse_args()
    sets = []
    if args.sim:
        sets.append(("simulated, held out", *sim_set(args.sim)))
    if args.mosd:
        sets.append(("mOSD learn33-44 (real)", *mosd_set(args.mosd)))
    if args.uw:
        sets.append(("UW RGB-D crops (real)", *uw_set(args.uw)))
    if args.rgbd:
        if not args.rgbd_labels:
            sys.exit("evaluate_classifier: --rgbd needs --rgbd-labels")
        sets += rgbd_sets(args.rgbd, args.rgbd_labels, args.list)
    if not sets:
        sys.exit("evaluate_classifier: give --sim, --mosd, --uw and/or --rgbd")
    print("| set | score | objects | cylinders | ROC AUC | average precision | others >= 0.3 | "
          "cylinders < 0.3 |")
    print("|---|---|---|---|---|---|---|---|")
    for name, scores, y in sets:
        for score, s in scores.items():
            neg = sum(v >= 0.3 for v, t in zip(s, y) if not t)
            pos = sum(v < 0.3 for v, t in zip(s, y) if t)
            print(f"| {name} | {score} | {len(y)} | {sum(y)} | {roc_auc(s, y):.3f} | "
                  f"{average_precision(s, y):.3f} | {neg} | {pos} |")
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

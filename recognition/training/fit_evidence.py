#!/usr/bin/python3
"""The evidence model of facyl's cylinder decision, fitted and validated leave-one-source-out.

p_cylinder is a logistic regression of evidenceFeatures (C++: the fit's evidence and, with a
classifier, the network's logit). This script collects the recognizer's objects with their
labels from every labelled source there is, fits the model with each source left out in turn and
scores that source with it (the estimate of what a sensor or room never seen will get), then fits
the model on all of them and prints the weights for facyl (kGeometryWeights in
cylinder_evidence.h; the "fusion" line of a classifier's .cfg).

Sources (each one of the sensors, rooms or renderers the recognizer must transfer to):
  sim-kinect, sim-stereo, sim-random   facyl_crops --sim (layouts spread, cluttered, realistic)
  mosd                                  the 45 mOSD learn frames (Kinect; per-pixel labels)
  rgbd-<folder>                         the hand-labelled rgbd frames (labels.csv), one source per
                                        folder (RealSense-class and Kinect v1 rooms)
  uw                                    UW RGB-D Object crops (Kinect, single objects)

Positives are cylinders (cans, tins, tubes); boxes, bowls, cones, spheres and unlabelled objects
(clutter, furniture) are negatives; cups and mugs with handles, open cups and "other" (bottles,
tools, fruit) are neither, as in score_frames.py. Only fits that pass the decision's gates
(passesGates: score, curvature ratio, coverage, arc gap, taper) are the model's to decide.

    /usr/bin/python3 recognition/training/fit_evidence.py --build build \\
        --real ../shared/data/real --out /tmp/evidence [--model none|default|PATH.onnx]

Prints, per source, precision, recall and F1 of the decision left out (rgbd sources: scored as
score_frames.py scores frames, with segmentation recall; mosd: the labelled objects and every
object on a box-only frame; sim: the ground truth; uw: each crop's largest object) and the worst
source; then the weights fitted on every source. The recognizer's own flow (retries and the
cylinder-first recovery ask the decision too) ran with the model built into BUILD, so each left-out
score re-decides the objects that flow produced: an estimate, exact for the built-in weights.
"""
import argparse
import csv
import glob
import json
import math
import os
import pickle
import subprocess
import sys
from collections import Counter, defaultdict

import numpy as np

FEATURES = 20  # facyl::kEvidenceFeatures; the last is the network's logit
LID = 14  # facyl::kLidFeaturesBegin: a lid fit's features (0 for a side's fit) begin here
NETWORK = FEATURES - 1
POSITIVE = {"cylinder", "can", "tin", "tube"}
IGNORED = {"cylinder_handle", "cup_handle", "cup", "cylinder_open", "other", "unknown", "merged",
           "coffee_mug", "mustard"}
CUPS = {"cylinder_handle", "cup_handle", "cup", "cylinder_open", "coffee_mug"}
UW_CYLINDERS = {"soda_can", "food_can", "food_jar", "glue_stick", "marker", "dry_battery",
                "flashlight"}


def label_kind(kind):
    """1 positive, 0 negative, None ignored (as score_frames.py scores)."""
    if kind in POSITIVE:
        return 1
    if kind in IGNORED:
        return None
    return 0


def training_label(kind):
    """What the model learns: cylinders and cups (open, with or without a handle: a cylinder
    wall all the same, which scores ignore) are positives; bottles, tools, fruit and what is
    unknown are left out."""
    if kind in CUPS:
        return 1
    return label_kind(kind)


# --------------------------------------------------------------------------- features

def features_of(obj):
    """The object's evidenceFeatures as the recognizer computed them (detect()'s "features":
    C++ makes them, cylinder_evidence.cpp); None when the object was not fitted."""
    f = obj.get("features")
    if f is None:
        return None
    if len(f) != FEATURES:
        sys.exit("fit_evidence: the recognizer gives %d evidence features, this script expects %d "
                 "(facyl::kEvidenceFeatures)" % (len(f), FEATURES))
    return [float("nan") if v is None else float(v) for v in f]


def logit(p):
    if p is None or not math.isfinite(p):
        return 0.0
    p = min(max(p, 1e-4), 1 - 1e-4)
    return math.log(p / (1 - p))


# --------------------------------------------------------------------------- sources

def read_frame(path):
    import open3d as o3d
    pc = o3d.t.io.read_point_cloud(path)
    pts = pc.point.positions.numpy()
    col = pc.point.colors.numpy() if "colors" in pc.point else None
    lab = pc.point.label.numpy().reshape(-1) if "label" in pc.point else None
    return pts, col, lab


def detect(facyl, pts, col, model, shape=(480, 640), camera=None):
    if camera is None:
        pts = pts.reshape(shape[0], shape[1], 3)
        col = None if col is None else col.reshape(shape[0], shape[1], 3)
    kw = {"model": model}
    if camera is not None:
        kw["camera"] = camera
    return facyl.detect(pts, col, **kw)


def obj_row(source, frame, obj, label, extra=None):
    r = {"source": source, "frame": frame, "label": label, "obj": obj}
    r.update(extra or {})
    return r


def collect_mosd(facyl, real, model):
    classes = {}
    with open(os.path.join(real, "mosd", "labels.csv"), newline="") as f:
        for r in csv.DictReader(f):
            classes[(r["scene"], int(r["object_id"]))] = r["class"]
    rows, truth = [], []
    for k in range(45):
        frame = "learn%d" % k
        pts, col, lab = read_frame(os.path.join(real, "mosd", frame + ".pcd"))
        out = detect(facyl, pts, col, model)
        obj_of = np.where(lab >= 20, lab // 10, 0)
        ids, counts = np.unique(obj_of[obj_of > 0], return_counts=True)
        found = {int(i): False for i in ids}
        for o in out["objects"]:
            idx = np.asarray(o["indices"])
            v, c = np.unique(obj_of[idx], return_counts=True)
            top = int(v[np.argmax(c)])
            if top > 0:
                inter = int((obj_of[idx] == top).sum())
                union = len(idx) + int(counts[list(ids).index(top)]) - inter
                found[top] = found[top] or inter / union >= 0.5
            if top == 0:
                kind = "none"
            elif k <= 24:
                kind = "box"
            elif k <= 32:
                kind = "unknown"
            else:
                kind = classes.get((frame, top), "unknown")
            rows.append(obj_row("mosd", frame, o, kind))
        truth += [("mosd", frame, i, ok) for i, ok in found.items()]
    return rows, truth


def collect_rgbd(facyl, real, model):
    labels = defaultdict(list)
    with open(os.path.join(real, "rgbd", "labels.csv"), newline="") as f:
        for r in csv.DictReader(f):
            labels[r["frame"]]
            if r["class"] != "none":
                labels[r["frame"]].append((r["class"], float(r["u"]), float(r["v"]),
                                           [float(r[k]) for k in ("u0", "v0", "u1", "v1")]))
    frames = []
    for frame, labs in sorted(labels.items()):
        pts, col, _ = read_frame(os.path.join(real, "rgbd", frame + ".pcd"))
        out = detect(facyl, pts, col, model)
        frames.append(("rgbd-" + frame.split("/")[0], frame, labs, out["objects"]))
    return frames


def collect_uw(facyl, real, model):
    rows = []
    for path in sorted(glob.glob(os.path.join(real, "uw_objects", "*.pcd"))):
        stem = os.path.splitext(os.path.basename(path))[0]
        category = stem
        for i in range(len(stem) - 1):
            if stem[i] == "_" and stem[i + 1].isdigit():
                category = stem[:i]
                break
        pts, col, _ = read_frame(path)
        cam = np.stack([pts[:, 0], -pts[:, 2], pts[:, 1]], 1)  # z up, y depth -> camera frame
        ok = np.isfinite(cam).all(1)
        out = detect(facyl, cam[ok].astype(np.float64), None if col is None else col[ok], model,
                     camera=(525.0, 525.0, 319.5, 239.5))
        if not out["objects"]:
            continue
        o = max(out["objects"], key=lambda o: o["n_points"])
        kind = ("cylinder" if category in UW_CYLINDERS else
                "coffee_mug" if category == "coffee_mug" else "none")
        rows.append(obj_row("uw", stem, o, kind))
    return rows


def collect_sim(build, out, scenes, model):
    rows = []
    crops = os.path.join(build, "apps", "facyl_crops")
    for k, sensor in enumerate(("kinect", "stereo", "random")):
        d = os.path.join(out, "sim-" + sensor)
        os.makedirs(d, exist_ok=True)
        cmd = [crops, "--sim", str(scenes), "--seed", str(90000 + 10000 * k), "--layout",
               "spread,cluttered,realistic", "--sensor", sensor, "--model", model, d]
        subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL)
        with open(os.path.join(d, "objects.csv"), newline="") as f:
            for r in csv.DictReader(f):
                if r["fitted"] != "1" or r["kind"] == "table":
                    continue
                x = [float(r["f%d" % i]) for i in range(FEATURES)]
                p = float(r["p_network"]) if r["p_network"] not in ("", "nan") else float("nan")
                rows.append({"source": "sim-" + sensor, "frame": r["scene"], "label": r["kind"],
                             "x": x, "p_network": p, "gates": r["passes_gates"] == "1"})
    return rows


def prepare(row):
    """Adds x (features), p_network and gates to a row from detect()."""
    if "x" in row:
        return row
    o = row["obj"]
    row["x"] = features_of(o)
    row["p_network"] = o.get("p_network") if o.get("p_network") is not None else float("nan")
    row["gates"] = bool(o.get("passes_gates"))  # passesGates under the recognizer's decision
    return row


# --------------------------------------------------------------------------- model

def design(rows, network):
    x = np.array([r["x"] for r in rows], float)
    if network:
        x[:, NETWORK] = [logit(r["p_network"]) for r in rows]
    else:
        x = x[:, :NETWORK]
    return x


def fit_logistic(x, y, weight, l2=0.1, offset=None):
    """Weighted, L2-regularised logistic regression by Newton's method on standardised
    features (plus a fixed \a offset per row); returns the weights of the raw features (bias
    first, unpenalised)."""
    mu = x[:, 1:].mean(0)
    sd = x[:, 1:].std(0) + 1e-6
    z = np.hstack([np.ones((len(x), 1)), (x[:, 1:] - mu) / sd])
    w = np.zeros(z.shape[1])
    weight = weight / weight.sum()
    reg = np.full(z.shape[1], l2)
    reg[0] = 0.0
    base = np.zeros(len(x)) if offset is None else np.asarray(offset, float)
    for _ in range(100):
        p = 1 / (1 + np.exp(-(base + z @ w)))
        g = z.T @ ((p - y) * weight) + reg * w
        h = (z * (weight * p * (1 - p))[:, None]).T @ z + np.diag(reg + 1e-12)
        step = np.linalg.solve(h, g)
        w -= step
        if np.abs(step).max() < 1e-10:
            break
    raw = np.zeros(x.shape[1])
    raw[1:] = w[1:] / sd
    raw[0] = w[0] - (w[1:] * mu / sd).sum()
    return raw


# The direction in which each feature can speak for a cylinder (evidenceFeatures' order; 0:
# either): more of the surface explained, more coverage and a surer network speak for one; a
# curved profile, a taper, normals that disagree with the radial line or point one way, a bent
# axis and points beyond the surface against. A weight that comes out the other way (the
# features overlap) is set to 0 and the rest refitted. The arc gap is a gate only: it is known
# for the parts of the cylinder-first recovery alone. A lid fit's (from LID): its own offset,
# more of the surface explained and more of the rim seen for, the disc seen through and points
# beyond the circle against.
SIGNS = [0, 1, 1, -1, 1, -1, None, -1, -1, -1, -1, None, -1, -1, 0, 1, 1, -1, -1, 1]


def fit_signed(x, y, weight, signs=SIGNS, offset=None):
    use = [i for i, s in enumerate(signs[:x.shape[1]]) if s is not None]
    while True:
        w = np.zeros(x.shape[1])
        w[use] = fit_logistic(x[:, use], y, weight, offset=offset)
        wrong = [i for i in use if signs[i] and np.sign(w[i]) == -signs[i]]
        if not wrong:
            return w
        use = [i for i in use if i not in wrong]


def is_lid(row):
    return row["x"][LID] != 0.0  # a lid fit's own offset feature


def shipped_weights(model):
    """The weights of the model the recognizer decides with: kGeometryWeights (none) or the
    fusion line of the network's .cfg (a fusion of kSideOnlyEvidenceFeatures numbers has no lid
    weights: 0)."""
    here = os.path.dirname(os.path.abspath(__file__))
    if model == "none":
        text = open(os.path.join(here, "..", "include", "facyl", "recognition",
                                 "cylinder_evidence.h")).read()
        body = text[text.index("kGeometryWeights = {") + len("kGeometryWeights = {"):]
        w = [float(v.strip().rstrip("f")) for v in body[:body.index("}")].split(",")]
    else:
        cfg = os.path.join(here, "..", "models", "cylinder_net.cfg") if model == "default" \
            else os.path.splitext(model)[0] + ".cfg"
        line = [l for l in open(cfg) if l.startswith("fusion ")][0]
        w = [float(v) for v in line.split()[1:]]
        if len(w) == LID + 1:
            w = w[:LID] + [0.0] * (FEATURES - 1 - LID) + w[-1:]
    if len(w) != FEATURES:
        sys.exit("fit_evidence: the shipped weights have %d numbers, not %d" % (len(w), FEATURES))
    return np.array(w)


def train(rows, network, keep=None):
    """Each source weighs the same, and within it positives and negatives weigh the same.
    With \a keep (weights): only the lid fits' weights are fitted, on the lid fits, the rest
    (the side's, the shared offset and the network's) kept."""
    data = [r for r in rows if r["gates"] and training_label(r["label"]) is not None]
    if keep is not None:
        data = [r for r in data if is_lid(r)]
    y = np.array([training_label(r["label"]) for r in data], float)
    count = Counter((r["source"], training_label(r["label"])) for r in data)
    weight = np.array([1.0 / count[(r["source"], training_label(r["label"]))] for r in data])
    x = design(data, network)
    if keep is None:
        return fit_signed(x, y, weight)
    w = np.array(keep[:x.shape[1]], float)
    lid = list(range(LID, FEATURES - 1))
    fixed = x @ w - x[:, lid] @ w[lid]  # the shared offset and the network's part
    w[lid] = fit_signed(x[:, lid], y, weight, signs=SIGNS[LID:FEATURES - 1], offset=fixed)
    return w


def decide(rows, w, network):
    """is_cylinder of each row under weights w (gates, then p >= 0.5)."""
    out = []
    for r in rows:
        if not r["gates"]:
            out.append(False)
            continue
        x = design([r], network)[0]
        out.append(float(x @ w) >= 0.0)
    return out


def probabilities(rows, w, network):
    return [1 / (1 + math.exp(-float(design([r], network)[0] @ w))) for r in rows]


def reliability(pairs, bins=10):
    """Calibration of left-out probabilities: per bin of p, (mean p, share positive, count),
    and the expected calibration error."""
    table, ece, total = [], 0.0, len(pairs)
    for b in range(bins):
        lo, hi = b / bins, (b + 1) / bins
        inb = [(p, y) for p, y in pairs if lo <= p < hi or (b == bins - 1 and p == 1.0)]
        if not inb:
            continue
        mp = sum(p for p, _ in inb) / len(inb)
        my = sum(y for _, y in inb) / len(inb)
        table.append((mp, my, len(inb)))
        ece += len(inb) / total * abs(mp - my)
    return table, ece


def plot_reliability(curves, path):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(4.6, 4.2))
    ax.plot([0, 1], [0, 1], color="0.7", lw=1)
    for name, (table, ece) in curves.items():
        line, = ax.plot([t[0] for t in table], [t[1] for t in table], "-", lw=1,
                        label="%s sources (ECE %.3f)" % (name, ece))
        ax.scatter([t[0] for t in table], [t[1] for t in table], s=[4 + 2 * t[2] ** 0.5 * 3 for t in table],
                   color=line.get_color(), zorder=3)
    ax.set_xlabel("p_cylinder (left out)")
    ax.set_ylabel("share that are cylinders")
    ax.set_title("Reliability, left out (marker area ~ objects)")
    ax.legend(fontsize=7, loc="upper left")
    fig.tight_layout()
    fig.savefig(path, dpi=110)


# --------------------------------------------------------------------------- scores

def prf(tp, fp, fn):
    p = tp / (tp + fp) if tp + fp else 1.0
    r = tp / (tp + fn) if tp + fn else 1.0
    f = 2 * p * r / (p + r) if p + r else 0.0
    return p, r, f


def score_objects(rows, calls):
    tp = fp = fn = 0
    for r, c in zip(rows, calls):
        k = label_kind(r["label"])
        if k is None:
            continue
        tp += c and k == 1
        fp += c and k == 0
        fn += (not c) and k == 1
    return tp, fp, fn


def inside(b, u, v):
    return b[0] <= u <= b[2] and b[1] <= v <= b[3]


def score_frames(frames, calls_of):
    """score_frames.py's rules: tp, fp, fn and segmentation recall over labelled frames."""
    tp = fp = npos = clean = nlab = 0
    for source, frame, labs, objs in frames:
        calls = calls_of(frame, objs)
        boxes = [o["bbox"] for o in objs]
        npts = [sum(inside(b, u, v) for _, u, v, _ in labs) for b in boxes]
        matched = defaultdict(set)
        for cls, u, v, _ in labs:
            hits = [i for i, b in enumerate(boxes) if b and inside(b, u, v)]
            best = min(hits, key=lambda i: (boxes[i][2] - boxes[i][0]) * (boxes[i][3] - boxes[i][1])) if hits else None
            ok = best is not None and npts[best] == 1
            nlab += 1
            clean += ok
            if best is not None:
                matched[best].add(cls)
            if cls == "cylinder":
                npos += 1
                tp += best is not None and calls[best] and ok
        for i, o in enumerate(objs):
            cl = matched.get(i, set())
            if not cl and boxes[i]:
                cu, cv = (boxes[i][0] + boxes[i][2]) / 2, (boxes[i][1] + boxes[i][3]) / 2
                cl = {c for c, _, _, b in labs if inside(b, cu, cv)}
            if calls[i] and "cylinder" not in cl and (not cl or cl - {"cylinder_handle", "other"}):
                fp += 1
    return tp, fp, npos - tp, clean / nlab if nlab else float("nan")


def frame_rows(frames):
    """One row per rgbd object, labelled as score_frames.py matches it (for training)."""
    rows = []
    for source, frame, labs, objs in frames:
        for o in objs:
            b = o["bbox"]
            hit = [cls for cls, u, v, _ in labs if b and inside(b, u, v)]
            kind = hit[0] if len(hit) == 1 else ("merged" if hit else "none")
            if kind == "none" and b:
                cu, cv = (b[0] + b[2]) / 2, (b[1] + b[3]) / 2
                part = {c for c, _, _, bb in labs if inside(bb, cu, cv)}
                if part:
                    kind = "cylinder_handle" if part <= {"cylinder", "cylinder_handle", "other"} else "box"
            rows.append(prepare(obj_row(source, frame, o, kind)))
    return rows


# --------------------------------------------------------------------------- main

def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--build", default="build")
    ap.add_argument("--real", default="../shared/data/real")
    ap.add_argument("--out", required=True, help="working folder (simulated crops)")
    ap.add_argument("--model", default="none", help="none | default | PATH.onnx (the network)")
    ap.add_argument("--sim-scenes", type=int, default=300, help="scenes per simulated sensor")
    ap.add_argument("--fit", choices=("all", "lid"), default="all",
                    help="all weights, or only the lid fits' (the side's and the network's kept as "
                         "the model in use has them)")
    ap.add_argument("--json", help="write the per-source table and the weights here")
    ap.add_argument("--rows", help="pickle of the collected objects: read when it exists, else "
                    "written (to refit without running the recognizer again)")
    ap.add_argument("--list", action="store_true", help="list the real objects each left-out "
                    "model decides wrongly")
    ap.add_argument("--plot", help="PNG of the reliability curve of the left-out probabilities "
                    "(simulated and real sources apart)")
    args = ap.parse_args()
    sys.path.insert(0, os.path.join(os.path.abspath(args.build), "python"))
    import facyl
    network = args.model != "none"

    if args.rows and os.path.exists(args.rows):
        with open(args.rows, "rb") as f:
            sim, mosd_rows, mosd_truth, frames, uw = pickle.load(f)
    else:
        sim = collect_sim(args.build, args.out, args.sim_scenes, args.model)
        mosd_rows, mosd_truth = collect_mosd(facyl, args.real, args.model)
        frames = collect_rgbd(facyl, args.real, args.model)
        uw = collect_uw(facyl, args.real, args.model)
        if args.rows:
            for r in mosd_rows + uw:
                r["obj"].pop("indices", None)
            for fr in frames:
                for o in fr[3]:
                    o.pop("indices", None)
            with open(args.rows, "wb") as f:
                pickle.dump((sim, mosd_rows, mosd_truth, frames, uw), f)
    rows = sim + [prepare(r) for r in mosd_rows + uw] + frame_rows(frames)
    rows = [r for r in rows if r["x"] is not None or not r["gates"]]
    for r in rows:
        if r["x"] is None:
            r["x"] = [0.0] * FEATURES
    sources = sorted({r["source"] for r in rows} | {f[0] for f in frames})

    table = {}
    left_out = {"simulated": [], "real": []}  # (p, is a cylinder) of the fits each model decides
    keep = shipped_weights(args.model)[:None if network else NETWORK] if args.fit == "lid" else None
    for s in sources:
        w = train([r for r in rows if r["source"] != s], network, keep)
        judged = [r for r in rows if r["source"] == s and r["gates"] and
                  label_kind(r["label"]) is not None]
        left_out["simulated" if s.startswith("sim") else "real"] += zip(
            probabilities(judged, w, network), [label_kind(r["label"]) for r in judged])
        if s.startswith("rgbd-"):
            mine = [f for f in frames if f[0] == s]
            calls_of = lambda frame, objs: decide([prepare(obj_row(s, frame, o, "")) for o in objs], w, network)
            tp, fp, fn, seg = score_frames(mine, calls_of)
        else:
            mine = [r for r in rows if r["source"] == s]
            tp, fp, fn = score_objects(mine, decide(mine, w, network))
            seg = float("nan")
            if s == "mosd":
                seg = sum(ok for *_, ok in mosd_truth) / len(mosd_truth)
        if args.list and not s.startswith("sim"):
            mine_rows = [r for r in rows if r["source"] == s]
            for r, c in zip(mine_rows, decide(mine_rows, w, network)):
                k = label_kind(r["label"])
                if k is not None and c != bool(k) or (args.list and c and k is None):
                    x = design([r], network)[0]
                    print("  %s %-10s %-22s p=%.2f  %s" % (s, r["label"], r["frame"][:22],
                          1 / (1 + math.exp(-float(x @ w))), " ".join("%.2f" % v for v in r["x"][1:13])))
        p, r, f = prf(tp, fp, fn)
        table[s] = {"tp": tp, "fp": fp, "fn": fn, "precision": p, "recall": r, "f1": f,
                    "segmentation_recall": seg}
    w_all = train(rows, network, keep)
    curves = {k: reliability(v) for k, v in left_out.items() if v}
    for k, (t, ece) in curves.items():
        print("reliability, %s sources left out: ECE %.3f; bins (mean p, share cylinders, n): %s" % (
            k, ece, " ".join("(%.2f %.2f %d)" % b for b in t)))
    if args.plot:
        plot_reliability(curves, args.plot)

    print("Leave-one-source-out (model %s; each source scored by the evidence model fitted "
          "without it):" % args.model)
    print("| source | tp | fp | fn | precision | recall | F1 | segmentation recall |")
    print("|---|---|---|---|---|---|---|---|")
    for s, t in table.items():
        print("| %s | %d | %d | %d | %.3f | %.3f | %.3f | %s |" % (
            s, t["tp"], t["fp"], t["fn"], t["precision"], t["recall"], t["f1"],
            "-" if not math.isfinite(t["segmentation_recall"]) else "%.3f" % t["segmentation_recall"]))
    with_pos = {s: t for s, t in table.items() if t["tp"] + t["fn"] > 0}
    worst = min(with_pos, key=lambda s: with_pos[s]["f1"])
    print("worst source: %s (F1 %.3f); false positives where nothing is a cylinder: %s" % (
        worst, with_pos[worst]["f1"],
        ", ".join("%s %d" % (s, t["fp"]) for s, t in table.items() if s not in with_pos) or "-"))
    full = list(w_all) + ([] if network else [0.0])
    print("weights fitted on every source (kEvidenceFeatures = %d):" % FEATURES)
    print("  " + " ".join("%.6g" % v for v in full))
    if args.json:
        with open(args.json, "w") as f:
            json.dump({"model": args.model, "table": table, "worst": worst, "weights": full}, f,
                      indent=1)


if __name__ == "__main__":
    main()

#!/usr/bin/python3
"""Trains facyl's shape classifier (paper III-B) on the data facyl_crops writes.

One command: reads one or more facyl_crops folders, splits the simulated objects by scene into
train / calibration / test (70 / 15 / 15 %), trains a SqueezeNet-1.1-style network from scratch
with mirrored augmentation (paper IV-B), draws learning curves, exports ONNX (opset 11, batch
dynamic) with its description (.cfg), checks that OpenCV's DNN gives PyTorch's output on the
same input, fits the fusion model (a logistic regression of evidenceFeatures, with the network's
logit, on the calibration split) and reports the held-out test split.

    /usr/bin/python3 recognition/training/train_classifier.py --data DIR... --out OUT \
        [--channels depth|rgb|depthrgb] [--epochs N] [--seed S] [--real-repeat R]

Writes OUT/cylinder_net.onnx, OUT/cylinder_net.cfg, OUT/curves.png, OUT/report.json and
OUT/test_predictions.csv. The images are exactly what facyl's classifierImage makes (C++), so
training and inference share one preprocessing; the network input is (byte - 127.5) / 127.5.
"""
import argparse
import csv
import json
import math
import os
import sys
import time
import zlib

import numpy as np
import torch
import torch.nn as nn
import torch.nn.functional as F

MEAN, SCALE = 127.5, 1.0 / 127.5
CHANNELS = {"rgb": 3, "depth": 2, "depthrgb": 5}
# The files of facyl_crops that make each channel set: depthrgb is depth's planes followed by
# rgb's, as facyl::classifierImage makes it (ClassifierChannels::DepthRgb).
FILES = {"rgb": ("rgb",), "depth": ("depth",), "depthrgb": ("depth", "rgb")}
FUSION_FEATURES = 20  # facyl::kEvidenceFeatures; the last is the network's logit


# ----------------------------------------------------------------------------- data

def load_folder(folder, channels):
    """Rows of objects.csv and the images of one channel set (N x C x S x S uint8)."""
    with open(os.path.join(folder, "objects.csv"), newline="") as f:
        rows = list(csv.DictReader(f))
    parts, size = [], None
    for name in FILES[channels]:
        raw = np.fromfile(os.path.join(folder, name + ".u8"), dtype=np.uint8)
        c = CHANNELS[name]
        per = raw.size // max(1, len(rows))
        s = int(round(math.sqrt(per / c)))
        if len(rows) == 0 or c * s * s * len(rows) != raw.size or (size is not None and s != size):
            sys.exit(f"train_classifier: {folder}: {raw.size} bytes of {name}.u8 do not hold "
                     f"{len(rows)} images of {c} channels")
        size = s
        parts.append(raw.reshape(len(rows), c, s, s))
    return rows, np.concatenate(parts, 1) if len(parts) > 1 else parts[0], size


def split_of(source, scene, train_real=False):
    """0 train, 1 calibration, 2 test: by a hash of the scene, so a scene's objects stay
    together. Real crops harvested for training (source 'real', with train_real) go to train
    (80 %) or calibration, never to the simulated test split; other real data (UW crops) is
    never trained on: 3."""
    h = zlib.crc32(scene.encode()) % 100
    if source == "real" and train_real:
        return 0 if h < 80 else 1
    if source != "sim":
        return 3
    return 0 if h < 70 else (1 if h < 85 else 2)


def load(folders, channels):
    rows, images, size = [], [], None
    for folder in folders:
        r, x, s = load_folder(folder, channels)
        if size is not None and s != size:
            sys.exit("train_classifier: the folders have different image sizes")
        size = s
        rows += r
        images.append(x)
    return rows, np.concatenate(images), size


# ---------------------------------------------------------------------------- network

class Fire(nn.Module):
    """SqueezeNet's fire module: squeeze 1x1, expand 1x1 and 3x3, concatenated."""

    def __init__(self, c_in, squeeze, expand):
        super().__init__()
        self.squeeze = nn.Sequential(nn.Conv2d(c_in, squeeze, 1, bias=False),
                                     nn.BatchNorm2d(squeeze), nn.ReLU(inplace=True))
        self.e1 = nn.Sequential(nn.Conv2d(squeeze, expand, 1, bias=False),
                                nn.BatchNorm2d(expand), nn.ReLU(inplace=True))
        self.e3 = nn.Sequential(nn.Conv2d(squeeze, expand, 3, padding=1, bias=False),
                                nn.BatchNorm2d(expand), nn.ReLU(inplace=True))

    def forward(self, x):
        x = self.squeeze(x)
        return torch.cat([self.e1(x), self.e3(x)], 1)


class CylinderNet(nn.Module):
    """SqueezeNet 1.1's layout (conv, pool, fire pairs between pools, 1x1 classifier, global
    average) at a width and depth for 64 x 64 inputs, with batch normalisation (trains from
    scratch reliably; OpenCV folds it into the convolutions)."""

    def __init__(self, c_in, width=1.0):
        super().__init__()
        w = lambda n: max(4, int(round(n * width)))
        self.features = nn.Sequential(
            nn.Conv2d(c_in, w(32), 3, stride=2, padding=1, bias=False), nn.BatchNorm2d(w(32)),
            nn.ReLU(inplace=True),
            nn.MaxPool2d(3, stride=2, padding=1),
            Fire(w(32), w(8), w(32)), Fire(2 * w(32), w(8), w(32)),
            nn.MaxPool2d(3, stride=2, padding=1),
            Fire(2 * w(32), w(16), w(64)), Fire(2 * w(64), w(16), w(64)),
            nn.MaxPool2d(3, stride=2, padding=1),
            Fire(2 * w(64), w(24), w(96)), Fire(2 * w(96), w(24), w(96)),
        )
        self.classifier = nn.Sequential(nn.Dropout(0.3), nn.Conv2d(2 * w(96), 2, 1))

    def forward(self, x):
        x = self.classifier(self.features(x))
        return torch.flatten(F.adaptive_avg_pool2d(x, 1), 1)


def to_input(batch_u8):
    return (torch.from_numpy(batch_u8).float() - MEAN) * SCALE


def smooth_depth(f, rng, max_sigma):
    """Real depth maps are smooth where the simulator's are sharp: stereo matching windows and
    the sensors' spatial filters round a box's edges (the foam brick and the Spam tin of the
    rgbd frames look like short cans). Blurs the relative depth of half of the images within
    their masks (normalised convolution), by a Gaussian of sigma in [0, max_sigma] pixels."""
    n = len(f)
    sigma = np.round(rng.uniform(0.0, max_sigma, size=n) * 2) / 2 * (rng.random(n) < 0.5)
    for s in np.unique(sigma[sigma > 0]):
        idx = np.flatnonzero(sigma == s)
        r = int(math.ceil(2.5 * s))
        k = np.exp(-0.5 * (np.arange(-r, r + 1) / s) ** 2)
        k = torch.from_numpy((k / k.sum()).astype(np.float32))
        m = torch.from_numpy((f[idx, 0] > 0).astype(np.float32))[:, None]
        d = torch.from_numpy(f[idx, 1] - 128.0)[:, None]
        blur = lambda t: F.conv2d(F.conv2d(t, k.view(1, 1, 1, -1), padding=(0, r)),
                                  k.view(1, 1, -1, 1), padding=(r, 0))
        num, den = blur(d * m), blur(m)
        out = torch.where((m > 0) & (den > 1e-3), num / den.clamp_min(1e-3), d)[:, 0].numpy()
        f[idx, 1] = out + 128.0
    return f


def augment(x, rng, channels, depth_blur=0.0):
    """Mirrored images (paper IV-B), quarter turns (a standing can turned by 90 degrees is a
    lying one; the camera may roll), shifts of up to 4 pixels, and the faults of real depth
    images that the simulator makes too rarely: missing pixels in the object's mask (speckle,
    dark or shiny surfaces), a ragged mask border, depth noise; for RGB, colours randomized:
    gain and offset per channel, the channels swapped, grey. A pixel without depth keeps its
    colour (the camera still sees it)."""
    x = x.copy()
    flip = rng.random(len(x)) < 0.5
    x[flip] = x[flip][..., ::-1]
    turns = rng.integers(0, 4, size=len(x))
    for k in (1, 2, 3):
        m = turns == k
        if m.any():
            x[m] = np.rot90(x[m], k, axes=(2, 3))
    pad = 4
    padded = np.pad(x, ((0, 0), (0, 0), (pad, pad), (pad, pad)), mode="edge")
    out = np.empty_like(x)
    for i in range(len(x)):
        dy, dx = rng.integers(0, 2 * pad + 1, size=2)
        out[i] = padded[i, :, dy:dy + x.shape[2], dx:dx + x.shape[3]]
    f = out.astype(np.float32)
    if channels in ("depth", "depthrgb"):
        n, _, h, w = f.shape
        # Missing pixels: a per-image rate in [0, 0.35], some in 2x2 blocks.
        rate = rng.uniform(0.0, 0.35, size=(n, 1, 1)) * (rng.random((n, 1, 1)) < 0.7)
        holes = rng.random((n, h, w)) < rate
        blocks = rng.random((n, h // 2, w // 2)) < rate / 3
        holes |= np.kron(blocks, np.ones((2, 2), bool))[:, :h, :w]
        f[:, 0][holes] = 0.0
        f[:, 1][holes] = 128.0
        # Depth noise on the object's pixels.
        sigma = rng.uniform(0.0, 6.0, size=(n, 1, 1))
        inside = f[:, 0] > 0
        f[:, 1] += np.where(inside, rng.normal(size=(n, h, w)) * sigma, 0.0)
        if depth_blur > 0:
            f = smooth_depth(f, rng, depth_blur)
    if channels in ("rgb", "depthrgb"):
        c = slice(f.shape[1] - 3, f.shape[1])
        rgb = f[:, c]
        gain = rng.uniform(0.6, 1.4, size=(len(f), 3, 1, 1))
        bias = rng.uniform(-30, 30, size=(len(f), 3, 1, 1))
        rgb = rgb * gain + bias
        if channels == "depthrgb":
            # Colours and textures of the simulator are few: any permutation of the channels.
            order = np.argsort(rng.random((len(f), 3)), axis=1)
            rgb = np.take_along_axis(rgb, order[:, :, None, None], axis=1)
        gray = rng.random(len(f)) < 0.3
        rgb[gray] = rgb[gray].mean(1, keepdims=True)
        f[:, c] = rgb
    out = np.clip(np.rint(f), 0, 255).astype(np.uint8)
    return np.ascontiguousarray(out)


def probabilities(net, images, batch=256):
    net.eval()
    out = []
    with torch.no_grad():
        for i in range(0, len(images), batch):
            out.append(torch.softmax(net(to_input(images[i:i + batch])), 1)[:, 1].numpy())
    return np.concatenate(out) if out else np.zeros(0)


# ---------------------------------------------------------------------------- metrics

def roc_auc(scores, labels):
    """Area under the ROC curve (ties count half)."""
    scores, labels = np.asarray(scores, float), np.asarray(labels, int)
    pos, neg = scores[labels == 1], scores[labels == 0]
    if len(pos) == 0 or len(neg) == 0:
        return float("nan")
    order = np.argsort(np.concatenate([pos, neg]), kind="mergesort")
    ranks = np.empty(len(order))
    allv = np.concatenate([pos, neg])[order]
    ranks[order] = np.arange(1, len(order) + 1)
    # average ranks of ties
    i = 0
    while i < len(allv):
        j = i
        while j + 1 < len(allv) and allv[j + 1] == allv[i]:
            j += 1
        ranks[order[i:j + 1]] = (i + j + 2) / 2.0
        i = j + 1
    return float((ranks[:len(pos)].sum() - len(pos) * (len(pos) + 1) / 2) / (len(pos) * len(neg)))


def pr_curve(scores, labels):
    """Precision and recall at every threshold (descending scores)."""
    scores, labels = np.asarray(scores, float), np.asarray(labels, int)
    order = np.argsort(-scores, kind="mergesort")
    tp = np.cumsum(labels[order] == 1)
    fp = np.cumsum(labels[order] == 0)
    total = max(1, int((labels == 1).sum()))
    return tp / np.maximum(1, tp + fp), tp / total


def average_precision(scores, labels):
    p, r = pr_curve(scores, labels)
    r_prev = np.concatenate([[0.0], r[:-1]])
    return float(np.sum((r - r_prev) * p))


def calibration_error(p, labels, bins=10):
    """Expected calibration error over equal-width bins."""
    p, labels = np.asarray(p, float), np.asarray(labels, int)
    e = 0.0
    for b in range(bins):
        m = (p >= b / bins) & (p < (b + 1) / bins if b < bins - 1 else p <= 1.0)
        if m.any():
            e += m.mean() * abs(p[m].mean() - labels[m].mean())
    return float(e)


# ----------------------------------------------------------------------------- fusion

def fusion_matrix(rows, p_network):
    """evidenceFeatures of facyl (C++ wrote f0..f18), f19 = logit(p) clamped as C++ does."""
    x = np.array([[float(r[f"f{i}"]) for i in range(FUSION_FEATURES)] for r in rows], float)
    p = np.clip(np.asarray(p_network, float), 1e-4, 1 - 1e-4)
    x[:, FUSION_FEATURES - 1] = np.log(p / (1 - p))
    return x


def fit_logistic(x, y, l2=1e-3, steps=3000):
    """L2-regularised logistic regression by Newton's method (the bias is not penalised)."""
    w = np.zeros(x.shape[1])
    reg = np.full(x.shape[1], l2 * len(x))
    reg[0] = 0.0
    for _ in range(steps):
        z = x @ w
        p = 1 / (1 + np.exp(-z))
        g = x.T @ (p - y) + reg * w
        h = (x * (p * (1 - p))[:, None]).T @ x + np.diag(reg + 1e-9)
        step = np.linalg.solve(h, g)
        w -= step
        if np.abs(step).max() < 1e-9:
            break
    return w


def fused(w, x):
    return 1 / (1 + np.exp(-(x @ w)))


# ------------------------------------------------------------------------------ export

def export(net, c, size, out_dir, channels, fusion_w):
    net.eval()
    onnx_path = os.path.join(out_dir, "cylinder_net.onnx")
    dummy = torch.zeros(1, c, size, size)
    torch.onnx.export(net, dummy, onnx_path, opset_version=11, input_names=["input"],
                      output_names=["logits"],
                      dynamic_axes={"input": {0: "batch"}, "logits": {0: "batch"}})
    with open(os.path.join(out_dir, "cylinder_net.cfg"), "w") as f:
        f.write("# facyl shape classifier (recognition/training/train_classifier.py)\n")
        f.write(f"channels {channels}\nsize {size}\nmean {MEAN}\nscale {SCALE:.10f}\n")
        f.write("output softmax\n")
        if fusion_w is not None:
            f.write("fusion " + " ".join(f"{v:.6g}" for v in fusion_w) + "\n")
    return onnx_path


def opencv_agrees(onnx_path, net, images):
    """Max |p_opencv - p_torch| on \a images, or None without OpenCV's Python module."""
    try:
        import cv2
    except ImportError:
        return None
    cv_net = cv2.dnn.readNetFromONNX(onnx_path)
    blob = to_input(images).numpy()
    cv_net.setInput(blob)
    logits = cv_net.forward()
    e = np.exp(logits - logits.max(1, keepdims=True))
    p_cv = e[:, 1] / e.sum(1)
    p_torch = probabilities(net, images)
    return float(np.abs(p_cv - p_torch).max())


def plot_curves(history, path):
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        return False
    ep = [h["epoch"] for h in history]
    fig, ax = plt.subplots(1, 2, figsize=(9, 3.5))
    ax[0].plot(ep, [h["train_loss"] for h in history], label="train")
    ax[0].plot(ep, [h["val_loss"] for h in history], label="calibration split")
    ax[0].set_xlabel("epoch"); ax[0].set_ylabel("cross-entropy"); ax[0].legend()
    ax[1].plot(ep, [h["train_acc"] for h in history], label="train")
    ax[1].plot(ep, [h["val_acc"] for h in history], label="calibration split")
    ax[1].plot(ep, [h["val_auc"] for h in history], label="calibration AUC")
    ax[1].set_xlabel("epoch"); ax[1].set_ylabel("accuracy / AUC"); ax[1].legend()
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    return True


# -------------------------------------------------------------------------------- main

def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--data", nargs="+", required=True, help="facyl_crops output folders")
    ap.add_argument("--out", required=True)
    ap.add_argument("--channels", choices=sorted(CHANNELS), default="depth")
    ap.add_argument("--epochs", type=int, default=14)
    ap.add_argument("--batch", type=int, default=64)
    ap.add_argument("--lr", type=float, default=2e-3)
    ap.add_argument("--width", type=float, default=1.0, help="channel width multiplier")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--threads", type=int, default=0, help="torch threads (0: all cores)")
    ap.add_argument("--max-train", type=int, default=0, help="at most this many training images")
    ap.add_argument("--depth-blur", type=float, default=0.0,
                    help="blur half of the depth images by up to this sigma (pixels; 0: off)")
    ap.add_argument("--real-repeat", type=int, default=0,
                    help="train on the real crops (source 'real', facyl_crops --mosd), each "
                         "this many times per epoch (0: not at all)")
    args = ap.parse_args()
    if args.epochs < 1 or args.batch < 1:
        sys.exit("train_classifier: --epochs and --batch must be >= 1")
    torch.manual_seed(args.seed)
    rng = np.random.default_rng(args.seed)
    if args.threads > 0:
        torch.set_num_threads(args.threads)
    else:
        torch.set_num_threads(os.cpu_count() or 1)
    os.makedirs(args.out, exist_ok=True)

    rows, images, size = load(args.data, args.channels)
    labels = np.array([int(r["label"]) for r in rows])
    split = np.array([split_of(r["source"], r["scene"], args.real_repeat > 0) for r in rows])
    train = np.flatnonzero(split == 0)
    if args.max_train:
        train = train[:args.max_train]
    real = np.array([r["source"] == "real" for r in rows])
    if args.real_repeat > 1:
        train = np.concatenate([train] + [train[real[train]]] * (args.real_repeat - 1))
    calib, test = np.flatnonzero(split == 1), np.flatnonzero(split == 2)
    if len(train) == 0:
        sys.exit("train_classifier: no simulated objects to train on")
    if len(calib) == 0:
        print("train_classifier: too few scenes for a calibration split; calibrating on the "
              "training split (a smoke run, not a model)", flush=True)
        calib = train
    c = CHANNELS[args.channels]
    print(f"train_classifier: {len(rows)} objects ({size}x{size}, {args.channels}): train "
          f"{len(train)} ({labels[train].mean():.2f} cylinders, {int(real[train].sum())} real), "
          f"calibration {len(calib)} ({int(real[calib].sum())} real), test {len(test)}",
          flush=True)

    net = CylinderNet(c, args.width)
    opt = torch.optim.AdamW(net.parameters(), lr=args.lr, weight_decay=1e-4)
    steps = args.epochs * math.ceil(len(train) / args.batch)
    sched = torch.optim.lr_scheduler.OneCycleLR(opt, max_lr=args.lr, total_steps=steps)
    history = []
    for epoch in range(1, args.epochs + 1):
        t0 = time.time()
        net.train()
        order = rng.permutation(train)
        total, correct, loss_sum = 0, 0, 0.0
        for i in range(0, len(order), args.batch):
            idx = order[i:i + args.batch]
            x = to_input(augment(images[idx], rng, args.channels, args.depth_blur))
            y = torch.from_numpy(labels[idx]).long()
            logits = net(x)
            loss = F.cross_entropy(logits, y)
            opt.zero_grad()
            loss.backward()
            opt.step()
            sched.step()
            loss_sum += float(loss) * len(idx)
            correct += int((logits.argmax(1) == y).sum())
            total += len(idx)
        p_val = probabilities(net, images[calib])
        y_val = labels[calib]
        val_loss = float(-np.mean(y_val * np.log(np.clip(p_val, 1e-7, 1)) +
                                  (1 - y_val) * np.log(np.clip(1 - p_val, 1e-7, 1))))
        h = {"epoch": epoch, "train_loss": loss_sum / total, "train_acc": correct / total,
             "val_loss": val_loss, "val_acc": float(((p_val >= 0.5) == y_val).mean()),
             "val_auc": roc_auc(p_val, y_val), "seconds": time.time() - t0}
        history.append(h)
        print(f"epoch {epoch}/{args.epochs}: train loss {h['train_loss']:.4f} acc "
              f"{h['train_acc']:.3f} | calibration loss {h['val_loss']:.4f} acc {h['val_acc']:.3f} "
              f"AUC {h['val_auc']:.4f} ({h['seconds']:.0f} s)", flush=True)

    # Fusion on the calibration split's fitted objects.
    p_calib = probabilities(net, images[calib])
    fitted_calib = np.array([rows[i]["fitted"] == "1" for i in calib])
    fusion_w = None
    if fitted_calib.sum() >= 10 and len(set(labels[calib][fitted_calib])) == 2:
        x = fusion_matrix([rows[i] for i in calib[fitted_calib]], p_calib[fitted_calib])
        fusion_w = fit_logistic(x, labels[calib][fitted_calib])
    onnx_path = export(net, c, size, args.out, args.channels, fusion_w)
    diff = opencv_agrees(onnx_path, net, images[calib[:128]])
    if diff is not None:
        print(f"OpenCV DNN vs PyTorch on {min(128, len(calib))} images: max |dp| = {diff:.2e}")
        if diff > 1e-4:
            sys.exit("train_classifier: OpenCV's output differs from PyTorch's")

    # The held-out test split.
    report = {"data": args.data, "channels": args.channels, "size": size, "seed": args.seed,
              "epochs": args.epochs, "width": args.width, "real_repeat": args.real_repeat,
              "depth_blur": args.depth_blur,
              "train": int(len(train)),
              "calibration": int(len(calib)), "test": int(len(test)),
              "opencv_max_abs_diff": diff, "history": history,
              "fusion": None if fusion_w is None else [float(v) for v in fusion_w]}
    if len(test):
        p_test = probabilities(net, images[test])
        y_test = labels[test]
        test_rows = [rows[i] for i in test]
        fitted = np.array([r["fitted"] == "1" for r in test_rows])
        p_final = p_test.copy()
        if fusion_w is not None and fitted.any():
            p_final[fitted] = fused(fusion_w, fusion_matrix([test_rows[i] for i in np.flatnonzero(fitted)],
                                                            p_test[fitted]))
        inlier = np.array([float(r["inlier_ratio"]) if r["fitted"] == "1" else 0.0 for r in test_rows])
        report["test_metrics"] = {
            "auc_network": roc_auc(p_test, y_test), "auc_p_cylinder": roc_auc(p_final, y_test),
            "auc_inlier_ratio": roc_auc(inlier, y_test),
            "ap_network": average_precision(p_test, y_test),
            "ap_p_cylinder": average_precision(p_final, y_test),
            "ap_inlier_ratio": average_precision(inlier, y_test),
            "ece_p_cylinder": calibration_error(p_final, y_test),
            "accuracy_network": float(((p_test >= 0.5) == y_test).mean()),
        }
        with open(os.path.join(args.out, "test_predictions.csv"), "w", newline="") as f:
            w = csv.writer(f)
            w.writerow(["row", "scene", "kind", "label", "fitted", "inlier_ratio", "p_network",
                        "p_cylinder"])
            for r, pn, pf in zip(test_rows, p_test, p_final):
                w.writerow([r["row"], r["scene"], r["kind"], r["label"], r["fitted"],
                            r["inlier_ratio"], f"{pn:.6f}", f"{pf:.6f}"])
        print("test split: " + ", ".join(f"{k} {v:.4f}" for k, v in report["test_metrics"].items()))
    plot_curves(history, os.path.join(args.out, "curves.png"))
    with open(os.path.join(args.out, "report.json"), "w") as f:
        json.dump(report, f, indent=1)
    print(f"train_classifier: wrote {onnx_path}")


if __name__ == "__main__":
    main()

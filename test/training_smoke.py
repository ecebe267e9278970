#!/usr/bin/python3
"""The classifier's training command end to end on a few generated images (CTest
classifier_training_smoke): facyl_crops renders 3 scenes (a mix with the realistic layout and
the random sensor), train_classifier.py runs one tiny epoch for each channel set that a model
may ship with (depth; depthrgb with the blur augmentation), exports ONNX and checks OpenCV
against PyTorch, and the C++ CylinderClassifier loads each export and gives a probability per
object. Skipped (exit 77) without PyTorch.

    training_smoke.py FACYL_CROPS TRAIN_SCRIPT
"""
import csv
import math
import os
import subprocess
import sys
import tempfile

try:
    import torch  # noqa: F401
except ImportError:
    print("training_smoke: PyTorch (python3-torch) is not installed: skipped")
    sys.exit(77)

crops, train = sys.argv[1], sys.argv[2]
with tempfile.TemporaryDirectory() as tmp:
    data, out, check = (os.path.join(tmp, d) for d in ("data", "out", "check"))
    for d in (data, check):
        os.makedirs(d)
    subprocess.run([crops, "--sim", "3", "--seed", "7", "--layout", "spread,realistic",
                    "--sensor", "kinect,random", data], check=True)
    for channels, extra in (("depth", []), ("depthrgb", ["--depth-blur", "2"])):
        model = os.path.join(out, channels)
        subprocess.run(["/usr/bin/python3", train, "--data", data, "--out", model, "--epochs", "1",
                        "--max-train", "48", "--threads", "1", "--seed", "1",
                        "--channels", channels] + extra, check=True)
        for f in ("cylinder_net.onnx", "cylinder_net.cfg", "report.json"):
            if not os.path.isfile(os.path.join(model, f)):
                sys.exit(f"training_smoke: {channels}: {f} was not written")
        checked = os.path.join(check, channels)
        os.makedirs(checked)
        subprocess.run([crops, "--sim", "1", "--seed", "7", "--model",
                        os.path.join(model, "cylinder_net.onnx"), checked], check=True)
        rows = list(csv.DictReader(open(os.path.join(checked, "objects.csv"))))
        p = [float(r["p_network"]) for r in rows]
        if not rows or not all(0.0 <= x <= 1.0 and not math.isnan(x) for x in p):
            sys.exit(f"training_smoke: {channels}: the C++ classifier gave {p}")
        print(f"training_smoke: {channels} ok ({len(rows)} objects classified by the exported "
              f"model)")

#!/usr/bin/python3
"""facyl_viewer under xvfb-run (CTest viewer_screenshots): screenshots of a simulated scene
with --detect, --compare-pcl and --accumulator are written at the asked size, and the accepted
cylinders are drawn (in the cylinder green) where the ground truth puts the cylinders. Also:
a missing file and no display give clear messages. Skipped (exit 77) without xvfb-run.

    viewer_screenshots.py FACYL_VIEWER FACYL_SYNTH FACYL_DETECT
"""
import json
import os
import shutil
import subprocess
import sys
import tempfile

import numpy as np

if not shutil.which("xvfb-run"):
    print("viewer_screenshots: xvfb-run is not installed (apt-get install xvfb): skipped")
    sys.exit(77)
import cv2  # python3-opencv

viewer, synth, detect = sys.argv[1], sys.argv[2], sys.argv[3]
failures = []


def check(name, ok, detail=""):
    print(("ok   " if ok else "FAIL ") + name + ("" if ok else ": " + detail))
    if not ok:
        failures.append(name)


def shot(args, out, size):
    cmd = ["xvfb-run", "-a", "-s", "-screen 0 1600x1200x24", viewer, "--screenshot", out,
           "--size", f"{size[0]},{size[1]}"] + args
    r = subprocess.run(cmd, capture_output=True, text=True, timeout=300)
    img = cv2.imread(out) if os.path.exists(out) else None
    return r, img


def green(img):
    b, g, r = (img[..., i].astype(int) for i in range(3))
    return (g > 90) & (g > 1.5 * r) & (g > 1.5 * b)


with tempfile.TemporaryDirectory() as tmp:
    prefix = os.path.join(tmp, "scene")
    subprocess.run([synth, "--seed", "3", prefix], check=True, capture_output=True)
    scene = prefix + ".pcd"
    truth = json.load(open(prefix + ".json"))
    ids = cv2.imread(prefix + "_ids.png", cv2.IMREAD_UNCHANGED)
    cylinders = [o["id"] for o in truth["objects"] if o["class"] == "cylinder"]

    # --detect: the camera is the sensor's (640 x 480 like the frame), so the image pixels of
    # the ground truth are where the drawn cylinders must be.
    r, img = shot(["--detect", scene], os.path.join(tmp, "detect.png"), (640, 480))
    check("--detect writes 640 x 480", r.returncode == 0 and img is not None and img.shape[:2] == (480, 640),
          f"exit {r.returncode} {r.stderr[-300:]}")
    if img is not None and img.shape[:2] == (480, 640) and cylinders:
        g = green(img)
        on = np.isin(ids, cylinders)
        other = (ids == 0) | (ids == 1)
        share_on, share_off = g[on].mean(), g[other].mean()
        check("cylinder green on the true cylinders", share_on > 0.4 and share_on > 5 * share_off,
              f"green share {share_on:.2f} on cylinders, {share_off:.3f} on table/background")
        print(f"     green share: {share_on:.2f} on the {len(cylinders)} true cylinders, "
              f"{share_off:.3f} on table and background")

    # --detections: facyl_detect's output drawn the same way.
    lines = os.path.join(tmp, "detections.jsonl")
    with open(lines, "w") as f:
        subprocess.run([detect, scene], check=True, stdout=f)
    r, img = shot(["--detections", lines, scene], os.path.join(tmp, "lines.png"), (640, 480))
    check("--detections writes 640 x 480", r.returncode == 0 and img is not None and img.shape[:2] == (480, 640),
          f"exit {r.returncode} {r.stderr[-300:]}")
    if img is not None and img.shape[:2] == (480, 640) and cylinders:
        on = np.isin(ids, cylinders)
        check("--detections: cylinder green on the true cylinders", green(img)[on].mean() > 0.4,
              f"green share {green(img)[on].mean():.2f}")
    with open(os.path.join(tmp, "bad.jsonl"), "w") as f:
        f.write('{"file": "x", "objects": [\n')
    r, _ = shot(["--detections", os.path.join(tmp, "bad.jsonl"), scene], os.path.join(tmp, "bad.png"), (320, 240))
    check("malformed --detections: exit 1 naming the line", r.returncode == 1 and "line 1" in r.stderr,
          f"exit {r.returncode} {r.stderr[-300:]}")

    r, img = shot(["--detect", "--compare-pcl", scene], os.path.join(tmp, "compare.png"), (1000, 400))
    check("--compare-pcl writes 1000 x 400", r.returncode == 0 and img is not None and img.shape[:2] == (400, 1000),
          f"exit {r.returncode} {r.stderr[-300:]}")
    if img is not None:
        check("--compare-pcl: both halves drawn", img[:, :500].std() > 10 and img[:, 500:].std() > 10)

    r, img = shot(["--accumulator", "0", scene], os.path.join(tmp, "acc.png"), (900, 300))
    check("--accumulator writes 900 x 300", r.returncode == 0 and img is not None and img.shape[:2] == (300, 900),
          f"exit {r.returncode} {r.stderr[-300:]}")
    if img is not None:
        thirds = [img[:, k * 300:(k + 1) * 300] for k in range(3)]
        check("--accumulator: three voting modes drawn", all(t.std() > 5 for t in thirds))

    # Clear messages, no crash.
    r, _ = shot([scene + ".missing"], os.path.join(tmp, "none.png"), (320, 240))
    check("missing file: exit 1 with the reason", r.returncode == 1 and "cannot open the file" in r.stderr,
          f"exit {r.returncode} {r.stderr[-300:]}")
    env = {k: v for k, v in os.environ.items() if k != "DISPLAY"}
    r = subprocess.run([viewer, scene], capture_output=True, text=True, env=env, timeout=60)
    check("no display: exit 1 with the reason", r.returncode == 1 and "no X display" in r.stderr,
          f"exit {r.returncode} {r.stderr[-300:]}")
    r = subprocess.run([viewer, "--size", "10,10", scene], capture_output=True, text=True, timeout=60)
    check("bad --size: exit 2", r.returncode == 2 and "--size" in r.stderr, r.stderr[-200:])

sys.exit(1 if failures else 0)

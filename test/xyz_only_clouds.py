#!/usr/bin/python3
"""Clouds without colour (FIELDS x y z, as many grabbers write them) are drawn coloured by depth
(CTest xyz_only_clouds, issue 41): near warm, far cool, never black on black. A simulated frame
(facyl_synth) and, when REAL_DATA is there, PCL's tutorial scene are written again
without their colour; then
- facyl_detect --overlay: the pixels with a point are not black, the near ones warm (red over
  blue), the far ones cool;
- facyl_viewer (when given, under xvfb-run, when there): the same in its scene mode and in --stream (a
  folder of such frames through pcl::PCDGrabber): the screenshot of the frame's size lies on
  the frame's pixels.
A frame with colour keeps its colours (the overlay's pixels are the frame's).
Skipped (exit 77) without Open3D (which reads the frames here).

    xyz_only_clouds.py FACYL_DETECT FACYL_SYNTH REAL_DATA [FACYL_VIEWER]
"""
import os
import shutil
import subprocess
import sys
import tempfile

import numpy as np

try:
    import open3d as o3d
except ImportError:
    print("xyz_only_clouds: Open3D is not installed (python3-open3d): skipped")
    sys.exit(77)
import cv2  # python3-opencv

detect, synth = sys.argv[1], sys.argv[2]
real = sys.argv[3] if len(sys.argv) > 3 else ""
viewer = sys.argv[4] if len(sys.argv) > 4 else ""
failures = []


def check(name, ok, detail=""):
    print(("ok   " if ok else "FAIL ") + name + ("" if ok else ": " + str(detail)[:600]))
    if not ok:
        failures.append(name)


def read_frame(path):
    """An organized PCD file's points as (H, W, 3), NaN without depth, and its VIEWPOINT."""
    width = height = 0
    viewpoint = "0 0 0 1 0 0 0"
    with open(path, "rb") as f:
        for line in f:
            words = line.decode("ascii", "replace").split()
            if words and words[0] == "WIDTH":
                width = int(words[1])
            elif words and words[0] == "HEIGHT":
                height = int(words[1])
            elif words and words[0] == "VIEWPOINT":
                viewpoint = " ".join(words[1:])
            elif words and words[0] == "DATA":
                break
    cloud = o3d.io.read_point_cloud(path, remove_nan_points=False, remove_infinite_points=False)
    return np.asarray(cloud.points, np.float32).reshape(height, width, 3), viewpoint


def write_xyz_frame(path, points, viewpoint):
    """(H, W, 3) points as a binary PCD with the fields x y z only."""
    h, w = points.shape[:2]
    with open(path, "wb") as f:
        f.write((f"VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\nWIDTH {w}\n"
                 f"HEIGHT {h}\nVIEWPOINT {viewpoint}\nPOINTS {w * h}\nDATA binary\n").encode())
        f.write(np.ascontiguousarray(points, np.float32).tobytes())


def judge(name, img, points):
    """The pixels with a point are drawn (not black) and coloured by depth: the nearest fifth
    warm (red over blue), the farthest fifth cool."""
    if img is None or img.shape[:2] != points.shape[:2]:
        check(name + ": an image of the frame's size", False, None if img is None else img.shape)
        return
    z = points[..., 2]
    seen = np.isfinite(z)
    b, g, r = (img[..., i].astype(int) for i in range(3))
    dark = (np.maximum(np.maximum(r, g), b) < 40)[seen].mean()
    near = seen & (z <= np.percentile(z[seen], 20))
    far = seen & (z >= np.percentile(z[seen], 80))
    warm_near, warm_far = (r - b)[near].mean(), (r - b)[far].mean()
    check(name + ": the points are drawn, not black", dark < 0.1,
          f"{dark:.0%} of the pixels with a point are near black")
    check(name + ": near warm, far cool", warm_near > 40 and warm_far < -40,
          f"red - blue: {warm_near:.0f} near, {warm_far:.0f} far")


def shot(args, out, size):
    cmd = ["xvfb-run", "-a", "-s", "-screen 0 1280x1024x24", viewer, "--model", "none",
           "--screenshot", out, "--size", f"{size[1]},{size[0]}"] + args
    r = subprocess.run(cmd, capture_output=True, text=True, timeout=600)
    ok = r.returncode == 0 and os.path.exists(out)
    if not ok:
        check(" ".join(args[:2]) + ": exit 0", False, (r.returncode, r.stderr[-400:]))
    return cv2.imread(out) if ok else None


with tempfile.TemporaryDirectory() as tmp:
    subprocess.run([synth, "--layout", "cluttered", "--seed", "4", os.path.join(tmp, "sim")],
                   check=True, capture_output=True)
    scenes = [("simulated", os.path.join(tmp, "sim.pcd"))]
    tutorial = os.path.join(real, "pcl", "table_scene_mug_stereo_textured.pcd") if real else ""
    if tutorial and os.path.exists(tutorial):
        scenes.append(("PCL's tutorial scene", tutorial))
    else:
        print("skip PCL's tutorial scene: REAL_DATA/pcl not given or absent")
    for name, path in scenes:
        points, viewpoint = read_frame(path)
        xyz = os.path.join(tmp, "xyz_" + os.path.basename(path))
        write_xyz_frame(xyz, points, viewpoint)
        overlay = os.path.join(tmp, "overlay.png")
        r = subprocess.run([detect, "--model", "none", "--overlay", overlay, xyz],
                           capture_output=True, text=True, timeout=600)
        check(f"{name} without colour: facyl_detect --overlay exits 0",
              r.returncode == 0 and os.path.exists(overlay), (r.returncode, r.stderr[-400:]))
        if os.path.exists(overlay):
            judge(f"{name} without colour: facyl_detect --overlay", cv2.imread(overlay), points)
        if viewer and shutil.which("xvfb-run"):
            judge(f"{name} without colour: facyl_viewer",
                  shot([xyz], os.path.join(tmp, "scene.png"), points.shape[:2]), points)
            folder = os.path.join(tmp, "stream_" + str(len(failures)) + os.path.basename(path))
            os.mkdir(folder)
            for k in range(2):
                shutil.copy(xyz, os.path.join(folder, f"f{k}.pcd"))
            judge(f"{name} without colour: facyl_viewer --stream",
                  shot(["--stream", folder], os.path.join(tmp, "stream.png"), points.shape[:2]),
                  points)
        elif viewer:
            print("skip facyl_viewer: xvfb-run is not installed")

    # With colour: the overlay's pixels away from the boxes are the frame's own.
    overlay = os.path.join(tmp, "colour.png")
    subprocess.run([detect, "--model", "none", "--overlay", overlay, os.path.join(tmp, "sim.pcd")],
                   check=True, capture_output=True)
    rgb = cv2.imread(os.path.join(tmp, "sim_rgb.png"))
    img = cv2.imread(overlay)
    same = (np.abs(img.astype(int) - rgb.astype(int)).max(axis=2) <= 2).mean()
    check("a frame with colour keeps its colours in the overlay", same > 0.9,
          f"{same:.0%} of the pixels are the frame's")

print(f"{len(failures)} failure(s)")
sys.exit(1 if failures else 0)

#!/usr/bin/python3
"""No tool writes over an input or over a file that is not plainly an output of the kind asked
for (CTest output_safety). For every tool that writes files, each refused output must exit 2
with a message saying why, and leave every file as it was (same bytes, same time) and no new
file behind. Also: the outputs that are fine are still written.

    output_safety.py BIN_DIR DATA_DIR [FIT_OPEN3D_EXAMPLE]

BIN_DIR holds the tools (facyl_detect, facyl_synth, ...; facyl_viewer when built), DATA_DIR is
the repository's data/ folder. The Open3D example is checked when python3-open3d and the facyl
module (PYTHONPATH) are there.
"""
import hashlib
import os
import shutil
import subprocess
import sys
import tempfile

BIN, DATA = os.path.abspath(sys.argv[1]), os.path.abspath(sys.argv[2])
EXAMPLE = sys.argv[3] if len(sys.argv) > 3 else ""
SCENE = os.path.join(DATA, "default_scene.pcd")
failures = []


def tool(name):
    return os.path.join(BIN, name)


def check(name, ok, detail=""):
    print(("ok   " if ok else "FAIL ") + name + ("" if ok else ": " + detail))
    if not ok:
        failures.append(name)


def snapshot(folder):
    """Every file under folder: its bytes' digest and its modification time."""
    out = {}
    for root, _, files in os.walk(folder):
        for f in files:
            p = os.path.join(root, f)
            st = os.stat(p)
            out[p] = (hashlib.sha256(open(p, "rb").read()).hexdigest(), st.st_mtime_ns)
    return out


def refused(name, cmd, folder, message, cwd=None):
    """cmd must exit 2 with message on standard error and change nothing in folder."""
    before = snapshot(folder)
    r = subprocess.run(cmd, capture_output=True, text=True, timeout=300, cwd=cwd)
    after = snapshot(folder)
    changed = sorted(p for p in set(before) | set(after) if before.get(p) != after.get(p))
    check(name, r.returncode == 2 and message in r.stderr and not changed,
          f"exit {r.returncode}, stderr {r.stderr[-400:]!r}, changed {changed}")


with tempfile.TemporaryDirectory() as tmp:
    # An input folder: scenes under names a user might give.
    d = os.path.join(tmp, "in")
    os.makedirs(d)
    for n in ("a.pcd", "c.pcd", "scene.png", "s.pcd", "s_obj1.pcd"):
        shutil.copy(SCENE, os.path.join(d, n))
    a, c = os.path.join(d, "a.pcd"), os.path.join(d, "c.pcd")
    detect = tool("facyl_detect")

    # facyl_detect --overlay: the PNG name forgotten (issue 20: a.pcd became a PNG, exit 0).
    refused("facyl_detect --overlay a.pcd c.pcd (PNG name forgotten)",
            [detect, "--overlay", a, c], tmp, "this output is a PNG image")
    refused("facyl_detect --overlay=a.pcd c.pcd", [detect, f"--overlay={a}", c], tmp,
            "was the output's name forgotten?")
    refused("facyl_detect --overlay INPUT.png INPUT.png (a PCD named .png)",
            [detect, "--overlay", os.path.join(d, "scene.png"), os.path.join(d, "scene.png")], tmp,
            "is also an input")
    # The same file through another name: a symbolic link to the input.
    link = os.path.join(tmp, "link.png")
    os.symlink(os.path.join(d, "scene.png"), link)
    refused("facyl_detect --overlay LINK-TO-INPUT.png INPUT", [detect, "--overlay", link,
            os.path.join(d, "scene.png")], tmp, "is also an input")
    refused("facyl_detect --overlay FOLDER.png", [detect, "--overlay", d, c], tmp,
            "this output is a PNG image")
    # Several scenes: the folder's generated <stem>.png would be the input scene.png.
    refused("facyl_detect --overlay DIR (a generated name is an input)",
            [detect, "--overlay", d, a, os.path.join(d, "scene.png")], tmp, "which is an input")
    # --save-clusters DIR: s's object 1 would be written to s_obj1.pcd, an input.
    refused("facyl_detect --save-clusters DIR (a generated name is an input)",
            [detect, "--save-clusters", d, os.path.join(d, "s.pcd"), os.path.join(d, "s_obj1.pcd")],
            tmp, "which is an input")
    # --save-clusters DIR where DIR holds an input: the next *.pcd of DIR would read the
    # clusters as scenes (before: written, exit 0).
    refused("facyl_detect --save-clusters DIR DIR/a.pcd (the folder holds an input)",
            [detect, "--save-clusters", d, a], tmp, "holds the input")
    refused("facyl_detect --save-clusters . a.pcd (the same folder, relative)",
            [detect, "--save-clusters", ".", "a.pcd"], tmp, "holds the input", cwd=d)
    # What is fine is still written.
    out = os.path.join(tmp, "out")
    os.makedirs(out)
    r = subprocess.run([detect, "--overlay", os.path.join(out, "a.png"), "--save-clusters", out, a],
                       capture_output=True, text=True, timeout=300)
    check("facyl_detect --overlay out/a.png --save-clusters out: written",
          r.returncode == 0 and os.path.getsize(os.path.join(out, "a.png")) > 0 and
          os.path.exists(os.path.join(out, "a_obj0.pcd")), f"exit {r.returncode} {r.stderr[-300:]}")

    # facyl_synth PREFIX: a name, not a file of its outputs' kinds, not a folder.
    synth = tool("facyl_synth")
    refused("facyl_synth a.pcd (PREFIX with an extension)", [synth, a], tmp, "ends in .pcd")
    refused("facyl_synth DIR/ (PREFIX is a folder)", [synth, d + "/"], tmp, "is a folder")

    # facyl_simulate OUT.pcd: a .pcd, never e.g. a PNG or JSON of someone else's.
    sim = tool("facyl_simulate")
    png = os.path.join(d, "scene.png")
    refused("facyl_simulate OUT.png", [sim, png], tmp, "this output is a PCD point cloud")

    # facyl_crops OUT: a folder; its files never replace an input (--model here).
    crops = tool("facyl_crops")
    with open(os.path.join(out, "objects.csv"), "w") as f:
        f.write("not a model\n")
    refused("facyl_crops --model OUT/objects.csv OUT", [crops, "--sim", "1", "--model",
            os.path.join(out, "objects.csv"), out], tmp, "which is an input")
    refused("facyl_crops FILE (not a folder)", [crops, "--sim", "1", a], tmp, "does not exist")

    # facyl_bench --out: a folder, never an existing file.
    refused("facyl_bench --out FILE", [tool("facyl_bench"), "--quick", "--out", a], tmp,
            "is a file, not a folder")

    # facyl_tabletop_eval --csv: a .csv outside the data set it reads.
    mosd = os.path.join(tmp, "mosd")
    os.makedirs(mosd)
    with open(os.path.join(mosd, "labels.csv"), "w") as f:
        f.write("frame,object,class\n")
    evaluate = tool("facyl_tabletop_eval")
    refused("facyl_tabletop_eval --csv MOSD/labels.csv", [evaluate, "--mosd", mosd, "--csv",
            os.path.join(mosd, "labels.csv"), "--model", "none"], tmp, "--mosd folder")
    refused("facyl_tabletop_eval --csv a.pcd", [evaluate, "--sim", "1", "--csv", a, "--model",
            "none"], tmp, "this output is a CSV table")

    # facyl_viewer --screenshot: a .png that is no input (checked before any display is needed).
    if os.path.exists(tool("facyl_viewer")):
        viewer = tool("facyl_viewer")
        refused("facyl_viewer --screenshot a.pcd c.pcd", [viewer, "--screenshot", a, c], tmp,
                "this output is a PNG image")
        refused("facyl_viewer --screenshot INPUT.png INPUT.png",
                [viewer, "--screenshot", png, png], tmp, "is also an input")
        lines = os.path.join(d, "lines.png")
        with open(lines, "w") as f:
            f.write("{}\n")
        refused("facyl_viewer --screenshot DETECTIONS --detections DETECTIONS",
                [viewer, "--detections", lines, "--screenshot", lines, c], tmp, "is also an input")

    # facyl_fit writes no file at all.
    before = snapshot(tmp)
    subprocess.run([tool("facyl_fit"), a], capture_output=True, timeout=300, cwd=tmp)
    check("facyl_fit writes no file", snapshot(tmp) == before)

    # The Open3D example's --screenshot.
    if EXAMPLE:
        have = subprocess.run(["/usr/bin/python3", "-c", "import open3d, facyl"],
                              capture_output=True).returncode == 0
        if have:
            cyl = os.path.join(d, "cyl.pcd")
            shutil.copy(os.path.join(DATA, "default_cylinder.pcd"), cyl)
            refused("fit_open3d.py FILE --screenshot FILE",
                    ["/usr/bin/python3", EXAMPLE, cyl, "--screenshot", cyl], tmp,
                    "a screenshot is a PNG image")
            refused("fit_open3d.py --screenshot INPUT.png (a cloud named .png)",
                    ["/usr/bin/python3", EXAMPLE, png, "--screenshot", png], tmp, "is also the input")
        else:
            print("skip fit_open3d.py: python3-open3d or the facyl module is missing")

sys.exit(1 if failures else 0)

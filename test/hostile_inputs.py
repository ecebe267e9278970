#!/usr/bin/python3
"""Hostile inputs for the tools, as a batch on a robot would meet them.

Usage: hostile_inputs.py FACYL_FIT FACYL_DETECT CYLINDER.pcd SCENE.pcd

Every file must give its own JSON line with an "error" that names the problem (exit status 1),
never a crash, a hang or gigabytes of memory; every bad option must exit 2 with a message.
Each tool runs with a 60 s timeout and a 3 GiB address-space limit (none under ASan).
"""
import json
import os
import random
import resource
import struct
import subprocess
import sys
import tempfile

FIT, DETECT, CYLINDER, SCENE = sys.argv[1:5]
GOOD = {FIT: CYLINDER, DETECT: SCENE}  # a good file after each bad one: the batch goes on
failures = []


def limits():
    # Under AddressSanitizer (which reserves terabytes of address space) its own checks stand in.
    if "ASAN_OPTIONS" not in os.environ:
        resource.setrlimit(resource.RLIMIT_AS, (3 << 30, 3 << 30))


def run(tool, args):
    try:
        p = subprocess.run([tool] + args, capture_output=True, text=True, timeout=120,
                           preexec_fn=limits)
    except subprocess.TimeoutExpired:
        return None, "", "timeout"
    return p.returncode, p.stdout, p.stderr


def check(name, ok, detail=""):
    print(("ok   " if ok else "FAIL ") + name + ("" if ok else ": " + detail))
    if not ok:
        failures.append(name)


def header(fields="x y z", size="4 4 4", type_="F F F", count="1 1 1", width=10, height=1,
           points=None, data="ascii", viewpoint="0 0 0 1 0 0 0"):
    points = width * height if points is None else points
    return (f"# .PCD v0.7\nVERSION 0.7\nFIELDS {fields}\nSIZE {size}\nTYPE {type_}\n"
            f"COUNT {count}\nWIDTH {width}\nHEIGHT {height}\nVIEWPOINT {viewpoint}\n"
            f"POINTS {points}\nDATA {data}\n").encode()


def plane_points(width, height):
    """An organized view of a table plane 0.6 m below a VGA-like pinhole, cropped."""
    pts = []
    for v in range(height):
        for u in range(width):
            ray = ((u + 300 - width / 2 - 319.5) / 525.0, (v + 240 - 239.5) / 525.0 + 0.3, 1.0)
            t = 0.6 / ray[1]
            pts.append((ray[0] * t, ray[1] * t, ray[2] * t))
    return pts


def expect_file_error(name, content, message, tools=(FIT, DETECT), is_dir=False):
    path = os.path.join(tmp, name)
    if is_dir:
        os.makedirs(path, exist_ok=True)
    elif content is not None:
        with open(path, "wb") as f:
            f.write(content)
    for tool in tools:
        label = f"{os.path.basename(tool)} {name}"
        rc, out, err = run(tool, [path if content is not None or is_dir else name, GOOD[tool]])
        lines = [l for l in out.splitlines() if l.strip()]
        try:
            first = json.loads(lines[0]) if lines else {}
        except json.JSONDecodeError:
            first = {}
        check(label, rc == 1 and message in first.get("error", "") and len(lines) == 2 and
              "error" not in json.loads(lines[1]),
              f"exit {rc}, output {out[:300]!r}, stderr {err[-300:]!r}")


with tempfile.TemporaryDirectory() as tmp:
    # 1. The path: a directory, a device, a missing file.
    expect_file_error("folder.pcd", None, "it is a directory", is_dir=True)
    expect_file_error("/dev/zero", None, "not a regular file")
    expect_file_error("missing.pcd", None, "cannot open the file")
    # 2. Headers that claim more than the file holds (before: gigabytes, or bad_alloc abort).
    expect_file_error("huge_points.pcd", header(width=200000000, data="binary") + b"\0" * 300,
                      "more than facyl reads")
    expect_file_error("truncated.pcd", header(width=100000, data="binary") + b"\0" * 3000,
                      "truncated")
    expect_file_error("huge_points_ascii.pcd", header(width=50000000) + b"0 0 0\n" * 10,
                      "truncated")
    expect_file_error("huge_count.pcd", header(count="1 1 2000000000", data="binary"),
                      "invalid SIZE, TYPE or COUNT")
    expect_file_error("false_compressed.pcd",
                      header(width=1000, data="binary_compressed") +
                      struct.pack("<II", 100, 2000000000) + b"\0" * 100,
                      "compressed data unpacks to")
    expect_file_error("lying_compressed.pcd",
                      header(width=1000, data="binary_compressed") +
                      struct.pack("<II", 100000, 12000) + b"\0" * 100,
                      "corrupt or truncated")
    # 3. Contents that PCL reads but facyl cannot use, named as such.
    expect_file_error("double_xyz.pcd",
                      header(size="8 8 8", data="binary") + b"\0" * 240,
                      "stored as float64")
    expect_file_error("zero_points.pcd", header(width=0, points=0), "POINTS 0")
    expect_file_error("no_xyz.pcd", header(fields="a b c") + b"0 0 0\n" * 10, "no x, y, z")
    expect_file_error("all_nan.pcd", header() + b"nan nan nan\n" * 10, "no finite point")
    expect_file_error("mismatched.pcd", header(size="4 4") + b"0 0 0\n" * 10,
                      "do not have the same length")
    expect_file_error("garbage.pcd", random.Random(11).randbytes(2000), "not a PCD file")
    # A header line of bytes that text tools take for line breaks (NEL, FS, VT, U+2028) and of
    # invalid UTF-8 is quoted byte by byte: one line of valid JSON.
    expect_file_error("line_breaks.pcd", b"\x85\x1c\x0b\xe2\x80\xa8\xff\rVERSION\n" * 3,
                      "unknown header line '\\x85\\x1c\\x0b\\xe2\\x80\\xa8\\xff\\x0dVERSION'")

    # Points that hold no plane: one line on standard error (before: 1,003 lines of PCL's
    # "Sample points too similar or collinear!" and exit 0).
    same = b"0.1 0.2 1\n" * 10
    line = "".join(f"{0.1 + 0.01 * i:.4f} {0.2 + 0.02 * i:.4f} {1 + 0.005 * i:.4f}\n"
                   for i in range(50)).encode()
    for name, body, width in [("identical.pcd", same, 10), ("collinear.pcd", line, 50)]:
        expect_file_error(name, header(width=width) + body, "recognition failed", tools=(DETECT,))
        rc, out, err = run(DETECT, [os.path.join(tmp, name)])
        check(f"facyl_detect {name}: one line on stderr",
              len(err.splitlines()) == 1 and "lie on one line" in err, f"stderr {err[-300:]!r}")

    # 4. Organized clouds too narrow for an image search (an 8-ring scan; before: segfault).
    for w, h in [(12, 480), (640, 12), (640, 5), (8, 64), (1024, 8), (1, 2)]:
        pts = plane_points(w, h)
        body = "".join(f"{x:.5f} {y:.5f} {z:.5f}\n" for x, y, z in pts).encode()
        path = os.path.join(tmp, f"narrow_{w}x{h}.pcd")
        with open(path, "wb") as f:
            f.write(header(width=w, height=h) + body)
        rc, out, err = run(DETECT, [path])
        ok = rc in (0, 1) and out.strip().startswith("{") and len(out.splitlines()) == 1
        check(f"facyl_detect narrow {w}x{h}", ok, f"exit {rc}, {out[:200]!r} {err[-300:]!r}")

    # 5. Two inputs with one name in different folders: two overlays, none overwritten.
    for d in ("a", "b"):
        os.makedirs(os.path.join(tmp, d), exist_ok=True)
        os.symlink(os.path.abspath(SCENE), os.path.join(tmp, d, "scene.pcd"))
    overlays = os.path.join(tmp, "overlays")
    os.makedirs(overlays)
    rc, out, err = run(DETECT, ["--overlay", overlays, os.path.join(tmp, "a", "scene.pcd"),
                                os.path.join(tmp, "b", "scene.pcd")])
    check("facyl_detect same stems", rc == 0 and
          sorted(os.listdir(overlays)) == ["scene-1.png", "scene-2.png"],
          f"exit {rc}, {sorted(os.listdir(overlays))}")

    # 6. Options that used to wrap or saturate, and limits that keep a run bounded.
    bad_options = [
        (FIT, ["--k", "4294967299"], "--k: 4294967299 is not in [3, 1000]"),
        (FIT, ["--seed", "99999999999999999999"], "--seed: 99999999999999999999 is not in"),
        (FIT, ["--seed", "-1"], "--seed: -1 is not in"),
        (FIT, ["--orientations", "20000000"], "--orientations: 20000000 is not in"),
        (FIT, ["--threads", "1e3"], "is not an integer"),
        (FIT, ["--radius-max", "nan"], "is not a number"),
        (DETECT, ["--neighbours", "4294967299"], "--neighbours: 4294967299 is not in [5, 200]"),
        (DETECT, ["--orientations", "20000000"], "--orientations: 20000000 is not in"),
        (DETECT, ["--camera", "525,525,4e4,4e4", "--overlay", os.path.join(tmp, "o.png")],
         "--camera: expected fx,fy,cx,cy with 0 < fx, fy <= 1e5"),
        (DETECT, ["--repeat", "100000"], "--repeat: 100000 is not in [1, 1000]"),
        (DETECT, ["--cluster-size", "1,1e20"], "--cluster-size: expected 1 <= A <= B <= 1e9"),
        (DETECT, ["--radius-limits", "0.01,1e30"], "--radius-limits: expected 0 <= A < B <= 10"),
        (DETECT, ["--min-score", "2"], "--min-score: 2 is not in [0, 1]"),
    ]
    for tool, args, message in bad_options:
        rc, out, err = run(tool, args + [GOOD[tool]])
        check(f"{os.path.basename(tool)} {' '.join(args)}", rc == 2 and message in err,
              f"exit {rc}, stderr {err[-300:]!r}")

print(f"{len(failures)} failed" if failures else "all passed")
sys.exit(1 if failures else 0)

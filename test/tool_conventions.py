#!/usr/bin/python3
"""What every facyl tool does the same way (CTest tool_conventions):

- --version and -h on every tool (-h lists -h and --version), --name=value as well as
  --name value, an option given twice is refused, old spellings still read (--k, --radius-min,
  --radius-max, --method soft-normal);
- exit status: a warning (facyl_detect --overlay on an unorganized cloud without --camera)
  goes to standard error and keeps exit status 0;
- one vocabulary: facyl_detect's "cylinder" objects have exactly facyl_fit's cylinder fields;
  the viewer reads the recognizer's options;
- units: facyl works in metres; facyl_fit refuses a cloud evidently in millimetres and radius
  limits beyond 1 m, and --units mm converts and converts back.

    tool_conventions.py BIN_DIR DATA_DIR
"""
import json
import math
import os
import random
import subprocess
import sys
import tempfile

BIN, DATA = os.path.abspath(sys.argv[1]), os.path.abspath(sys.argv[2])
CYLINDER = os.path.join(DATA, "default_cylinder.pcd")
SCENE = os.path.join(DATA, "default_scene.pcd")
failures = []


def check(name, ok, detail=""):
    print(("ok   " if ok else "FAIL ") + name + ("" if ok else ": " + detail))
    if not ok:
        failures.append(name)


def run(name, *args, cwd=None):
    return subprocess.run([os.path.join(BIN, name)] + list(args), capture_output=True, text=True,
                          timeout=300, cwd=cwd)


def fit(*args):
    r = run("facyl_fit", *args)
    try:
        return r, json.loads(r.stdout.splitlines()[0])
    except (ValueError, IndexError):
        return r, {}


def can_points():
    """A can seen from one side: radius 4 cm, 12 cm high, axis tilted, 0.3 mm noise (seeded)."""
    rng = random.Random(7)
    axis = (0.28, 0.19, 0.94)
    norm = math.sqrt(sum(a * a for a in axis))
    axis = tuple(a / norm for a in axis)
    u = (axis[1], -axis[0], 0.0)
    nu = math.sqrt(u[0] ** 2 + u[1] ** 2)
    u = (u[0] / nu, u[1] / nu, 0.0)
    v = (axis[1] * u[2] - axis[2] * u[1], axis[2] * u[0] - axis[0] * u[2],
         axis[0] * u[1] - axis[1] * u[0])
    pts = []
    for _ in range(1500):
        t, h = rng.uniform(0, 1.3 * math.pi), rng.uniform(0, 0.12)
        r = 0.04 + rng.gauss(0, 0.0003)
        pts.append(tuple(0.8 * (k == 2) + h * axis[k] + r * (math.cos(t) * u[k] + math.sin(t) * v[k])
                         for k in range(3)))
    return pts


def write_pcd(path, xyz):
    with open(path, "w") as f:
        f.write("VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\n"
                f"WIDTH {len(xyz)}\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS {len(xyz)}\n"
                "DATA ascii\n")
        for p in xyz:
            f.write(f"{p[0]:.9g} {p[1]:.9g} {p[2]:.9g}\n")


# ---- --version, -h on every tool
tools = ["facyl_fit", "facyl_detect", "facyl_synth", "facyl_simulate", "facyl_crops",
         "facyl_bench", "facyl_tabletop_eval", "facyl_viewer"]
for t in tools + ["facyl_benchmarks"]:
    if not os.path.exists(os.path.join(BIN, t)):
        print(f"skip {t}: not built")
        continue
    r = run(t, "--version")
    check(f"{t} --version", r.returncode == 0 and r.stdout.startswith(f"{t} (facyl) "),
          f"exit {r.returncode} {r.stdout!r} {r.stderr[-200:]!r}")
    if t == "facyl_benchmarks":
        continue
    r = run(t, "-h")
    check(f"{t} -h lists -h and --version", r.returncode == 0 and "-h, --help" in r.stdout and
          "--version" in r.stdout, f"exit {r.returncode}")

# ---- --name=value, old spellings, an option given twice
_, a = fit("--radius-limits", "0.01,0.25", "--neighbours", "12", CYLINDER)
_, b = fit("--radius-limits=0.01,0.25", "--neighbours=12", CYLINDER)
_, c = fit("--radius-min", "0.01", "--radius-max=0.25", "--k", "12", CYLINDER)
radius = lambda j: j.get("cylinders", [{}])[0].get("radius") if j.get("cylinders") else None
check("facyl_fit --name=value and old spellings give the same fit",
      radius(a) is not None and radius(a) == radius(b) == radius(c), f"{radius(a)} {radius(b)} {radius(c)}")
_, v1 = fit("--voting", "soft-normal", CYLINDER)
_, v2 = fit("--method", "soft-normal", CYLINDER)
check("facyl_fit --method soft-normal is --voting soft-normal",
      radius(v1) is not None and radius(v1) == radius(v2) and v1.get("voting") == "soft-normal" and
      v1.get("method") == "facyl", f"{v1} {v2}")
r, _ = fit("--k", "12", "--neighbours", "12", CYLINDER)
check("an option given twice (--k and --neighbours) is refused",
      r.returncode == 2 and "given twice" in r.stderr, f"exit {r.returncode} {r.stderr!r}")
r, _ = fit("--inliers", CYLINDER)
j = json.loads(r.stdout) if r.returncode == 0 else {}
cyl = (j.get("cylinders") or [{}])[0]
check("facyl_fit --inliers: n_inliers indices", r.returncode == 0 and
      len(cyl.get("inliers", [])) == cyl.get("n_inliers", -1) > 0, r.stderr[-200:])

# ---- exit status: a warning keeps 0, goes to standard error
with tempfile.TemporaryDirectory() as tmp:
    out = os.path.join(tmp, "x.png")
    r = run("facyl_detect", "--overlay", out, CYLINDER)
    try:
        line = json.loads(r.stdout)
    except ValueError:
        line = {}
    check("facyl_detect --overlay x.png UNORGANIZED: exit 0, warning on standard error",
          r.returncode == 0 and "warning" in r.stderr and "--camera" in r.stderr and
          "error" not in line and not os.path.exists(out),
          f"exit {r.returncode} stdout {r.stdout[:200]!r} stderr {r.stderr!r}")

# ---- one vocabulary: the cylinder fields of facyl_detect are facyl_fit's
_, f = fit(CYLINDER)
fit_fields = list((f.get("cylinders") or [{}])[0].keys())
r = run("facyl_detect", SCENE)
scene = json.loads(r.stdout) if r.returncode == 0 else {"objects": []}
detect_fields = [list(o["cylinder"].keys()) for o in scene["objects"] if o["cylinder"]]
check("facyl_detect's cylinder fields are facyl_fit's (base and top included)",
      fit_fields and detect_fields and all(d == fit_fields for d in detect_fields) and
      "base" in fit_fields and "angular_coverage" in fit_fields, f"{fit_fields} vs {detect_fields[:1]}")
if os.path.exists(os.path.join(BIN, "facyl_viewer")):
    r = run("facyl_viewer", "--min-score", "2", SCENE)
    check("facyl_viewer reads the recognizer's options (--min-score checked)",
          r.returncode == 2 and "--min-score: 2 is not in [0, 1]" in r.stderr, r.stderr[-200:])
    r = run("facyl_viewer", "--radius-limits=0.01,0.2", "--prior", "sideways", SCENE)
    check("facyl_viewer --prior checked", r.returncode == 2 and "sideways" in r.stderr, r.stderr[-200:])

# ---- units: metres, millimetres refused or converted
with tempfile.TemporaryDirectory() as tmp:
    pts = can_points()
    m, mm = os.path.join(tmp, "m.pcd"), os.path.join(tmp, "mm.pcd")
    write_pcd(m, pts)
    write_pcd(mm, [(1000 * x, 1000 * y, 1000 * z) for x, y, z in pts])
    r, j = fit(mm)
    check("facyl_fit refuses a cloud in millimetres (exit 1, says metres)",
          r.returncode == 1 and "metres" in j.get("error", "") and "--units mm" in j.get("error", ""),
          f"exit {r.returncode} {r.stdout[:300]!r}")
    r, _ = fit("--radius-limits", "10,250", CYLINDER)
    check("facyl_fit refuses radius limits in millimetres (exit 2)",
          r.returncode == 2 and "metres" in r.stderr, f"exit {r.returncode} {r.stderr!r}")
    r, j = fit("--units", "mm", "--radius-limits", "10,250", mm)
    r_m, jm = fit("--radius-limits", "0.01,0.25", m)
    got, want = radius(j), radius(jm)
    check("facyl_fit --units mm: the metre fit, in millimetres",
          r.returncode == 0 and got is not None and want is not None and
          abs(got - 1000 * want) < 1e-3 * 1000 * want and j.get("units") == "mm",
          f"exit {r.returncode}: {got} mm vs {want} m")
    r, j = fit("--units", "m", mm)
    check("facyl_fit --units m: no check", r.returncode == 0 and "error" not in j, r.stdout[:200])

sys.exit(1 if failures else 0)

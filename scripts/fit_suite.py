#!/usr/bin/python3
"""A synthetic suite for the bare fit (issue 41): 30 random cylinders (radius 0.02-0.5 m, height 2-4 r,
random axis) per case; a failure is no cylinder, radius off by > 10 % or axis off by > 5 deg."""
import json, math, os, random, subprocess, sys, tempfile
import numpy as np
if len(sys.argv) < 3:
    sys.exit("usage: scripts/fit_suite.py FACYL_SIMULATE FACYL_FIT [facyl_fit options...]")
sim, fit = sys.argv[1], sys.argv[2]
extra = sys.argv[3:]
cases = {"clean": [], "lids 100%": ["--lids", "1"], "lids 300%": ["--lids", "3"], "lids 500%": ["--lids", "5"],
         "occlusion 75%": ["--occlusion", "0.75"], "noise 10%": ["--noise", "0.1"], "noise 15%": ["--noise", "0.15"],
         "noise 20%": ["--noise", "0.2"], "noise 30%": ["--noise", "0.3"]}
d = tempfile.mkdtemp(prefix="facyl_fit_suite_")
for name, args in cases.items():
    fails = 0
    errors = []
    for k in range(30):
        rnd = random.Random(1000 + k)
        r = math.exp(rnd.uniform(math.log(0.02), math.log(0.5)))
        h = r * rnd.uniform(2, 4)
        path = os.path.join(d, "c.pcd")
        truth = json.loads(subprocess.run([sim, "--radius", "%.4f" % r, "--height", "%.4f" % h, "--random-axis", "--seed", str(k)] + args + [path], check=True, capture_output=True, text=True).stdout)
        out = json.loads(subprocess.run([fit] + extra + [path], capture_output=True, text=True).stdout.strip().splitlines()[0])
        cyl = out.get("cylinders") or []
        t = truth.get("truth", truth)
        ta = np.array(t["axis"]); tr = t["radius"]
        ok = False
        if cyl:
            c = cyl[0]
            ang = math.degrees(math.acos(min(1, abs(float(np.dot(ta / np.linalg.norm(ta), np.array(c["axis"])))))))
            ok = abs(c["radius"] - tr) / tr <= 0.1 and ang <= 5
            if ok:
                errors.append((abs(c["radius"] - tr) / tr, ang))
        fails += not ok
    e = np.array(errors) if errors else np.full((1, 2), np.nan)
    print("%-14s failures %2d of 30; good fits: radius error median %.3f %%, axis %.3f deg" %
          (name, fails, 100 * np.median(e[:, 0]), np.median(e[:, 1])))

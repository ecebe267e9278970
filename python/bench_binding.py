#!/usr/bin/python3
"""What the Python module costs and what it gives a Python user (figures for the README).

1. Binding overhead: fit_cylinders on simulated clouds of 1800 points called from Python
   (median of R calls, perf_counter around the call) against the same C++ work timed inside
   C++ (facyl._time_fit_in_cpp: normals, curvatures and the fit, default settings),
   interleaved call by call.
2. Against PCL: the same clouds through `facyl_fit --method pcl-ransac` (SACSegmentationFromNormals
   + SACMODEL_CYLINDER on the same normals): radius and axis errors, time.

    PYTHONPATH=build/python /usr/bin/python3 python/bench_binding.py build/apps/facyl_fit [CLOUDS]
"""
import json
import os
import subprocess
import sys
import tempfile
import time

import numpy as np

import facyl

REPEATS = 20


def clouds(n):
    rng = np.random.default_rng(0)
    for seed in range(n):
        yield facyl.simulate_cylinder(radius=float(rng.uniform(0.02, 0.2)), height=0.3,
                                      random_axis=True, points=1800, noise=0.02, seed=seed)


def write_pcd(path, xyz):
    with open(path, "w") as f:
        f.write("VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\n"
                f"WIDTH {len(xyz)}\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS {len(xyz)}\nDATA ascii\n")
        np.savetxt(f, xyz, fmt="%.9g")


def errors(radius, axis, truth):
    rel = abs(radius - truth["radius"]) / truth["radius"] * 100
    ang = np.degrees(np.arccos(min(1.0, abs(float(np.dot(axis, truth["axis"]))))))
    return rel, ang


def main():
    facyl_fit = sys.argv[1]
    n = int(sys.argv[2]) if len(sys.argv) > 2 else 30
    py_ms, cpp_ms, ours, pcl, pcl_ms, pcl_fail = [], [], [], [], [], 0
    with tempfile.TemporaryDirectory() as tmp:
        for k, sim in enumerate(clouds(n)):
            p = sim["points"]
            # Interleaved, so that both see the same caches and clock: a call from Python
            # (timed around it), then the same work timed inside C++.
            t, inner = [], []
            for _ in range(REPEATS):
                t0 = time.perf_counter()
                found = facyl.fit_cylinders(p, radius_limits=(0.01, 0.25))
                t.append((time.perf_counter() - t0) * 1e3)
                inner.append(facyl._time_fit_in_cpp(p, 1))
            py_ms.append(float(np.median(t)))
            cpp_ms.append(float(np.median(inner)))
            c = found[0]
            ours.append(errors(c.radius, c.axis, sim["truth"]))
            path = os.path.join(tmp, f"c{k}.pcd")
            write_pcd(path, p)
            out = json.loads(subprocess.run(
                [facyl_fit, "--method", "pcl-ransac", "--radius-limits", "0.01,0.25", "--seed", "0",
                 path], check=True, capture_output=True, text=True).stdout)
            pcl_ms.append(out["timing_ms"]["normals"] + out["timing_ms"]["fit"])
            if out["cylinders"]:
                r = out["cylinders"][0]
                pcl.append(errors(r["radius"], np.array(r["axis"]), sim["truth"]))
            else:
                pcl_fail += 1
    py, cpp = np.median(py_ms), np.median(cpp_ms)
    print(f"{n} clouds of 1800 points (radius 0.02-0.2 m, noise 2% of r, random axis), "
          f"median of {REPEATS} calls each")
    print(f"fit_cylinders from Python: median {py:.3f} ms; the same work inside C++: "
          f"{cpp:.3f} ms; overhead {100 * (py - cpp) / cpp:+.1f}%")
    o, q = np.array(ours), np.array(pcl) if pcl else np.zeros((0, 2))
    print("| method | found | radius error median (p90) | axis error median (p90) | time median |")
    print("|---|---|---|---|---|")
    print(f"| facyl.fit_cylinders | {len(o)}/{n} | {np.median(o[:, 0]):.2f}% "
          f"({np.percentile(o[:, 0], 90):.2f}%) | {np.median(o[:, 1]):.2f} deg "
          f"({np.percentile(o[:, 1], 90):.2f}) | {py:.2f} ms |")
    if len(q):
        print(f"| facyl_fit --method pcl-ransac | {len(q)}/{n} | {np.median(q[:, 0]):.2f}% "
              f"({np.percentile(q[:, 0], 90):.2f}%) | {np.median(q[:, 1]):.2f} deg "
              f"({np.percentile(q[:, 1], 90):.2f}) | {np.median(pcl_ms):.2f} ms |")
    print("| Open3D | - | no cylinder model | | |")


if __name__ == "__main__":
    main()

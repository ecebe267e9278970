#!/usr/bin/python3
"""Median and p90 of facyl_detect's timing_ms.total per source, for one or more builds, run in
alternated rounds (on a shared machine the second of two back-to-back runs can be faster).

usage: scripts/frame_times.py [--real DIR] [--sim720 DIR] [--rounds N] BUILD [BUILD...]
  BUILD: a build folder with apps/facyl_detect (e.g. build, /tmp/before/build)
  --real DIR    the shared real data (default ../shared/data/real): mOSD learn frames and the
                rgbd frames of other sensors, one source per folder
  --sim720 DIR  also a folder of simulated 1280 x 720 frames, e.g. made with
                build/apps/facyl_synth --layout realistic --sensor stereo --resolution 1280x720
                --count 10 --seed 700 DIR/real720
  --rounds N    rounds (default 3); each frame runs with --repeat 3 (its median is the figure)
"""
import argparse
import glob
import json
import os
import statistics
import subprocess


def p90(values):
    values = sorted(values)
    return values[min(len(values) - 1, int(round(0.9 * (len(values) - 1))))]


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--real", default="../shared/data/real")
    ap.add_argument("--sim720")
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("builds", nargs="+")
    args = ap.parse_args()
    sources = {
        "mosd (Kinect VGA)": sorted(glob.glob(args.real + "/mosd/learn*.pcd")),
        "graspnet6dof (RealSense-class VGA)": sorted(glob.glob(args.real + "/rgbd/graspnet6dof/*.pcd")),
        "posecnn (RealSense-class VGA)": sorted(glob.glob(args.real + "/rgbd/posecnn/*.pcd")),
        "sevenscenes (Kinect v1 kitchen)": sorted(glob.glob(args.real + "/rgbd/sevenscenes/*.pcd")),
    }
    if args.sim720:
        sources["simulated 1280x720"] = sorted(glob.glob(args.sim720 + "/*.pcd"))
    sources = {s: f for s, f in sources.items() if f}
    times = {b: {s: [] for s in sources} for b in args.builds}
    for k in range(args.rounds):
        for b in args.builds if k % 2 == 0 else args.builds[::-1]:
            for s, files in sources.items():
                out = subprocess.run([os.path.join(b, "apps", "facyl_detect"), "--repeat", "3"] + files,
                                     capture_output=True, text=True).stdout
                for line in out.splitlines():
                    if line.startswith("{"):
                        t = json.loads(line).get("timing_ms")
                        if t:
                            times[b][s].append(t["total"])
    for s in sources:
        print(s + ": " + " | ".join(
            "%s median %.1f p90 %.1f ms (n %d)" % (b, statistics.median(times[b][s]), p90(times[b][s]),
                                                   len(times[b][s])) for b in args.builds if times[b][s]))


if __name__ == "__main__":
    main()

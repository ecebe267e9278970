#!/usr/bin/env python3
"""How steady facyl_detect --track is over a stream: switches of the table plane, tracks carried.

usage: stream_steadiness.py [--json] [--max-offset M] TRACK.jsonl
  e.g. build/apps/facyl_detect --track ../shared/data/real/rgbd/sevenscenes_stream/*.pcd > s.jsonl
       scripts/stream_steadiness.py s.jsonl
Reads the JSON lines of one stream (in order) and prints, for the steps from one frame to the next:
- table switches: steps whose table plane ("table" "coefficients", in each frame's camera frame) is
  another plane than the frame before's, or where one frame has a table and the other none. Two
  planes are one when their normals are within 0.1 rad (the tolerance of a family of parallel
  supports) and their distances from the camera within 0.1 m: a hand-held camera moves by a few
  centimetres and degrees between frames at 15 Hz, while the planes of one family that a room
  holds (a counter, a table, the floor) lie 0.2 m and more apart;
- tracks carried: for each step, the share of the track ids that a frame's objects carry that the
  next frame's objects carry too, and its mean over the steps (steps from a frame without objects
  are left out);
- found flips: steps where "table" "found" (an object stands on a support) changes;
- objects per frame (min, median, max), frames with an error and new scenes.
--json prints the same as one JSON object. --max-offset M: planes whose distances from the camera
differ by more than M metres are two (default 0.1; 0.03 counts a jitter of a few centimetres,
a counter against slabs lying on it, as a switch).
"""
import json
import math
import os
import statistics
import sys

MAX_ANGLE = 0.1  # rad
MAX_OFFSET = 0.1  # m


def load(path):
    return [json.loads(line) for line in open(path) if line.startswith("{")]


def table_plane(frame):
    table = frame.get("table") or {}
    c = table.get("coefficients")
    return c if c and len(c) == 4 else None


def same_plane(a, b, max_offset=MAX_OFFSET):
    if a is None or b is None:
        return a is None and b is None
    dot = sum(x * y for x, y in zip(a[:3], b[:3]))
    return math.acos(max(-1.0, min(1.0, dot))) <= MAX_ANGLE and abs(a[3] - b[3]) <= max_offset


def track_ids(frame):
    return {o["track_id"] for o in frame.get("objects") or [] if o.get("track_id", -1) >= 0}


def steadiness(frames, max_offset=MAX_OFFSET):
    switches = [
        k for k in range(1, len(frames))
        if not same_plane(table_plane(frames[k - 1]), table_plane(frames[k]), max_offset)
    ]
    found = [bool((f.get("table") or {}).get("found")) for f in frames]
    flips = [k for k in range(1, len(frames)) if found[k] != found[k - 1]]
    carried = []
    for a, b in zip(frames, frames[1:]):
        ids = track_ids(a)
        if ids:
            carried.append(len(ids & track_ids(b)) / len(ids))
    counts = [len(f.get("objects") or []) for f in frames]
    return {
        "frames": len(frames),
        "steps": max(0, len(frames) - 1),
        "table_switches": len(switches),
        "switch_frames": [os.path.basename(frames[k].get("file", str(k))) for k in switches],
        "found_flips": len(flips),
        "found_flip_frames": [os.path.basename(frames[k].get("file", str(k))) for k in flips],
        "tracks_carried": statistics.mean(carried) if carried else float("nan"),
        "tracks_carried_min": min(carried) if carried else float("nan"),
        "objects_min": min(counts) if counts else 0,
        "objects_median": statistics.median(counts) if counts else 0,
        "objects_max": max(counts) if counts else 0,
        "errors": sum("error" in f for f in frames),
        "new_scenes": sum(bool((f.get("stream") or {}).get("new_scene")) for f in frames),
    }


def main(argv):
    as_json = "--json" in argv
    argv = [a for a in argv if a != "--json"]
    max_offset = MAX_OFFSET
    if "--max-offset" in argv:
        k = argv.index("--max-offset")
        if k + 1 >= len(argv):
            sys.exit(__doc__)
        max_offset = float(argv[k + 1])
        del argv[k:k + 2]
    paths = argv
    if len(paths) != 1:
        sys.exit(__doc__)
    s = steadiness(load(paths[0]), max_offset)
    if as_json:
        print(json.dumps(s))
        return
    print(f"table switches: {s['table_switches']} in {s['steps']} steps"
          + (f" (at {', '.join(s['switch_frames'])})" if s["switch_frames"] else ""))
    print(f"table found flips: {s['found_flips']}"
          + (f" (at {', '.join(s['found_flip_frames'])})" if s["found_flip_frames"] else ""))
    print(f"tracks carried into the next frame: mean {s['tracks_carried']:.3f}, "
          f"lowest {s['tracks_carried_min']:.3f}")
    print(f"objects per frame: min {s['objects_min']}, median {s['objects_median']}, "
          f"max {s['objects_max']}; frames with an error {s['errors']}, new scenes {s['new_scenes']}")


if __name__ == "__main__":
    main(sys.argv[1:])

#!/usr/bin/python3
"""Writes the seed corpus of the fuzz targets (fuzz/corpus/pcd, fuzz/corpus/estimator)."""
import math
import os
import random
import struct

here = os.path.dirname(os.path.abspath(__file__))
random.seed(3)


def pcd(fields, size, type_, w, h, data, body, viewpoint="0 0 0 1 0 0 0"):
    n = len(fields.split())
    return (f"# .PCD v0.7\nVERSION 0.7\nFIELDS {fields}\nSIZE {size}\nTYPE {type_}\n"
            f"COUNT {' '.join(['1'] * n)}\nWIDTH {w}\nHEIGHT {h}\nVIEWPOINT {viewpoint}\n"
            f"POINTS {w * h}\nDATA {data}\n").encode() + body


def write(name, data):
    with open(os.path.join(here, "corpus", name), "wb") as f:
        f.write(data)


# An organized 24 x 16 view of a table 0.6 m below the sensor with a can on it.
W, H = 24, 16
pts = []
for v in range(H):
    for u in range(W):
        dx, dy = (u - W / 2) / W * 0.8, (v - H / 2) / H * 0.5 + 0.3
        t = 0.6 / dy
        p = [dx * t, dy * t, t]
        if abs(dx) < 0.035 and t > 1.1:
            x = dx * 1.1
            p = [x, dy * 1.1, 1.1 - math.sqrt(max(0.0, 0.04 ** 2 - x * x))]
        pts.append(p)
colours = [0xff000000 | random.randrange(1 << 24) for _ in pts]
text = b"".join(f"{x:.4f} {y:.4f} {z:.4f} {c}\n".encode() for (x, y, z), c in zip(pts, colours))
write("pcd/organized_ascii.pcd", pcd("x y z rgba", "4 4 4 4", "F F F U", W, H, "ascii", text))
body = b"".join(struct.pack("<fffI", *p, c) for p, c in zip(pts, colours))
write("pcd/organized_binary.pcd", pcd("x y z rgba", "4 4 4 4", "F F F U", W, H, "binary", body))
nan3 = [float("nan")] * 3
body = b"".join(struct.pack("<fff", *(p if i % 7 else nan3)) for i, p in enumerate(pts))
write("pcd/unorganized_pose.pcd", pcd("x y z", "4 4 4", "F F F", W * H, 1, "binary", body,
                                       "0.1 0.2 0.3 0.7071 0.7071 0 0"))
# binary_compressed: fields one after another, as an LZF stream of literal runs (<= 32 bytes).
raw = b"".join(struct.pack("<f", p[c]) for c in range(3) for p in pts)
lzf = bytearray()
for i in range(0, len(raw), 32):
    chunk = raw[i:i + 32]
    lzf.append(len(chunk) - 1)
    lzf += chunk
write("pcd/compressed.pcd", pcd("x y z", "4 4 4", "F F F", W, H, "binary_compressed",
                                struct.pack("<II", len(lzf), len(raw)) + bytes(lzf)))


# The estimator: a parameter block, then points on a cylinder with their cues.
def estimator(flags, rmin, rmax, dist, angle, kexp, maxc, cand, grid, prior, orient, seed, k, n):
    b = struct.pack("<BffffBBBHBHQB", flags, rmin, rmax, dist, angle, kexp, maxc, cand, grid,
                    prior, orient, seed, k)
    for i in range(n):
        a = 2 * math.pi * i / n * 0.7
        z = (i % 17) / 17 * 0.2
        b += struct.pack("<fff", 0.05 * math.cos(a), 0.05 * math.sin(a), z)
        b += struct.pack("<fff", math.cos(a), math.sin(a), 0)
        b += struct.pack("<fff", -math.sin(a), math.cos(a), 0)
        b += struct.pack("<fff", 20, 0, 0.01)
    return b


write("estimator/cylinder_soft.bin", estimator(2, 0.0, 1.0, 0.0, 0.5, 1, 1, 4, 64, 0, 300, 1, 16, 300))
write("estimator/cylinder_estimate.bin",
      estimator(0x12, 0.01, 0.5, 0.005, 0.3, 2, 2, 8, 128, 1, 450, 7, 12, 400))
write("estimator/cylinder_rabbani.bin",
      estimator(0, 0.0, float("inf"), 0.0, 0.5, 1, 1, 1, 64, 3, 100, 0, 8, 100))

#!/usr/bin/python3
"""Reads a point cloud with Open3D, fits cylinders with facyl and draws them.

    PYTHONPATH=build/python /usr/bin/python3 examples/python/fit_open3d.py data/default_cylinder.pcd
        [--max-cylinders N] [--radius-limits A,B] [--units auto|m|mm]
        [--screenshot OUT.png [--size W,H] | --no-window]

Open3D reads the file (PCD, PLY, ...); facyl fits (Open3D's points go to facyl as they are,
NaN rows of organized frames included: inliers index the file's points); each cylinder is
drawn as a green wireframe from its base to its top (no surface that would hide the red
inliers on it or the points inside) over the finite points (grey; inliers red). The
screenshot is framed on the fitted cylinders: each whole, with as much again around it, in
the middle, seen from the sensor (the origin, image y down, as RGB-D frames and PCL's tools
have it; from in front along +z when the cloud is not in a sensor's frame); without a
cylinder, on the points. The window starts looking at the same place. Open3D has no cylinder
detection of its own.
--screenshot renders off-screen (under xvfb-run without a screen); its path must end in
.png and must not be the input (exit 2, nothing written).
"""
import argparse
import os
import sys

import numpy as np
import open3d as o3d

import facyl

GREEN = (0.1, 0.8, 0.2)
RED = (0.9, 0.1, 0.1)
GREY = (0.6, 0.6, 0.6)


def cylinder_lines(c, segments=36, generators=24, rings=6):
    """An Open3D wireframe of facyl Cylinder c from its base to its top: rings and generators
    (lines hide no point: the red inliers on the surface and the lid points stay visible)."""
    a = np.asarray(c.axis, float)
    a /= np.linalg.norm(a)
    u = np.cross(a, [1.0, 0.0, 0.0] if abs(a[0]) < 0.9 else [0.0, 1.0, 0.0])
    u /= np.linalg.norm(u)
    v = np.cross(a, u)
    base, top = np.asarray(c.base, float), np.asarray(c.top, float)
    if np.linalg.norm(top - base) < 1e-9:
        top = base + a * max(float(c.height), 1e-3)
    t = np.linspace(0, 2 * np.pi, segments, endpoint=False)
    circle = float(c.radius) * (np.cos(t)[:, None] * u + np.sin(t)[:, None] * v)
    vertices, lines = [], []
    for k in range(rings + 1):
        centre = base + (top - base) * k / rings
        first = len(vertices)
        vertices.extend(centre + circle)
        lines += [[first + i, first + (i + 1) % segments] for i in range(segments)]
    step = segments // generators
    last = rings * segments
    lines += [[i * step, last + i * step] for i in range(generators)]
    wire = o3d.geometry.LineSet(o3d.utility.Vector3dVector(np.array(vertices)),
                                o3d.utility.Vector2iVector(np.array(lines)))
    wire.paint_uniform_color(GREEN)
    return wire


def framed(points, cylinders, context=2.0):
    """What the picture must hold: each fitted cylinder whole (the corners of its wireframe) and
    as much again around it (its extent scaled by `context` about its centre: the points around
    it); without a cylinder, the finite points between the 2nd and 98th percentile of each
    coordinate (a sample of at most about 20000)."""
    if not cylinders:
        lo, hi = np.percentile(points, 2, axis=0), np.percentile(points, 98, axis=0)
        inside = points[((points >= lo) & (points <= hi)).all(axis=1)]
        return inside[::max(1, len(inside) // 20000)]
    corners = []
    for c in cylinders:
        wire = np.asarray(cylinder_lines(c).points)
        centre = wire.mean(axis=0)
        corners.append(centre + context * (wire - centre))
    return np.concatenate(corners)


def camera_axes(look):
    """The camera's axes (rows x, y, z) in the cloud's frame for a camera looking along `look`,
    image y down (towards +y, as RGB-D frames have it)."""
    z = look / np.linalg.norm(look)
    x = np.cross([0.0, 1.0, 0.0], z)
    if np.linalg.norm(x) < 1e-6:  # looking along y
        x = np.cross(z, np.cross([1.0, 0.0, 0.0], z))
    x /= np.linalg.norm(x)
    return np.stack([x, np.cross(z, x), z])


def frame_camera(vis, points, targets, width, height, margin=0.05):
    """Puts Open3D's camera where it sees all of `targets` (N x 3) in the middle of the picture,
    image y down: at the sensor (the origin) when the cloud is in a sensor's frame (most points
    in front of the origin, along +z), else in front of them along +z. The field of view holds
    every target with `margin` (a share of the picture) to spare. False when Open3D refuses
    the camera (the caller then sets a plain view)."""
    centre = 0.5 * (targets.min(axis=0) + targets.max(axis=0))
    if (points[:, 2] > 1e-6).mean() >= 0.5:
        eye = np.zeros(3)
    else:
        eye = centre - np.array([0.0, 0.0, 3.0 * np.linalg.norm(targets - centre, axis=1).max()])
    look = centre - eye
    for turn in range(4):  # aim at the middle of what the camera sees of the targets
        axes = camera_axes(look)
        q = (targets - eye) @ axes.T
        q = q[q[:, 2] > 1e-6]
        if len(q) == 0:
            return False
        u, v = q[:, 0] / q[:, 2], q[:, 1] / q[:, 2]
        if turn < 3:
            look = axes.T @ np.array([0.5 * (u.min() + u.max()), 0.5 * (v.min() + v.max()), 1.0])
    tx, ty = np.abs(u).max(), np.abs(v).max()
    f = (1.0 - 2.0 * margin) * 0.5 * min(width / max(tx, 1e-6), height / max(ty, 1e-6))
    # Open3D takes fields of view from 5 to 90 degrees.
    f = min(max(f, 0.5 * height / np.tan(np.radians(44))), 0.5 * height / np.tan(np.radians(3)))
    param = vis.get_view_control().convert_to_pinhole_camera_parameters()
    param.intrinsic = o3d.camera.PinholeCameraIntrinsic(width, height, f, f, width / 2 - 0.5,
                                                        height / 2 - 0.5)
    extrinsic = np.eye(4)
    extrinsic[:3, :3] = axes
    extrinsic[:3, 3] = -axes @ eye
    param.extrinsic = extrinsic
    return vis.get_view_control().convert_from_pinhole_camera_parameters(param)


def same_file(a, b):
    try:
        return os.path.samefile(a, b)
    except OSError:
        return os.path.realpath(a) == os.path.realpath(b)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("file")
    ap.add_argument("--max-cylinders", type=int, default=1)
    ap.add_argument("--radius-limits", help="A,B (default: facyl's, 0 to twice the extent)")
    ap.add_argument("--units", default="auto", choices=["auto", "m", "mm"])
    ap.add_argument("--screenshot", help="render off-screen to this PNG instead of a window")
    ap.add_argument("--size", default="800,600", help="screenshot size W,H (default 800,600)")
    ap.add_argument("--no-window", action="store_true", help="print the fit only")
    ap.add_argument("--version", action="version", version=f"fit_open3d (facyl) {facyl.__version__}")
    args = ap.parse_args()
    if args.screenshot is not None:
        if not args.screenshot.lower().endswith(".png"):
            ap.exit(2, f"fit_open3d: --screenshot {args.screenshot}: a screenshot is a PNG image; "
                       "give a path ending in .png. Nothing was written.\n")
        if same_file(args.screenshot, args.file):
            ap.exit(2, f"fit_open3d: --screenshot {args.screenshot}: is also the input; facyl "
                       "never writes over its inputs. Nothing was written.\n")
    radius_limits = None
    if args.radius_limits:
        try:
            radius_limits = tuple(float(x) for x in args.radius_limits.split(","))
        except ValueError:
            ap.exit(2, f"fit_open3d: --radius-limits: expected A,B, got {args.radius_limits!r}\n")
    try:
        width, height = (int(x) for x in args.size.split(","))
    except ValueError:
        ap.exit(2, f"fit_open3d: --size: expected W,H, got {args.size!r}\n")

    pcd = o3d.io.read_point_cloud(args.file)
    points = np.asarray(pcd.points)
    if len(points) == 0:
        sys.exit(f"fit_open3d: {args.file}: no points (not a point cloud Open3D can read?)")
    try:
        cylinders = facyl.fit_cylinders(pcd.points, pcd.normals if pcd.has_normals() else None,
                                        max_cylinders=args.max_cylinders,
                                        radius_limits=radius_limits, units=args.units)
    except ValueError as e:
        sys.exit(f"fit_open3d: {args.file}: {e}")
    for c in cylinders:
        print(c)
    if not cylinders:
        print("fit_open3d: no cylinder found")
    if args.no_window:
        return

    # What is drawn: the finite points only (NaN rows would make Open3D's view box NaN and the
    # picture empty), grey, the inliers red.
    colors = np.tile(GREY, (len(points), 1))
    for c in cylinders:
        colors[c.inliers] = RED
    finite = np.isfinite(points).all(axis=1)
    shown = o3d.geometry.PointCloud(o3d.utility.Vector3dVector(points[finite]))
    shown.colors = o3d.utility.Vector3dVector(colors[finite])
    geometries = [shown] + [cylinder_lines(c) for c in cylinders]
    targets = framed(points[finite], cylinders)
    if args.screenshot:
        vis = o3d.visualization.Visualizer()
        if not vis.create_window(visible=False, width=width, height=height):
            sys.exit("fit_open3d: cannot open an off-screen window (no display? run under "
                     "xvfb-run -a)")
        for g in geometries:
            vis.add_geometry(g)
        if not frame_camera(vis, points[finite], targets, width, height):
            view = vis.get_view_control()
            view.set_lookat(targets.mean(axis=0))
            view.set_front([0.0, 0.0, -1.0])
            view.set_up([0.0, -1.0, 0.0])
        vis.get_render_option().point_size = 2.0
        vis.get_render_option().line_width = 2.0
        vis.poll_events()
        vis.update_renderer()
        vis.capture_screen_image(args.screenshot, do_render=True)
        vis.destroy_window()
        print(f"fit_open3d: wrote {args.screenshot}")
    else:
        o3d.visualization.draw_geometries(geometries, lookat=targets.mean(axis=0),
                                          front=[0.0, 0.0, -1.0], up=[0.0, -1.0, 0.0], zoom=0.6)


if __name__ == "__main__":
    main()

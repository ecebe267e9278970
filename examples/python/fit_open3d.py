#!/usr/bin/python3
"""Reads a point cloud with Open3D, fits cylinders with facyl and draws them.

    PYTHONPATH=build/python /usr/bin/python3 examples/python/fit_open3d.py data/default_cylinder.pcd
        [--max-cylinders N] [--screenshot out.png | --no-window]

Open3D reads the file (PCD, PLY, ...); facyl fits; each finite cylinder is drawn as an Open3D
mesh (green) over the points (inliers red). Open3D has no cylinder detection of its own.
"""
import argparse
import sys

import numpy as np
import open3d as o3d

import facyl


def cylinder_mesh(c, resolution=40):
    """An Open3D mesh of facyl Cylinder c (from its base to its top)."""
    mesh = o3d.geometry.TriangleMesh.create_cylinder(radius=float(c.radius),
                                                     height=float(max(c.height, 1e-3)),
                                                     resolution=resolution)
    # Open3D's cylinder is centred at the origin along z: rotate z onto the axis, move to the
    # middle of base and top.
    z = np.array([0.0, 0.0, 1.0])
    a = np.asarray(c.axis, float)
    v = np.cross(z, a)
    s, cos = np.linalg.norm(v), float(np.dot(z, a))
    if s < 1e-9:
        rot = np.eye(3) if cos > 0 else np.diag([1.0, -1.0, -1.0])
    else:
        vx = np.array([[0, -v[2], v[1]], [v[2], 0, -v[0]], [-v[1], v[0], 0]])
        rot = np.eye(3) + vx + vx @ vx * ((1 - cos) / s ** 2)
    mesh.rotate(rot, center=(0, 0, 0))
    mesh.translate((np.asarray(c.base, float) + np.asarray(c.top, float)) / 2)
    mesh.compute_vertex_normals()
    mesh.paint_uniform_color([0.1, 0.8, 0.2])
    return mesh


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("file")
    ap.add_argument("--max-cylinders", type=int, default=1)
    ap.add_argument("--screenshot", help="render off-screen to this PNG instead of a window")
    ap.add_argument("--no-window", action="store_true", help="print the fit only")
    args = ap.parse_args()
    pcd = o3d.io.read_point_cloud(args.file)
    points = np.asarray(pcd.points)
    if len(points) == 0:
        sys.exit(f"fit_open3d: {args.file}: no points (not a point cloud Open3D can read?)")
    normals = np.asarray(pcd.normals) if pcd.has_normals() else None
    cylinders = facyl.fit_cylinders(points, normals, max_cylinders=args.max_cylinders)
    for c in cylinders:
        print(c)
    if not cylinders:
        print("fit_open3d: no cylinder found")
    if args.no_window:
        return
    colors = np.full((len(points), 3), 0.6)
    for c in cylinders:
        colors[c.inliers] = [0.9, 0.1, 0.1]
    pcd.colors = o3d.utility.Vector3dVector(colors)
    geometries = [pcd] + [cylinder_mesh(c) for c in cylinders]
    if args.screenshot:
        vis = o3d.visualization.Visualizer()
        vis.create_window(visible=False, width=800, height=600)
        for g in geometries:
            vis.add_geometry(g)
        vis.poll_events()
        vis.update_renderer()
        vis.capture_screen_image(args.screenshot, do_render=True)
        vis.destroy_window()
        print(f"fit_open3d: wrote {args.screenshot}")
    else:
        o3d.visualization.draw_geometries(geometries)


if __name__ == "__main__":
    main()

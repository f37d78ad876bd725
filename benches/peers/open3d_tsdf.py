"""Open3D's TSDF fusion (tensor VoxelBlockGrid) beside `nbv fuse` on the same exported views,
both meshes scored against the same true mesh by the same code (`nbv fuse --score`).

Input: episode directories written by `nbv explore` (or a sweep's episodes): each
objects/<name>/rgbd/ (16-bit depth PNGs in mm, camera_intrinsic.json, trajectory.log with
camera-to-world poses) and objects/<name>/truth.stl (the true object, world frame).

Open3D: `o3d.t.geometry.VoxelBlockGrid` (tsdf, weight), the same voxel size and truncation
(trunc_voxel_multiplier = truncation / voxel), depth_scale 1000, depth_max 1 m (the Dinast
sees to 0.8 m), `compute_unique_block_coordinates` then `integrate` per frame, and
`extract_triangle_mesh` at weight thresholds 0.5, 1 and Open3D's default 3: it keeps a voxel whose
weight (1 per view) is above the threshold, so these keep the voxels seen by at least 1, 2
and 4 views. (ScalableTSDFVolume is
not used: in Open3D 0.20.0 it integrates nothing from float depth.) nbv: `nbv fuse` on the same
directory at the same voxel and truncation; its printed time is the fusion in memory (file
reading excluded), as Open3D's here.

Prints one row per object and method: F-score at 2, 5, 10 mm, Chamfer (mm), triangles,
integration + extraction time (ms) and per view.
"""

import argparse
import glob
import json
import os
import re
import subprocess
import sys
import tempfile
import time

import numpy as np
import open3d as o3d


def open3d_mesh(rgbd, voxel, truncation, threshold, threads):
    intrinsic = o3d.io.read_pinhole_camera_intrinsic(os.path.join(rgbd, "camera_intrinsic.json"))
    trajectory = o3d.io.read_pinhole_camera_trajectory(os.path.join(rgbd, "trajectory.log"))
    depth_files = sorted(glob.glob(os.path.join(rgbd, "depth", "*.png")))
    assert len(depth_files) == len(trajectory.parameters), rgbd
    K = o3d.core.Tensor(intrinsic.intrinsic_matrix, o3d.core.Dtype.Float64)
    depths = [o3d.t.io.read_image(f) for f in depth_files]
    extrinsics = [o3d.core.Tensor(p.extrinsic, o3d.core.Dtype.Float64) for p in trajectory.parameters]
    start = time.perf_counter()
    vbg = o3d.t.geometry.VoxelBlockGrid(
        attr_names=("tsdf", "weight"),
        attr_dtypes=(o3d.core.float32, o3d.core.float32),
        attr_channels=((1), (1)),
        voxel_size=voxel,
        block_resolution=8,
        block_count=20000,
        device=o3d.core.Device("CPU:0"),
    )
    mult = truncation / voxel
    for depth, extrinsic in zip(depths, extrinsics):
        coords = vbg.compute_unique_block_coordinates(depth, K, extrinsic, 1000.0, 1.0, mult)
        vbg.integrate(coords, depth, K, extrinsic, 1000.0, 1.0, mult)
    try:
        mesh = vbg.extract_triangle_mesh(weight_threshold=threshold).to_legacy()
    except RuntimeError:  # nothing above the threshold: Open3D cannot colour an empty mesh
        mesh = o3d.geometry.TriangleMesh()
    seconds = time.perf_counter() - start
    return mesh, seconds, len(depths)


def score(nbv, mesh_path, truth):
    out = subprocess.run([nbv, "fuse", "--score", mesh_path, "--truth", truth],
                         check=True, capture_output=True, text=True).stdout
    return json.loads(out.strip().splitlines()[-1])


def row(episode, name, method, q, ms, views):
    f = q["f_score"]
    print(f"| {episode} | {name} | {method} | {100*f[0]:.1f} | {100*f[1]:.1f} | {100*f[2]:.1f} | "
          f"{1e3*q['chamfer']:.2f} | {q['triangles']} | {ms:.1f} ({ms/views:.2f}/view) |")
    sys.stdout.flush()


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("episodes", nargs="+")
    ap.add_argument("--nbv", required=True)
    ap.add_argument("--voxel", type=float, default=0.002)
    ap.add_argument("--truncation", type=float, default=0.016)
    ap.add_argument("--threads", type=int, default=0)
    args = ap.parse_args()
    if args.threads:
        o3d.utility.set_max_threads(args.threads)
    print("| episode | object | method | F@2mm | F@5mm | F@10mm | Chamfer mm | triangles | fusion ms |")
    print("|---|---|---|---|---|---|---|---|---|")
    found = [rgbd for episode in args.episodes
             for rgbd in sorted(glob.glob(os.path.join(episode, "objects", "*", "rgbd")))
             if os.path.exists(os.path.join(os.path.dirname(rgbd), "truth.stl"))]
    if not found:
        sys.exit(f"error: no objects/<name>/rgbd/ with a truth.stl beside it under {' '.join(args.episodes)}")
    with tempfile.TemporaryDirectory() as tmp:
        for rgbd in found:
            obj = os.path.dirname(rgbd)
            episode = os.path.basename(os.path.dirname(os.path.dirname(obj)).rstrip("/"))
            name = os.path.basename(obj)
            truth = os.path.join(obj, "truth.stl")
            ours = os.path.join(tmp, "nbv.ply")
            out = subprocess.run([args.nbv, "fuse", rgbd, "-o", ours, "--voxel", str(args.voxel),
                                  "--truncation", str(args.truncation), "--truth", truth],
                                 check=True, capture_output=True, text=True).stdout.splitlines()
            ms = float(re.search(r"fused in ([0-9.]+) ms", out[0]).group(1))
            views = int(re.search(r"(\d+) view", out[0]).group(1))
            row(episode, name, "nbv fuse", json.loads(out[-1]), ms, views)
            # Open3D keeps a voxel whose weight (1 per view) is above the threshold:
            # 0.5 keeps every observed voxel (as nbv's default), 1 those seen by two views
            # or more, 3 (its default) by four or more.
            for threshold, label in ((0.5, "≥ 1 view"), (1.0, "≥ 2 views"), (3.0, "≥ 4 views, its default")):
                mesh, seconds, views = open3d_mesh(rgbd, args.voxel, args.truncation, threshold, args.threads)
                method = f"Open3D VBG {label}"
                if len(mesh.triangles) == 0:
                    print(f"| {episode} | {name} | {method} | empty | | | | 0 | |")
                    continue
                path = os.path.join(tmp, "open3d.obj")
                o3d.io.write_triangle_mesh(path, mesh)
                row(episode, name, method, score(args.nbv, path, truth), 1e3 * seconds, views)

if __name__ == "__main__":
    main()

"""Open3D's multiway registration and sequential ICP beside `nbv register` (p-ICP-GPA and
sequential ICP) on the same views, scored against the same ground truth.

Input: a directory written by `cargo run --release -p nbv-core --example registration_views
-- DIR` (the paper's Table II case) or `--example user_scans -- DIR --mesh M` (a user's ring
or hand-held path of a mesh): view_<k>.ply (each view in its own sensor frame), initial.json (initial poses,
view 0 exact: the reference), truth.json (true poses) and spec.json. Pose files map file
names to 4x4 row-major view-to-world matrices, the format `nbv register` reads and writes.

Open3D multiway registration follows its documented recipe (tutorial "Multiway
registration"): views moved into the world frame by their initial poses, normals by a hybrid
radius search, for every pair a coarse then a fine point-to-plane ICP and the information
matrix, odometry edges between consecutive views and loop-closure edges (uncertain) for
the others, then Levenberg-Marquardt pose-graph optimisation with reference node 0.
Open3D sequential ICP registers view h onto view h-1 (point-to-point and point-to-plane),
chained, like nbv's baseline. nbv runs through its CLI; the registration time it prints
(without file I/O) is compared with Open3D's in-memory time.

Errors: for every view, the RMS distance between its points placed by the estimated pose
and by the true pose (mm); the table gives the mean and the worst view, and the worst
rotation error (degrees).
"""

import argparse
import json
import os
import re
import subprocess
import sys
import tempfile
import time

import numpy as np
import open3d as o3d

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from view_errors import point_errors  # noqa: E402

REG = o3d.pipelines.registration


def load_poses(path, names):
    with open(path) as f:
        data = json.load(f)
    return [np.array(data[n], dtype=float) for n in names]


def cloud(points, pose):
    c = o3d.geometry.PointCloud(o3d.utility.Vector3dVector(points))
    c.transform(pose)
    return c


def open3d_multiway(points, initial, d_fine, d_coarse, normal_radius):
    """The tutorial's recipe; returns view-to-world poses and the time (s)."""
    start = time.perf_counter()
    pcds = [cloud(p, pose) for p, pose in zip(points, initial)]
    for c in pcds:
        c.estimate_normals(o3d.geometry.KDTreeSearchParamHybrid(radius=normal_radius, max_nn=30))
    graph = REG.PoseGraph()
    odometry = np.identity(4)
    graph.nodes.append(REG.PoseGraphNode(odometry))
    n = len(pcds)
    for s in range(n):
        for t in range(s + 1, n):
            coarse = REG.registration_icp(
                pcds[s], pcds[t], d_coarse, np.identity(4),
                REG.TransformationEstimationPointToPlane())
            fine = REG.registration_icp(
                pcds[s], pcds[t], d_fine, coarse.transformation,
                REG.TransformationEstimationPointToPlane())
            info = REG.get_information_matrix_from_point_clouds(
                pcds[s], pcds[t], d_fine, fine.transformation)
            if t == s + 1:
                odometry = fine.transformation @ odometry
                graph.nodes.append(REG.PoseGraphNode(np.linalg.inv(odometry)))
                graph.edges.append(REG.PoseGraphEdge(s, t, fine.transformation, info,
                                                     uncertain=False))
            else:
                graph.edges.append(REG.PoseGraphEdge(s, t, fine.transformation, info,
                                                     uncertain=True))
    option = REG.GlobalOptimizationOption(max_correspondence_distance=d_fine,
                                          edge_prune_threshold=0.25, reference_node=0)
    with o3d.utility.VerbosityContextManager(o3d.utility.VerbosityLevel.Error):
        REG.global_optimization(graph, REG.GlobalOptimizationLevenbergMarquardt(),
                                REG.GlobalOptimizationConvergenceCriteria(), option)
    elapsed = time.perf_counter() - start
    # Node poses correct the clouds placed by the initial poses; node 0 is the reference.
    poses = [graph.nodes[k].pose @ initial[k] for k in range(n)]
    fix = initial[0] @ np.linalg.inv(poses[0])
    return [fix @ p for p in poses], elapsed


def open3d_sequential(points, initial, d_max, max_iterations, point_to_plane, normal_radius):
    """View h onto view h-1, chained from the reference view 0; poses and time (s)."""
    start = time.perf_counter()
    pcds = [cloud(p, np.identity(4)) for p in points]
    estimation = (REG.TransformationEstimationPointToPlane() if point_to_plane
                  else REG.TransformationEstimationPointToPoint())
    if point_to_plane:
        for c in pcds:
            c.estimate_normals(o3d.geometry.KDTreeSearchParamHybrid(radius=normal_radius,
                                                                     max_nn=30))
            c.orient_normals_towards_camera_location(np.zeros(3))
    criteria = REG.ICPConvergenceCriteria(relative_fitness=1e-6, relative_rmse=1e-6,
                                          max_iteration=max_iterations)
    poses = [initial[0]]
    for h in range(1, len(pcds)):
        guess = np.linalg.inv(initial[h - 1]) @ initial[h]
        result = REG.registration_icp(pcds[h], pcds[h - 1], d_max, guess, estimation, criteria)
        poses.append(poses[h - 1] @ result.transformation)
    return poses, time.perf_counter() - start


def nbv_register(nbv, files, init, method, threads):
    """Runs `nbv register`; returns its poses and the registration time it reports (s)."""
    with tempfile.TemporaryDirectory() as tmp:
        out = os.path.join(tmp, "poses.json")
        run = subprocess.run(
            [nbv, "register", *files, "--init", init, "--method", method,
             "--threads", str(threads), "-o", os.path.join(tmp, "model.ply"),
             "--poses", out],
            capture_output=True, text=True)
        if run.returncode not in (0, 3):
            sys.exit(f"nbv register failed ({run.returncode}):\n{run.stderr}")
        m = re.search(r"in ([0-9.]+) ms", run.stdout + run.stderr)
        if not m:
            sys.exit(f"no timing in nbv's output:\n{run.stdout}{run.stderr}")
        with open(out) as f:
            data = json.load(f)
        poses = [np.array(data[os.path.basename(p)], dtype=float) for p in files]
        return poses, float(m.group(1)) / 1000.0


def best_of(runs, fn):
    """Minimum time over `runs` calls (results of the last)."""
    best, result = float("inf"), None
    for _ in range(runs):
        poses, t = fn()
        best, result = min(best, t), poses
    return result, best


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--views", required=True)
    ap.add_argument("--nbv", required=True, help="path of the nbv binary")
    ap.add_argument("--d-max", type=float, default=0.01)
    ap.add_argument("--runs", type=int, default=5, help="timed runs; the best is shown")
    ap.add_argument("--max-iterations", type=int, default=300,
                    help="iteration cap of the sequential ICPs (Open3D and nbv)")
    ap.add_argument("--only", default="",
                    help="comma-separated words; run only the methods whose label has one "
                         "(e.g. multiway,MAP)")
    args = ap.parse_args()

    with open(os.path.join(args.views, "spec.json")) as f:
        spec = json.load(f)
    names = spec["files"]
    files = [os.path.join(args.views, n) for n in names]
    points = [np.asarray(o3d.io.read_point_cloud(p).points) for p in files]
    initial = load_poses(os.path.join(args.views, "initial.json"), names)
    truth = load_poses(os.path.join(args.views, "truth.json"), names)
    init_path = os.path.join(args.views, "initial.json")
    d = args.d_max
    normal_radius = 2 * d
    threads = os.cpu_count() or 1

    rows = [("initial poses", initial, None)]
    for label, fn in [
        ("Open3D multiway (pairwise ICP + pose graph)",
         lambda: open3d_multiway(points, initial, d, 3 * d, normal_radius)),
        ("Open3D sequential ICP, point-to-point",
         lambda: open3d_sequential(points, initial, d, args.max_iterations, False,
                                   normal_radius)),
        ("Open3D sequential ICP, point-to-plane",
         lambda: open3d_sequential(points, initial, d, args.max_iterations, True,
                                   normal_radius)),
        ("nbv p-ICP-GPA, 1 thread", lambda: nbv_register(args.nbv, files, init_path, "gpa", 1)),
        (f"nbv p-ICP-GPA, {threads} threads",
         lambda: nbv_register(args.nbv, files, init_path, "gpa", threads)),
        ("nbv MAP, 1 thread", lambda: nbv_register(args.nbv, files, init_path, "map", 1)),
        (f"nbv MAP, {threads} threads",
         lambda: nbv_register(args.nbv, files, init_path, "map", threads)),
        ("nbv sequential ICP, point-to-point, 1 thread",
         lambda: nbv_register(args.nbv, files, init_path, "icp", 1)),
        ("nbv sequential ICP, point-to-plane, 1 thread",
         lambda: nbv_register(args.nbv, files, init_path, "icp-plane", 1)),
    ]:
        words = [w for w in args.only.split(",") if w]
        if words and not any(w in label for w in words):
            continue
        poses, t = best_of(args.runs, fn)
        rows.append((label, poses, t))

    total = sum(len(p) for p in points)
    print(f"{len(points)} views, {total} points, d_max {d} m, Open3D {o3d.__version__} "
          f"({threads} threads), best of {args.runs} runs")
    print(f"{'method':48} {'mean err mm':>11} {'worst mm':>9} {'worst deg':>9} {'time ms':>9}")
    for label, poses, t in rows:
        rms, rot = point_errors(points, poses, truth)
        ms = "-" if t is None else f"{t * 1000:.1f}"
        print(f"{label:48} {np.mean(rms) * 1000:11.3f} {max(rms) * 1000:9.3f} "
              f"{max(rot):9.3f} {ms:>9}")


if __name__ == "__main__":
    main()

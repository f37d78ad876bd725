#!/usr/bin/env python3
"""OctoMap's side of the occupancy comparison (run by octomap_insert.sh).

Reads what `cargo run --release -p nbv-core --example occupancy_peer -- DIR` wrote:
cloud.ply (returns with per-point sensor origins), grid_per_line.nbvgrid and
grid_one_scan.nbvgrid (nbv's grids) and nbv_timing.json. Inserts the same returns into an
OctoMap OcTree of the same resolution, one insertPointCloud call per scan line with that
line's origin, with the same sensor model (hit p = p_hit from the grid file, miss
p = 1 - p_hit: the paper's symmetric model), the same clamping and the same maximum range;
times it; then classifies every voxel of nbv's grid by the OctoMap node at its centre with
nbv's threshold eps_o (log-odds > eps occupied, < -eps empty, else or no node unknown) and
prints the agreement of the two classifications and the time ratio.
"""

import argparse
import json
import math
import os
import struct
import sys
import time

import numpy as np
import octomap

PLY_TYPES = {
    "char": "i1", "int8": "i1", "uchar": "u1", "uint8": "u1",
    "short": "<i2", "int16": "<i2", "ushort": "<u2", "uint16": "<u2",
    "int": "<i4", "int32": "<i4", "uint": "<u4", "uint32": "<u4",
    "float": "<f4", "float32": "<f4", "double": "<f8", "float64": "<f8",
}
STATE_NAMES = ("unknown", "empty", "occupied")


def read_ply(path):
    """A binary little-endian PLY with one vertex element (what nbv writes)."""
    with open(path, "rb") as f:
        if f.readline().strip() != b"ply":
            sys.exit(f"{path}: not a PLY file")
        props, count, fmt = [], 0, None
        while True:
            line = f.readline().decode("ascii").strip()
            if not line:
                sys.exit(f"{path}: truncated header")
            words = line.split()
            if words[0] == "format":
                fmt = words[1]
            elif words[0] == "element":
                if words[1] != "vertex":
                    sys.exit(f"{path}: unexpected element {words[1]}")
                count = int(words[2])
            elif words[0] == "property":
                props.append((words[2], PLY_TYPES[words[1]]))
            elif words[0] == "end_header":
                break
        if fmt != "binary_little_endian":
            sys.exit(f"{path}: expected binary_little_endian, got {fmt}")
        data = np.frombuffer(f.read(), dtype=np.dtype(props), count=count)
    pts = np.stack([data["x"], data["y"], data["z"]], axis=1).astype(np.float64)
    org = np.stack([data["ox"], data["oy"], data["oz"]], axis=1).astype(np.float64)
    return pts, org


def read_grid(path):
    """An NBVGRID version-1 file (layout in nbv_core::occupancy)."""
    with open(path, "rb") as f:
        head = f.read(80)
        if head[:8] != b"NBVGRID\0":
            sys.exit(f"{path}: not an NBVGRID file")
        version, nx, ny, nz = struct.unpack_from("<4I", head, 8)
        mn = struct.unpack_from("<3d", head, 24)
        res, p_hit = struct.unpack_from("<2d", head, 48)
        cmin, cmax, eps = struct.unpack_from("<3f", head, 64)
        values = np.frombuffer(f.read(), dtype="<f4")
    if version != 1 or values.size != nx * ny * nz:
        sys.exit(f"{path}: bad version or size")
    return {
        "dims": (nx, ny, nz), "min": np.array(mn), "res": res, "p_hit": p_hit,
        "clamp": (cmin, cmax), "eps": eps, "log_odds": values,
    }


def states(log_odds, eps):
    s = np.zeros(log_odds.shape, dtype=np.uint8)
    s[log_odds < -eps] = 1
    s[log_odds > eps] = 2
    return s


def scan_lines(origins):
    """(start, end) of every run of equal consecutive origins."""
    change = np.any(origins[1:] != origins[:-1], axis=1)
    starts = np.concatenate([[0], np.nonzero(change)[0] + 1])
    ends = np.concatenate([starts[1:], [len(origins)]])
    return list(zip(starts, ends))


def make_tree(g):
    tree = octomap.OcTree(g["res"])
    tree.setProbHit(g["p_hit"])
    tree.setProbMiss(1.0 - g["p_hit"])
    prob = lambda lo: 1.0 / (1.0 + math.exp(-lo))
    tree.setClampingThresMin(prob(g["clamp"][0]))
    tree.setClampingThresMax(prob(g["clamp"][1]))
    return tree


def insert(g, scans, max_range, lazy):
    tree = make_tree(g)
    t = time.perf_counter()
    for pts, origin in scans:
        tree.insertPointCloud(pointcloud=pts, origin=origin, maxrange=max_range, lazy_eval=lazy)
    if lazy:
        tree.updateInnerOccupancy()
    return time.perf_counter() - t, tree


def classify(tree, g):
    """OctoMap's log-odds at every nbv voxel centre (NaN where OctoMap has no node)."""
    nx, ny, nz = g["dims"]
    iz, iy, ix = np.meshgrid(np.arange(nz), np.arange(ny), np.arange(nx), indexing="ij")
    centres = g["min"] + (np.stack([ix, iy, iz], axis=-1).reshape(-1, 3) + 0.5) * g["res"]
    out = np.full(len(centres), np.nan)
    for i, c in enumerate(centres):
        node = tree.search(c)
        try:
            out[i] = node.getLogOdds()
        except octomap.NullPointerException:
            pass
    return out


def compare(nbv_states, octo_states):
    agree = nbv_states == octo_states
    seen = (nbv_states != 0) | (octo_states != 0)
    confusion = {
        f"nbv {STATE_NAMES[a]} / octomap {STATE_NAMES[b]}":
            int(np.sum((nbv_states == a) & (octo_states == b)))
        for a in range(3) for b in range(3)
    }
    return {
        "agreement_all": float(agree.mean()),
        "agreement_seen": float(agree[seen].mean()) if seen.any() else 1.0,
        "disagreeing_voxels": int((~agree).sum()),
        "confusion": confusion,
    }


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("dir")
    ap.add_argument("--runs", type=int, default=15)
    ap.add_argument("--max-range", type=float, default=3.0)
    a = ap.parse_args()
    pts, org = read_ply(os.path.join(a.dir, "cloud.ply"))
    g = read_grid(os.path.join(a.dir, "grid_per_line.nbvgrid"))
    g_one = read_grid(os.path.join(a.dir, "grid_one_scan.nbvgrid"))
    with open(os.path.join(a.dir, "nbv_timing.json")) as f:
        nbv = json.load(f)
    if np.any(np.abs(np.round(g["min"] / g["res"]) * g["res"] - g["min"]) > 1e-9):
        sys.exit("the grid's lower corner is not on OctoMap's lattice")
    scans = [(np.ascontiguousarray(pts[s:e]), org[s].copy()) for s, e in scan_lines(org)]

    runs = max(1, a.runs)
    lazy_times = [insert(g, scans, a.max_range, True)[0] for _ in range(runs)]
    eager_times = [insert(g, scans, a.max_range, False)[0] for _ in range(max(1, runs // 3))]
    t_lazy, t_eager = float(np.median(lazy_times)), float(np.median(eager_times))
    _, tree = insert(g, scans, a.max_range, True)
    octo_log_odds = classify(tree, g)
    octo_states = states(np.nan_to_num(octo_log_odds, nan=0.0), g["eps"])
    per_line = compare(states(g["log_odds"], g["eps"]), octo_states)
    one_scan = compare(states(g_one["log_odds"], g_one["eps"]), octo_states)
    known = ~np.isnan(octo_log_odds)
    max_diff = float(np.max(np.abs(octo_log_odds[known] - g["log_odds"][known])))

    omp = os.environ.get("OMP_NUM_THREADS", "unset")
    print(f"octomap-python {getattr(octomap, '__version__', '?')}, OMP_NUM_THREADS={omp}: "
          f"{len(pts)} rays in {len(scans)} insertPointCloud calls at {g['res']} m; "
          f"median of {runs} runs:")
    print(f"  lazy_eval + updateInnerOccupancy: {t_lazy * 1e3:.1f} ms")
    print(f"  default (eager inner nodes):      {t_eager * 1e3:.1f} ms")
    best_nbv = nbv["per_line_s"]
    print(f"nbv per scan line: {best_nbv * 1e3:.2f} ms ({nbv['threads']} threads), "
          f"{nbv['per_line_1_thread_s'] * 1e3:.2f} ms (1 thread); "
          f"one scan: {nbv['one_scan_s'] * 1e3:.2f} ms, "
          f"{nbv['one_scan_1_thread_s'] * 1e3:.2f} ms (1 thread)")
    print(f"ratio OctoMap (lazy) / nbv, same per-line insertion: "
          f"{t_lazy / best_nbv:.1f}x ({nbv['threads']} threads), "
          f"{t_lazy / nbv['per_line_1_thread_s']:.1f}x (nbv on 1 thread)")
    print(f"ratio OctoMap (lazy) / nbv one scan: {t_lazy / nbv['one_scan_s']:.1f}x, "
          f"{t_lazy / nbv['one_scan_1_thread_s']:.1f}x (nbv on 1 thread)")
    print(f"classification vs nbv per line (eps_o = {g['eps']:.2f}): "
          f"{per_line['agreement_all'] * 100:.3f}% of all voxels agree, "
          f"{per_line['agreement_seen'] * 100:.3f}% of those either one saw; "
          f"{per_line['disagreeing_voxels']} differ; max |log-odds difference| on OctoMap's "
          f"nodes {max_diff:.2e}")
    for k, v in per_line["confusion"].items():
        if v and k.split(" / ")[0][4:] != k.split(" / ")[1][8:]:
            print(f"    {k}: {v}")
    print(f"classification vs nbv one scan: {one_scan['agreement_all'] * 100:.3f}% agree, "
          f"{one_scan['disagreeing_voxels']} differ")
    result = {
        "octomap_lazy_s": t_lazy, "octomap_eager_s": t_eager, "nbv": nbv,
        "per_line": per_line, "one_scan": one_scan, "max_log_odds_diff": max_diff,
        "omp_num_threads": omp,
    }
    with open(os.path.join(a.dir, "octomap_result.json"), "w") as f:
        json.dump(result, f, indent=2)


if __name__ == "__main__":
    main()

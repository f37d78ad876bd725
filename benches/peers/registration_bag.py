"""The same views registered by `nbv register` from PLY files and from a ROS 2 bag that
rosbags wrote, scored against the same ground truth: the bag path loses nothing.

    registration_bag.py --views DIR --nbv NBV --writer BAG_OF_SCANS_PY [--keep BAG_DIR]

DIR is a views directory (view_<k>.ply in each sensor's frame, initial.json, truth.json,
spec.json: `stanford_scans.py`, or the `user_scans` / `registration_views` examples). The
bag is written by bag/tests/python/bag_of_scans.py with rosbags' own Writer: /scans
(PointCloud2 in `camera_optical`, NaN padding, organised), /tf with the views' initial
poses through odom and camera_link, /tf_static. Both runs use `nbv register`'s defaults;
the errors are the per-view RMS point displacement against truth.json, as
open3d_registration.py reports them. Run with a Python that has rosbags 0.11.9 and numpy.
"""

import argparse
import json
import os
import re
import subprocess
import sys
import tempfile

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from stanford_scans import read_ply_vertices  # noqa: E402
from view_errors import point_errors  # noqa: E402


def run(cmd):
    out = subprocess.run(cmd, capture_output=True, text=True)
    if out.returncode not in (0, 3):
        sys.exit(f"{' '.join(cmd)} failed ({out.returncode}):\n{out.stderr}")
    m = re.search(r"in ([0-9.]+) ms", out.stdout + out.stderr)
    return float(m.group(1)) if m else float("nan")


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--views", required=True)
    ap.add_argument("--nbv", required=True)
    ap.add_argument("--writer", required=True, help="bag/tests/python/bag_of_scans.py")
    ap.add_argument("--keep", help="write the bag here (must not exist) and keep it")
    args = ap.parse_args()

    spec = json.load(open(os.path.join(args.views, "spec.json")))
    names = spec["files"]
    files = [os.path.join(args.views, n) for n in names]
    points = [read_ply_vertices(f) for f in files]
    initial = json.load(open(os.path.join(args.views, "initial.json")))
    truth_json = json.load(open(os.path.join(args.views, "truth.json")))
    truth = [np.array(truth_json[n]) for n in names]

    with tempfile.TemporaryDirectory() as tmp:
        scans = os.path.join(tmp, "scans.json")
        with open(scans, "w") as f:
            json.dump({"scans": [{"points": p.tolist(), "pose": initial[n]}
                                 for p, n in zip(points, names)]}, f)
        bag = args.keep or os.path.join(tmp, "bag")
        subprocess.run([sys.executable, args.writer, bag, scans], check=True,
                       capture_output=True)

        rows = []
        out = os.path.join(tmp, "files.json")
        ms = run([args.nbv, "register", *files, "--init", os.path.join(args.views, "initial.json"),
                  "-o", os.path.join(tmp, "files.ply"), "--poses", out])
        data = json.load(open(out))
        rows.append(("PLY files + initial.json", [np.array(data[n]) for n in names], ms))

        out = os.path.join(tmp, "bag.json")
        ms = run([args.nbv, "register", "--bag", bag, "--topic", "/scans", "--fixed-frame",
                  "world", "-o", os.path.join(tmp, "bag.ply"), "--poses", out])
        data = json.load(open(out))
        rows.append(("rosbags bag (/scans, /tf)",
                     [np.array(data[f"/scans#{k}"]) for k in range(len(names))], ms))

    init = [np.array(initial[n]) for n in names]
    print(f"{len(names)} views, {sum(len(p) for p in points)} points ({args.views})")
    print(f"{'input':28} {'mean err mm':>11} {'worst mm':>9} {'worst deg':>9} {'time ms':>9}")
    for label, poses, ms in [("initial poses", init, float("nan"))] + rows:
        rms, rot = point_errors(points, poses, truth)
        print(f"{label:28} {np.mean(rms) * 1000:11.3f} {max(rms) * 1000:9.3f} {max(rot):9.3f} "
              f"{ms:9.1f}")
    a, b = rows[0][1], rows[1][1]
    gap = max(float(np.abs(x - y).max()) for x, y in zip(a, b))
    print(f"largest difference between the two runs' pose matrices: {gap:.2e}")


if __name__ == "__main__":
    main()

"""A set of real range scans in the Stanford 3D Scanning Repository's layout (a `.conf` file
and one ASCII or binary PLY per scan) as the views directory `open3d_registration.py` reads,
with the scans' poses disturbed as a user's robot or turntable would give them.

    python3 stanford_scans.py SCANS_DIR OUT_DIR [--conf bun.conf] [--deg 2] [--mm 5] [--seed 1]

SCANS_DIR holds the `.conf` (`bmesh FILE tx ty tz qx qy qz qw` lines: the scan-to-world
pose, quaternion real part last) and the scans it names; scans it names but that are absent
are skipped. Nothing is downloaded: bring the scans yourself (the Stanford bunny's `data/`
directory, for one).

OUT_DIR (must not exist) gets view_<k>.ply (each scan's vertices as written, in its own
frame, binary float32), truth.json (the `.conf` poses: the reference the error is measured
against), initial.json (every view but the first turned by `--deg` degrees about a random
axis and moved by `--mm` millimetres in a random direction, seeded; view 0 exact: the gauge)
and spec.json. Pose files map file names to 4x4 row-major view-to-world matrices, the
format `nbv register --init` reads.
"""

import argparse
import json
import os
import sys

import numpy as np


def read_conf(path):
    """(file, 4x4 scan-to-world) for every bmesh line, in order."""
    out = []
    with open(path) as f:
        for n, line in enumerate(f, 1):
            w = line.split()
            if not w or w[0] != "bmesh":
                continue
            if len(w) != 9:
                sys.exit(f"{path}:{n}: a bmesh line has a file and 7 numbers, found {len(w) - 1} fields")
            try:
                tx, ty, tz, qx, qy, qz, qw = map(float, w[2:])
            except ValueError as e:
                sys.exit(f"{path}:{n}: {e}")
            q = np.array([qw, qx, qy, qz])
            norm = np.linalg.norm(q)
            if not np.isfinite(norm) or norm < 1e-9:
                sys.exit(f"{path}:{n}: the quaternion has no length")
            # The Stanford files' rotation is the conjugate's: p_world = R(q)ᵀ p + t (checked
            # on the bunny: the scans' overlaps agree to 0.3–0.4 mm only so).
            qw, qx, qy, qz = q / norm
            qx, qy, qz = -qx, -qy, -qz
            m = np.identity(4)
            m[:3, :3] = [
                [1 - 2 * (qy * qy + qz * qz), 2 * (qx * qy - qz * qw), 2 * (qx * qz + qy * qw)],
                [2 * (qx * qy + qz * qw), 1 - 2 * (qx * qx + qz * qz), 2 * (qy * qz - qx * qw)],
                [2 * (qx * qz - qy * qw), 2 * (qy * qz + qx * qw), 1 - 2 * (qx * qx + qy * qy)],
            ]
            m[:3, 3] = [tx, ty, tz]
            out.append((w[1], m))
    if not out:
        sys.exit(f"{path}: no bmesh line")
    return out


def read_ply_vertices(path):
    """The x, y, z of a PLY's vertex element (ASCII or binary little-endian)."""
    with open(path, "rb") as f:
        if f.readline().strip() != b"ply":
            sys.exit(f"{path}: not a PLY file")
        fmt, count, props, in_vertex, before = None, None, [], False, 0
        while True:
            line = f.readline()
            if not line:
                sys.exit(f"{path}: the header has no end_header")
            w = line.decode("ascii", "replace").split()
            if not w:
                continue
            if w[0] == "format":
                fmt = w[1]
            elif w[0] == "element":
                in_vertex = w[1] == "vertex"
                if in_vertex:
                    count = int(w[2])
                elif count is None:
                    before += 1
            elif w[0] == "property" and in_vertex:
                if w[1] == "list":
                    sys.exit(f"{path}: a list property in the vertex element")
                props.append((w[2], w[1]))
            elif w[0] == "end_header":
                break
        if count is None or before:
            sys.exit(f"{path}: no vertex element first")
        names = [p[0] for p in props]
        if not {"x", "y", "z"} <= set(names):
            sys.exit(f"{path}: the vertex element has no x, y, z")
        if fmt == "ascii":
            rows = [f.readline().split() for _ in range(count)]
            data = np.array([[float(r[names.index(c)]) for c in "xyz"] for r in rows])
        elif fmt == "binary_little_endian":
            types = {"float": "<f4", "float32": "<f4", "double": "<f8", "float64": "<f8",
                     "uchar": "u1", "uint8": "u1", "int": "<i4", "int32": "<i4",
                     "uint": "<u4", "uint32": "<u4", "short": "<i2", "ushort": "<u2"}
            dtype = np.dtype([(n, types[t]) for n, t in props])
            rec = np.frombuffer(f.read(dtype.itemsize * count), dtype=dtype, count=count)
            data = np.stack([rec[c].astype(float) for c in "xyz"], axis=1)
        else:
            sys.exit(f"{path}: format {fmt} is not read here")
    return data


def write_ply(path, points):
    header = (f"ply\nformat binary_little_endian 1.0\nelement vertex {len(points)}\n"
              "property float x\nproperty float y\nproperty float z\nend_header\n")
    with open(path, "wb") as f:
        f.write(header.encode())
        f.write(points.astype("<f4").tobytes())


def disturbed(pose, deg, mm, rng):
    axis = rng.normal(size=3)
    axis /= np.linalg.norm(axis)
    a = np.radians(deg)
    k = np.array([[0, -axis[2], axis[1]], [axis[2], 0, -axis[0]], [-axis[1], axis[0], 0]])
    r = np.identity(3) + np.sin(a) * k + (1 - np.cos(a)) * (k @ k)
    d = rng.normal(size=3)
    d *= mm / 1000.0 / np.linalg.norm(d)
    out = pose.copy()
    # The error is the robot's: about the sensor's own frame, so the view turns about itself.
    out[:3, :3] = pose[:3, :3] @ r
    out[:3, 3] = pose[:3, 3] + d
    return out


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("scans")
    ap.add_argument("out")
    ap.add_argument("--conf", default=None, help="the .conf file (default: the one *.conf in SCANS)")
    ap.add_argument("--deg", type=float, default=2.0)
    ap.add_argument("--mm", type=float, default=5.0)
    ap.add_argument("--seed", type=int, default=1)
    args = ap.parse_args()

    conf = args.conf
    if conf is None:
        found = sorted(f for f in os.listdir(args.scans) if f.endswith(".conf"))
        if len(found) != 1:
            sys.exit(f"{args.scans}: expected one .conf file, found {found}")
        conf = os.path.join(args.scans, found[0])
    if os.path.exists(args.out):
        sys.exit(f"{args.out}: exists")
    entries = [(f, m) for f, m in read_conf(conf) if os.path.exists(os.path.join(args.scans, f))]
    if len(entries) < 2:
        sys.exit(f"{conf}: fewer than two of its scans are in {args.scans}")
    rng = np.random.default_rng(args.seed)
    tmp = args.out + ".partial"
    os.makedirs(tmp)
    names, truth, initial, sources = [], {}, {}, []
    for k, (f, pose) in enumerate(entries):
        name = f"view_{k}.ply"
        points = read_ply_vertices(os.path.join(args.scans, f))
        write_ply(os.path.join(tmp, name), points)
        names.append(name)
        sources.append({"file": f, "points": len(points)})
        truth[name] = pose.tolist()
        initial[name] = (pose if k == 0 else disturbed(pose, args.deg, args.mm, rng)).tolist()
    for fname, value in [("truth.json", truth), ("initial.json", initial),
                         ("spec.json", {"files": names, "scans": sources, "conf": os.path.basename(conf),
                                        "pose_error": {"deg": args.deg, "mm": args.mm, "seed": args.seed}})]:
        with open(os.path.join(tmp, fname), "w") as out:
            json.dump(value, out, indent=1)
            out.write("\n")
    os.rename(tmp, args.out)
    print(f"{args.out}: {len(names)} views, {sum(s['points'] for s in sources)} points")


if __name__ == "__main__":
    main()

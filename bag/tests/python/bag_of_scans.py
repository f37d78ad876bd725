#!/usr/bin/env python3
"""Write a user's scans as a ROS 2 bag with rosbags' Writer (rosbag2 v8, MCAP storage), the
way a lab's recorder would: what `nbv register --bag` is tested on.

Usage: bag_of_scans.py OUTDIR SCANS.json

SCANS.json: {"scans": [{"points": [[x, y, z], ...], "pose": [[4x4 row-major]]}, ...]},
each scan's points in its sensor frame and `pose` the sensor's pose in `world`
(p_world = R p + t).

- /scans (sensor_msgs/msg/PointCloud2), scan i stamped 20 + i s in frame `camera_optical`:
  fields x, y, z FLOAT32 at 0, 4, 8 and a padding float of NaN (point_step 16, PCL's
  PointXYZ), an organised cloud of 2 rows when the count is even, is_dense False.
- /tf_static: world -> odom, a fixed offset (0.5, -0.25, 0.1) m turned 30 degrees about z;
  odom -> camera_link at 20 + i - 0.1 s and 20 + i + 0.1 s, the scan's pose moved by -2 mm
  and +2 mm along x (so tf2's linear interpolation gives it exactly at the stamp);
  camera_link -> camera_optical static, the optical rotation (z forward, x right, y down).

OUTDIR must not exist. Needs rosbags==0.11.9.
"""

from __future__ import annotations

import json
import math
import sys
from pathlib import Path

import numpy as np
from rosbags.rosbag2 import StoragePlugin, Writer
from rosbags.typesys import Stores, get_typestore

S = 1_000_000_000
ODOM = np.array(
    [
        [math.cos(math.pi / 6), -math.sin(math.pi / 6), 0.0, 0.5],
        [math.sin(math.pi / 6), math.cos(math.pi / 6), 0.0, -0.25],
        [0.0, 0.0, 1.0, 0.1],
        [0.0, 0.0, 0.0, 1.0],
    ]
)
# camera_link (x forward, y left, z up) -> camera_optical (z forward, x right, y down).
OPTICAL = np.array(
    [[0.0, 0.0, 1.0, 0.0], [-1.0, 0.0, 0.0, 0.0], [0.0, -1.0, 0.0, 0.0], [0.0, 0.0, 0.0, 1.0]]
)


def quaternion(r: np.ndarray) -> tuple[float, float, float, float]:
    """x, y, z, w of a rotation matrix."""
    t = np.trace(r)
    if t > 0:
        s = math.sqrt(t + 1.0) * 2
        return ((r[2, 1] - r[1, 2]) / s, (r[0, 2] - r[2, 0]) / s, (r[1, 0] - r[0, 1]) / s, s / 4)
    i = int(np.argmax(np.diag(r)))
    j, k = (i + 1) % 3, (i + 2) % 3
    s = math.sqrt(1.0 + r[i, i] - r[j, j] - r[k, k]) * 2
    q = [0.0, 0.0, 0.0, (r[k, j] - r[j, k]) / s]
    q[i] = s / 4
    q[j] = (r[j, i] + r[i, j]) / s
    q[k] = (r[k, i] + r[i, k]) / s
    return tuple(q)


def main() -> int:
    if len(sys.argv) != 3:
        print(__doc__, file=sys.stderr)
        return 2
    out, scans = Path(sys.argv[1]), json.loads(Path(sys.argv[2]).read_text())['scans']
    ts = get_typestore(Stores.ROS2_HUMBLE)
    T = ts.types
    PointCloud2, TFMessage = T['sensor_msgs/msg/PointCloud2'], T['tf2_msgs/msg/TFMessage']

    def stamp(t_ns: int):
        return T['builtin_interfaces/msg/Time'](sec=t_ns // S, nanosec=t_ns % S)

    def tf(parent: str, child: str, t_ns: int, m: np.ndarray):
        x, y, z, w = quaternion(m[:3, :3])
        return T['geometry_msgs/msg/TransformStamped'](
            header=T['std_msgs/msg/Header'](stamp=stamp(t_ns), frame_id=parent),
            child_frame_id=child,
            transform=T['geometry_msgs/msg/Transform'](
                translation=T['geometry_msgs/msg/Vector3'](x=m[0, 3], y=m[1, 3], z=m[2, 3]),
                rotation=T['geometry_msgs/msg/Quaternion'](x=x, y=y, z=z, w=w),
            ),
        )

    def cdr(msg, typ) -> bytes:
        return ts.serialize_cdr(msg, typ.__msgtype__)

    fields = [
        T['sensor_msgs/msg/PointField'](name=n, offset=4 * i, datatype=7, count=1)
        for i, n in enumerate('xyz')
    ]
    with Writer(out, version=8, storage_plugin=StoragePlugin.MCAP) as w:
        cloud_c = w.add_connection('/scans', PointCloud2.__msgtype__, typestore=ts)
        tf_c = w.add_connection('/tf', TFMessage.__msgtype__, typestore=ts)
        static_c = w.add_connection('/tf_static', TFMessage.__msgtype__, typestore=ts)
        statics = [tf('world', 'odom', 0, ODOM), tf('camera_link', 'camera_optical', 0, OPTICAL)]
        w.write(static_c, 1, cdr(TFMessage(transforms=statics), TFMessage))
        inv_odom, inv_optical = np.linalg.inv(ODOM), np.linalg.inv(OPTICAL)
        for i, scan in enumerate(scans):
            t = (20 + i) * S
            # world <- optical = ODOM · link(t) · OPTICAL, so link = ODOM⁻¹ · pose · OPTICAL⁻¹.
            link = inv_odom @ np.array(scan['pose']) @ inv_optical
            for dt, dx in ((-S // 10, -0.002), (S // 10, 0.002)):
                m = link.copy()
                m[0, 3] += dx
                w.write(tf_c, t + dt, cdr(TFMessage(transforms=[tf('odom', 'camera_link', t + dt, m)]), TFMessage))
            pts = np.asarray(scan['points'], dtype='<f4')
            rec = np.full((len(pts), 4), np.nan, dtype='<f4')
            rec[:, :3] = pts
            height = 2 if len(pts) % 2 == 0 else 1
            width = len(pts) // height
            cloud = PointCloud2(
                header=T['std_msgs/msg/Header'](stamp=stamp(t), frame_id='camera_optical'),
                height=height,
                width=width,
                fields=fields,
                is_bigendian=False,
                point_step=16,
                row_step=16 * width,
                data=np.frombuffer(rec.tobytes(), dtype=np.uint8),
                is_dense=False,
            )
            w.write(cloud_c, t, cdr(cloud, PointCloud2))
    print(out)
    return 0


if __name__ == '__main__':
    sys.exit(main())

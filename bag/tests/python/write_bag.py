#!/usr/bin/env python3
"""Write a reference bag with rosbags' Writer (rosbag2 v8, MCAP storage).

Usage: write_bag.py OUTDIR [N]

- /points (sensor_msgs/msg/PointCloud2), N clouds (default 3) in frame `sensor`: 200
  points on a sphere of radius 0.5 m centred at (0, 0, 2) in the sensor frame, fields
  x, y, z FLOAT32 at 0, 4, 8 plus a padding float (point_step 16). Cloud i is stamped
  (and logged) at 10 + i + 0.5 s.
- /tf (tf2_msgs/msg/TFMessage): world -> sensor at 10 + i s for i = 0..=N, translation
  (i, 0, 1) m, identity rotation, so at a cloud's stamp the sensor is at (i + 0.5, 0, 1)
  and the sphere's centre in `world` is (i + 0.5, 0, 3).
- /tf_static: world -> table, translation (0, 0, 0.75), transient-local QoS.

OUTDIR must not exist. Needs rosbags==0.11.9 (and numpy, which it pulls in).
"""

from __future__ import annotations

import math
import sys
from pathlib import Path

import numpy as np
from rosbags.interfaces import (
    Qos,
    QosDurability,
    QosHistory,
    QosLiveliness,
    QosReliability,
    QosTime,
)
from rosbags.rosbag2 import StoragePlugin, Writer
from rosbags.typesys import Stores, get_typestore

S = 1_000_000_000


def sphere(n: int = 200, radius: float = 0.5, centre=(0.0, 0.0, 2.0)) -> np.ndarray:
    """Fibonacci points on a sphere, float32, shape (n, 3)."""
    pts = []
    golden = math.pi * (3.0 - math.sqrt(5.0))
    for k in range(n):
        z = 1.0 - 2.0 * (k + 0.5) / n
        r = math.sqrt(1.0 - z * z)
        phi = golden * k
        pts.append(
            (
                centre[0] + radius * r * math.cos(phi),
                centre[1] + radius * r * math.sin(phi),
                centre[2] + radius * z,
            )
        )
    return np.asarray(pts, dtype=np.float32)


def main() -> int:
    if len(sys.argv) not in (2, 3):
        print(__doc__, file=sys.stderr)
        return 2
    out = Path(sys.argv[1])
    n = int(sys.argv[2]) if len(sys.argv) == 3 else 3
    ts = get_typestore(Stores.ROS2_HUMBLE)
    Time = ts.types['builtin_interfaces/msg/Time']
    Header = ts.types['std_msgs/msg/Header']
    PointField = ts.types['sensor_msgs/msg/PointField']
    PointCloud2 = ts.types['sensor_msgs/msg/PointCloud2']
    TFMessage = ts.types['tf2_msgs/msg/TFMessage']
    TransformStamped = ts.types['geometry_msgs/msg/TransformStamped']
    Transform = ts.types['geometry_msgs/msg/Transform']
    Vector3 = ts.types['geometry_msgs/msg/Vector3']
    Quaternion = ts.types['geometry_msgs/msg/Quaternion']

    def stamp(t_ns: int):
        return Time(sec=t_ns // S, nanosec=t_ns % S)

    def tf(parent: str, child: str, t_ns: int, xyz) -> object:
        return TransformStamped(
            header=Header(stamp=stamp(t_ns), frame_id=parent),
            child_frame_id=child,
            transform=Transform(
                translation=Vector3(x=xyz[0], y=xyz[1], z=xyz[2]),
                rotation=Quaternion(x=0.0, y=0.0, z=0.0, w=1.0),
            ),
        )

    pts = sphere()
    rec = np.zeros((len(pts), 4), dtype='<f4')
    rec[:, :3] = pts
    rec[:, 3] = np.nan  # the padding float
    data = np.frombuffer(rec.tobytes(), dtype=np.uint8)
    fields = [
        PointField(name=name, offset=4 * i, datatype=7, count=1) for i, name in enumerate('xyz')
    ]
    latched = Qos(
        QosHistory.KEEP_LAST,
        1,
        QosReliability.RELIABLE,
        QosDurability.TRANSIENT_LOCAL,
        QosTime(2147483647, 4294967295),
        QosTime(2147483647, 4294967295),
        QosLiveliness.AUTOMATIC,
        QosTime(2147483647, 4294967295),
        False,
    )

    with Writer(out, version=8, storage_plugin=StoragePlugin.MCAP) as w:
        points = w.add_connection('/points', PointCloud2.__msgtype__, typestore=ts)
        tfc = w.add_connection('/tf', TFMessage.__msgtype__, typestore=ts)
        static = w.add_connection(
            '/tf_static', TFMessage.__msgtype__, typestore=ts, offered_qos_profiles=[latched]
        )
        t0 = 10 * S
        msg = TFMessage(transforms=[tf('world', 'table', t0, (0.0, 0.0, 0.75))])
        w.write(static, t0, ts.serialize_cdr(msg, TFMessage.__msgtype__))
        for i in range(n + 1):
            t = t0 + i * S
            msg = TFMessage(transforms=[tf('world', 'sensor', t, (float(i), 0.0, 1.0))])
            w.write(tfc, t, ts.serialize_cdr(msg, TFMessage.__msgtype__))
        for i in range(n):
            t = t0 + i * S + S // 2
            cloud = PointCloud2(
                header=Header(stamp=stamp(t), frame_id='sensor'),
                height=1,
                width=len(pts),
                fields=fields,
                is_bigendian=False,
                point_step=16,
                row_step=16 * len(pts),
                data=data,
                is_dense=False,
            )
            w.write(points, t, ts.serialize_cdr(cloud, PointCloud2.__msgtype__))
    print(out)
    return 0


if __name__ == '__main__':
    sys.exit(main())

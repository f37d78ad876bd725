#!/usr/bin/env python3
"""Cross-check a bag written by nbv-bag with two independent readers.

Usage: check_bag.py BAGDIR   (a rosbag2 directory, or a bare .mcap file)

Opens the bag with rosbags' AnyReader and, file by file, with
mcap.reader.make_reader(validate_crcs=True) + mcap_ros2's DecoderFactory, decodes every
message on every topic with both, and prints JSON: per-topic counts from each reader, the
header profile, the durability rosbags reads for each topic's QoS, and per topic how many
messages rosbags re-serializes to exactly the bytes in the bag (`cdr_identical`; ROS's own
serializers may add trailing padding, so a difference there is reported, not failed). Exits non-zero on
any exception, on a profile other than ros2, or when the two readers' counts differ.

Needs: rosbags==0.11.9 mcap==1.6.0 mcap-ros2-support==0.6.0
"""

from __future__ import annotations

import json
import sys
from pathlib import Path

from mcap.reader import make_reader
from mcap_ros2.decoder import DecoderFactory
from rosbags.highlevel import AnyReader


def mcap_files(bag: Path) -> list[Path]:
    if bag.is_file():
        return [bag]
    return sorted(bag.glob('*.mcap'))


def main() -> int:
    if len(sys.argv) != 2:
        print(__doc__, file=sys.stderr)
        return 2
    bag = Path(sys.argv[1])
    out: dict = {
        'rosbags': {},
        'mcap_ros2': {},
        'profiles': [],
        'durability': {},
        'types': {},
        'cdr_identical': {},
    }

    with AnyReader([bag]) as reader:
        for conn in reader.connections:
            out['types'][conn.topic] = conn.msgtype
            qos = getattr(conn.ext, 'offered_qos_profiles', None) or []
            out['durability'][conn.topic] = [q.durability.name for q in qos]
            out['rosbags'].setdefault(conn.topic, 0)
            out['cdr_identical'].setdefault(conn.topic, 0)
        for conn, _t, raw in reader.messages():
            msg = reader.deserialize(raw, conn.msgtype)
            out['rosbags'][conn.topic] += 1
            again = reader.typestore.serialize_cdr(msg, conn.msgtype)
            out['cdr_identical'][conn.topic] += int(bytes(again) == bytes(raw))

    for path in mcap_files(bag):
        with path.open('rb') as f:
            reader = make_reader(f, validate_crcs=True, decoder_factories=[DecoderFactory()])
            header = reader.get_header()
            out['profiles'].append(header.profile)
            if header.profile != 'ros2':
                print(f'{path}: profile {header.profile!r}', file=sys.stderr)
                return 1
            for _schema, channel, _msg, _decoded in reader.iter_decoded_messages(
                log_time_order=True
            ):
                out['mcap_ros2'][channel.topic] = out['mcap_ros2'].get(channel.topic, 0) + 1
            # every channel appears, even with no messages
            summary = reader.get_summary()
            if summary is not None:
                for channel in summary.channels.values():
                    out['mcap_ros2'].setdefault(channel.topic, 0)

    print(json.dumps(out, indent=2, sort_keys=True))
    if out['rosbags'] != out['mcap_ros2']:
        print('per-topic counts differ between rosbags and mcap_ros2', file=sys.stderr)
        return 1
    return 0


if __name__ == '__main__':
    try:
        sys.exit(main())
    except Exception as e:  # noqa: BLE001 - any failure is a failed check
        print(f'check failed: {type(e).__name__}: {e}', file=sys.stderr)
        sys.exit(1)

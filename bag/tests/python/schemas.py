"""Prints, as JSON, the ros2msg schema text rosbags generates for each type named on the
command line (`pkg/msg/Type`), from its ROS 2 Humble type store."""
import json
import sys

from rosbags.typesys import Stores, get_typestore

store = get_typestore(Stores.ROS2_HUMBLE)
print(json.dumps({t: store.generate_msgdef(t, ros_version=2)[0] for t in sys.argv[1:]}))

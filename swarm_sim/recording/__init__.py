"""Recording: a ROS-free rosbag2 recorder and reader with MCAP storage.

Runs are recorded inside the simulation loop and analysed without a running ROS, so neither side
may need rclpy or rosbag2_py. `mcap` (foxglove) writes and reads the files, `rosbags` supplies the
message definitions; the result is a rosbag2 directory (``metadata.yaml`` version 9, as Jazzy's
``ros2 bag record`` writes it) that ``ros2 bag``, rosbags and Foxglove open.

A run that is killed must keep almost all of its data, so the writer

* splits the bag into ``<dirname>_<i>.mcap`` every ``split_seconds`` of wall time; every file but
  the one in progress is finalised (summary, footer, the ``rosbag2`` metadata record). The next
  file is opened before the previous one is finalised, so at every instant some file is
  unfinished and any kill shows up as a truncated bag;
* closes the chunk in progress and flushes it to the OS every ``flush_seconds`` of wall time, so
  SIGKILL loses at most the last ``flush_seconds`` of writes (``fsync=True`` also survives a power
  cut);
* rewrites ``metadata.yaml`` atomically when the bag opens, at every split and at close, listing
  the finished files and the file in progress.

The reader recovers every complete record of a file that was cut off mid-write and reports it
(`BagInfo.truncated`, a `BagTruncatedWarning` naming the file); a bag without ``metadata.yaml`` is
read from its ``*.mcap`` files alone. rosbags and ``ros2 bag`` need every file finalised, so they
read a cleanly closed bag only; `repair_bag` (``swarm-analyze --repair``, and ``swarm-run`` itself
when the world node died) rewrites a cut-off bag into one they read, losing nothing recovered.

Modules: `metadata` (constants, errors, records, metadata.yaml and QoS text), `writer`
(`BagWriter`), `mcap_file` (one MCAP file, record by record, with truncation recovery),
`reader` (`read_bag`, `bag_info`), `repair` (`repair_bag`).
"""

from swarm_sim.recording.metadata import (
    QOS_NAMES,
    BagError,
    BagFileInfo,
    BagInfo,
    BagMessage,
    BagTruncatedWarning,
    TopicInfo,
    flatten_metadata,
)
from swarm_sim.recording.reader import bag_info, read_bag
from swarm_sim.recording.repair import repair_bag
from swarm_sim.recording.writer import BagWriter

__all__ = [
    "QOS_NAMES",
    "BagError",
    "BagFileInfo",
    "BagInfo",
    "BagMessage",
    "BagTruncatedWarning",
    "BagWriter",
    "TopicInfo",
    "bag_info",
    "flatten_metadata",
    "read_bag",
    "repair_bag",
]

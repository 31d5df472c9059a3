"""swarm_msgs_py: the vocabulary at the bottom of the house, where a core type (`types`) meets a
standard ROS message (each paper's own messages have their codecs in its package). It imports no
other project package and no ROS package: the rclpy side is `swarm_sim.nodes`.

Only standard common_interfaces types travel, so a stock Jazzy ``ros2 topic echo`` and any
MCAP viewer read every topic. The hot codecs write and read CDR bytes directly with `struct`
(rclpy publishes `bytes`; ``raw=True`` subscriptions hand us bytes) and import no ROS package,
so bag analysis decodes without ROS.

Stamps are integer sim-time nanoseconds (``header.stamp`` = the tick). Every decoder raises
`CodecError` (a ValueError naming the ROS type) on malformed or truncated bytes. Each codec
module's docstring gives its field-by-field mapping.

Names and types as data: `topics` (the shared topics: clock, robot observations and commands,
status, world topics, diagnostics, the lockstep ack); a task's sense fields are declared by its
`sensing.Sensing` record (the whole sense in one message on ``sense``), each paper's protocol
topics by its own codec module (a `records.RecordFamily`), a server's state and markers topics,
and the run-trace series read off what it publishes, with its registry record
(`server_outputs`). QoS profiles: `qos`. The topic map, every topic with its type, direction and
QoS, is docs/topics.md.
"""

from swarm_msgs_py.cdr import CodecError

__all__ = ["CodecError"]

"""QoS profiles, one per kind of stream, so publishers and subscribers always match.

- `SENSOR_LOCKSTEP` (observations, commands, ``/clock``, ``/lockstep/ack``): best effort,
  because the lockstep barrier already recovers a lost sample: a tick not answered within
  ``resend_period`` is published again to the robots (and servers) still waiting, and a
  controller that has answered that tick sends its answer again (`WorldNode._await_commands`).
  Reliability on top of that made every sample cost a heartbeat/acknack exchange and a writer
  timer: with 112 robots in one controller process, 1250 context switches and 19 ms of CPU
  per tick in the world, 190 and 13 ms best effort (docs/benchmarks.md). Depth 10
  absorbs a slow subscriber for a few ticks; volatile, since a late joiner wants the next tick,
  not old ones. A stock ``ros2 topic echo`` matches it (it adapts to the publishers' QoS).
- `STATE_LATCHED` (assignments, depot/queue state, markers, cumulative robot stats):
  reliable + transient-local with depth 1, so a node that joins late receives the current
  state at once.
- `EVENTS` (world events, behaviour status, pheromones): reliable and deep,
  because every event counts and bursts (many pickups in one tick) must not be dropped.
- `STATE_STREAM` (a state published every tick that robots also act on, e.g. the DRTM nest's
  ``/nest/state``): reliable + transient-local like `STATE_LATCHED`, with a little depth so
  that no tick's state is overwritten before a slow subscriber has it.
"""

from __future__ import annotations

from rclpy.qos import DurabilityPolicy, HistoryPolicy, QoSProfile, ReliabilityPolicy

SENSOR_LOCKSTEP = QoSProfile(
    reliability=ReliabilityPolicy.BEST_EFFORT,
    durability=DurabilityPolicy.VOLATILE,
    history=HistoryPolicy.KEEP_LAST,
    depth=10,
)

STATE_LATCHED = QoSProfile(
    reliability=ReliabilityPolicy.RELIABLE,
    durability=DurabilityPolicy.TRANSIENT_LOCAL,
    history=HistoryPolicy.KEEP_LAST,
    depth=1,
)

EVENTS = QoSProfile(
    reliability=ReliabilityPolicy.RELIABLE,
    durability=DurabilityPolicy.VOLATILE,
    history=HistoryPolicy.KEEP_LAST,
    depth=1000,
)

STATE_STREAM = QoSProfile(
    reliability=ReliabilityPolicy.RELIABLE,
    durability=DurabilityPolicy.TRANSIENT_LOCAL,
    history=HistoryPolicy.KEEP_LAST,
    depth=10,
)


def family_qos(family: object, topic: str) -> QoSProfile:
    """The publisher QoS of a message family's topic: `STATE_STREAM` for the family's latched
    topics (`swarm_msgs_py.records.RecordFamily.latched`), `EVENTS` otherwise. Subscribers use
    `EVENTS`, which matches both."""
    return STATE_STREAM if topic in getattr(family, "latched", ()) else EVENTS


RECORD_LATCHED = QoSProfile(
    reliability=ReliabilityPolicy.RELIABLE,
    durability=DurabilityPolicy.TRANSIENT_LOCAL,
    history=HistoryPolicy.KEEP_LAST,
    depth=1000,
)
"""The recorder's subscription to a latched topic: gets the last message published before it
subscribed, then every later one."""


def rosbag2_profile(qos: QoSProfile, depth_if_unknown: int | None = None) -> dict:
    """`qos` as rosbag2 (metadata v9) writes an offered QoS profile. DDS discovery does not carry
    a remote publisher's history and depth (the graph reports UNKNOWN / 0); `depth_if_unknown`
    then gives the depth our own nodes publish that kind of topic with (`published_depth`)."""

    def duration(d) -> dict[str, int]:
        ns = d.nanoseconds
        return {"sec": ns // 1_000_000_000, "nsec": ns % 1_000_000_000}

    history, depth = qos.history.name.lower(), qos.depth
    if qos.history == HistoryPolicy.UNKNOWN and depth_if_unknown is not None:
        history, depth = "keep_last", depth_if_unknown
    return {
        "history": history,
        "depth": depth,
        "reliability": qos.reliability.name.lower(),
        "durability": qos.durability.name.lower(),
        "deadline": duration(qos.deadline),
        "lifespan": duration(qos.lifespan),
        "liveliness": qos.liveliness.name.lower(),
        "liveliness_lease_duration": duration(qos.liveliness_lease_duration),
        "avoid_ros_namespace_conventions": bool(qos.avoid_ros_namespace_conventions),
    }


def published_depth(topic: str, latched: bool) -> int:
    """The depth our nodes publish `topic` with: latched state `STATE_LATCHED`, the lockstep
    streams (``/clock``, ``/lockstep/ack``, a robot's observations and ``cmd_vel``)
    `SENSOR_LOCKSTEP`, everything else (events, statuses, protocol messages) `EVENTS`."""
    if latched:
        return STATE_LATCHED.depth
    parts = topic.split("/")
    lockstep = topic in ("/clock", "/lockstep/ack") or (len(parts) == 3 and parts[1].startswith("robot_")
                                                        and parts[2] != "status")
    return SENSOR_LOCKSTEP.depth if lockstep else EVENTS.depth

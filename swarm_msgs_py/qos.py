"""QoS profiles, one per kind of stream, so publishers and subscribers always match.

- `SENSOR_LOCKSTEP` (observations and commands): reliable, because in lockstep a lost
  message stalls the barrier until the stale timeout; depth 10 absorbs a slow subscriber
  for a few ticks; volatile, since a late joiner wants the next tick, not old ones.
- `STATE_LATCHED` (assignments, depot/queue state, markers, cumulative robot stats):
  reliable + transient-local with depth 1, so a node that joins late receives the current
  state at once.
- `EVENTS` (world events, behaviour status, pheromones): reliable and deep,
  because every event counts and bursts (many pickups in one tick) must not be dropped.
"""

from __future__ import annotations

from rclpy.qos import DurabilityPolicy, HistoryPolicy, QoSProfile, ReliabilityPolicy

SENSOR_LOCKSTEP = QoSProfile(
    reliability=ReliabilityPolicy.RELIABLE,
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

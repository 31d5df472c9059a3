"""QoS profiles, one per kind of stream, so publishers and subscribers always match.

- `SENSOR_LOCKSTEP` (observations and commands): reliable, because in lockstep a lost
  message stalls the barrier until the stale timeout; depth 10 absorbs a slow subscriber
  for a few ticks; volatile, since a late joiner wants the next tick, not old ones.
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

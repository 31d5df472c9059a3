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

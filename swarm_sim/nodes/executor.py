"""How a process of ours hosts its nodes: the executor they spin in, and one ``/clock``
subscription for all of them.

rclpy's C++ `EventsExecutor` (in Jazzy's rclpy as `rclpy.experimental`) dispatches callbacks
without rebuilding a Python wait set per wake-up, which is what limits a process hosting
many robots' subscriptions. `SWARM_EXECUTOR=single` falls back to the SingleThreadedExecutor.
"""

from __future__ import annotations

import os
from collections.abc import Sequence

from rclpy.context import Context
from rclpy.executors import Executor, SingleThreadedExecutor
from rclpy.node import Node


def make_executor(context: Context | None = None) -> Executor:
    if os.environ.get("SWARM_EXECUTOR", "events") != "single":
        try:
            from rclpy.experimental import EventsExecutor
        except ImportError:
            pass
        else:
            return EventsExecutor(context=context)
    return SingleThreadedExecutor(context=context)


def share_sim_time(nodes: Sequence[Node]) -> None:
    """Let the first node's time source drive every node's clock, with one ``/clock``
    subscription for the process instead of one per node.

    rclpy gives every node with ``use_sim_time`` its own ``/clock`` subscription; with 112
    controller nodes in one process every sim tick cost 112 deliveries and Python callbacks that
    all set the same time (about 2 ms of the process's ~15 ms of CPU per tick). The nodes keep
    their ``use_sim_time`` parameter and their clocks follow ``/clock`` as before. rclpy keeps a
    node's time source in the private ``_time_source``; where it does not, nothing changes.
    """
    source = getattr(nodes[0], "_time_source", None) if nodes else None
    if source is None:
        return
    for node in nodes[1:]:
        own = getattr(node, "_time_source", None)
        if own is None:
            continue
        own.detach_node()  # drops its /clock subscription
        source.attach_clock(node.get_clock())

"""How a process of ours hosts its nodes: the executor they spin in, and the clock of nodes that
step on the world's ticks.

rclpy's C++ `EventsExecutor` (in Jazzy's rclpy as `rclpy.experimental`) dispatches callbacks
without rebuilding a Python wait set per wake-up, which is what limits a process hosting
many robots' subscriptions. `SWARM_EXECUTOR=single` falls back to the SingleThreadedExecutor.
"""

from __future__ import annotations

import os

from rcl_interfaces.msg import ParameterDescriptor
from rclpy.clock_type import ClockType
from rclpy.context import Context
from rclpy.executors import Executor, SingleThreadedExecutor
from rclpy.node import Node
from rclpy.time import Time
from rclpy.time_source import USE_SIM_TIME_NAME, TimeSource


def make_executor(context: Context | None = None) -> Executor:
    """rclpy's EventsExecutor (``SWARM_EXECUTOR=single``: the SingleThreadedExecutor).

    Tear down in this order: ``executor.shutdown()``, drop the last reference to the executor
    (``executor = None``), then destroy the nodes. The EventsExecutor holds its nodes' QoS event
    handlers open (``with``) for the callbacks it registered or had queued, and lets go of them
    when it is destroyed: after the nodes, that closes a handler whose publisher is gone, a
    SIGSEGV (rclpy/event_handler.py ``__exit__``, seen in the world under load with the executor
    left to the interpreter's exit). The world itself no longer tears down (`lifetime.leave`)."""
    if os.environ.get("SWARM_EXECUTOR", "events") != "single":
        try:
            from rclpy.experimental import EventsExecutor
        except ImportError:
            pass
        else:
            return EventsExecutor(context=context)
    return SingleThreadedExecutor(context=context)


STAMP_TIME = "sim time from the stamps of the observations the node steps on; it hears no /clock (read-only)"
"""The description of ``use_sim_time`` on a node whose clock `StampTime` sets."""


class StampTime:
    """Sim time for nodes that step on the world's ticks, without ``/clock``.

    A controller steps on one tick's complete set of observations, all stamped with that tick, so
    it needs no other time. rclpy gives every node with ``use_sim_time`` a ``/clock``
    subscription: one message and a Python callback per tick and process, one of the five
    messages a tick that wake a process per robot (issue 40: a quarter of those processes' CPU). An attached node keeps ``use_sim_time``,
    declared true and read-only (`STAMP_TIME` says why), and its clock reads the newest tick any
    node of the process stepped on (`set`), as it read the newest ``/clock`` before.
    """

    def __init__(self) -> None:
        self._source = TimeSource()  # attached to no node: it never subscribes to /clock
        self._source.ros_time_is_active = True
        self._clocks = []
        self._ns = -1

    def attach(self, node: Node) -> None:
        """Take `node`'s clock off its own time source. The node must have been created with
        ``use_sim_time`` false (its time source then made no subscription)."""
        own = node._time_source  # rclpy keeps it private and offers no other handle on it
        if own.ros_time_is_active:
            raise ValueError(f"{node.get_fully_qualified_name()}: created with use_sim_time true; it subscribed /clock")
        node.remove_on_set_parameters_callback(own._on_parameter_event)
        own.detach_node()
        node.undeclare_parameter(USE_SIM_TIME_NAME)
        node.declare_parameter(USE_SIM_TIME_NAME, True, ParameterDescriptor(description=STAMP_TIME, read_only=True),
                               ignore_override=True)
        self._source.attach_clock(node.get_clock())
        self._clocks.append(node.get_clock())

    def set(self, stamp_ns: int) -> None:
        """A node steps on tick `stamp_ns`: the clocks read it (once per tick and process)."""
        if stamp_ns != self._ns:
            self._ns = stamp_ns
            now = Time(nanoseconds=stamp_ns, clock_type=ClockType.ROS_TIME)
            for clock in self._clocks:
                clock.set_ros_time_override(now)

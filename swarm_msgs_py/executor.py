"""The executor our nodes spin in.

rclpy's C++ `EventsExecutor` (in Jazzy's rclpy as `rclpy.experimental`) dispatches callbacks
without rebuilding a Python wait set per wake-up, which is what limits a process hosting
many robots' subscriptions. `SWARM_EXECUTOR=single` falls back to the SingleThreadedExecutor.
"""

from __future__ import annotations

import os

from rclpy.context import Context
from rclpy.executors import Executor, SingleThreadedExecutor


def make_executor(context: Context | None = None) -> Executor:
    if os.environ.get("SWARM_EXECUTOR", "events") != "single":
        try:
            from rclpy.experimental import EventsExecutor
        except ImportError:
            pass
        else:
            return EventsExecutor(context=context)
    return SingleThreadedExecutor(context=context)

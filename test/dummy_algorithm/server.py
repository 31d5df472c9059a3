"""The dummy's server core: counts the pings it hears (a time series for the run trace)."""

from __future__ import annotations

from collections.abc import Sequence

from dummy_algorithm.messages import Ping
from swarm_sim.types import NS_PER_S


class CounterServer:
    def __init__(self, scenario) -> None:
        self.robots = set(scenario.robot_names)
        self.pings = 0
        self.history: list[tuple[float, int]] = []

    def step(self, stamp_ns: int, messages: Sequence[object]) -> tuple[object, ...]:
        heard = sum(1 for m in messages if isinstance(m, Ping) and m.robot in self.robots)
        if heard:
            self.pings += heard
            self.history.append((stamp_ns / NS_PER_S, self.pings))
        return ()

    def series(self) -> dict[str, list[tuple[float, int]]]:
        return {"pings": list(self.history)}


def pings_heard(trace) -> int:
    """The dummy's JSON result field: pings the counter heard in the run."""
    history = trace.series.get("pings", [])
    return history[-1][1] if history else 0

"""The dummy's server core: counts the pings it hears (a time series for the run trace)."""

from __future__ import annotations

from collections.abc import Sequence

from dummy_algorithm.messages import Ping
from swarm_msgs_py.diagnostics import decode_diagnostics
from swarm_sim.types import NS_PER_S


class CounterServer:
    def __init__(self, scenario) -> None:
        self.robots = set(scenario.robot_names)
        self.history: list[tuple[float, int]] = []
        """(t [s], pings heard at that tick)."""

    def step(self, stamp_ns: int, messages: Sequence[object]) -> tuple[object, ...]:
        heard = sum(1 for m in messages if isinstance(m, Ping) and m.robot in self.robots)
        if heard:
            self.history.append((stamp_ns / NS_PER_S, heard))
        return ()

    def series(self) -> dict[str, list[tuple[float, int]]]:
        return {"pings": list(self.history)}


def pings_heard(trace) -> int:
    """The dummy's JSON result field: pings the counter heard in the run."""
    return sum(n for _, n in trace.series.get("pings", []))


def replay_pings(topic: str, data: bytes) -> list[tuple[str, float, int]]:
    """A recorded ``/dummy/pings`` message as a point of the ``pings`` series."""
    from dummy_algorithm.codec import PINGS

    if topic not in PINGS.topics.values():
        return []
    stamp_ns, _ = decode_diagnostics(data)
    return [("pings", stamp_ns / NS_PER_S, len(PINGS.decode(data)))]

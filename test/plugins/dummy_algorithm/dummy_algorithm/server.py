"""The dummy's server core: hears the robots' pings (the run trace's ``pings`` series is read
off them, `dummy_algorithm.codec.OUTPUTS`)."""

from __future__ import annotations

from collections.abc import Sequence

from dummy_algorithm.messages import Ping


class CounterServer:
    def __init__(self, scenario) -> None:
        self.robots = set(scenario.robot_names)
        self.heard = 0
        """Pings from robots of this run heard so far."""

    def step(self, stamp_ns: int, messages: Sequence[object]) -> tuple[object, ...]:
        self.heard += sum(1 for m in messages if isinstance(m, Ping) and m.robot in self.robots)
        return ()


def pings_heard(trace) -> int:
    """The dummy's JSON result field: pings the robots sent the counter in the run."""
    return sum(n for _, n in trace.series.get("pings", []))

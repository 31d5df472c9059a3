"""Message delivery helpers: a per-inbox summary is the summary of the tuple it is given."""

from __future__ import annotations

from swarm_controllers.cpfa.messages import PheromoneMessage
from swarm_sim.messaging import per_inbox


def test_per_inbox_summarises_each_tuple_once_and_never_confuses_two():
    calls: list[tuple] = []

    @per_inbox
    def count(messages: tuple) -> int:
        calls.append(messages)
        return len(messages)

    a = (PheromoneMessage(1, 0.0, 0.0), PheromoneMessage(2, 1.0, 1.0))
    b = tuple(list(a))  # equal but another tuple: summarised anew
    c = a[:1]
    assert [count(a), count(a), count(a)] == [2, 2, 2]
    assert count(c) == 1 and count(a) == 2 and count(b) == 2 and count(()) == 0
    assert [len(m) for m in calls] == [0, 2, 1, 2, 2, 0]  # the first: the empty inbox, up front

"""The dummy's sense on ``/<robot>/sense``: one status ``beacon``, value ``"range bearing"``
(`swarm_msgs_py.sensing.vector`); and its message family."""

from __future__ import annotations

from dummy_algorithm.messages import Ping
from dummy_algorithm.task import BeaconSense
from swarm_msgs_py.records import RecordFamily
from swarm_msgs_py.sensing import Sensing, vector
from swarm_sim.outputs import Series, ServerOutputs

SENSING = Sensing(BeaconSense, (vector("beacon", 2),))

PINGS = RecordFamily("pings", {Ping: "/dummy/pings"})
"""The dummy's message family: robots' pings to the counter server."""


def _ping(ping: Ping) -> dict[str, int]:
    return {"pings": 1}


OUTPUTS = ServerOutputs(series=(Series(PINGS.topics[Ping], _ping),))
"""The counter publishes nothing of its own; the trace's ``pings`` has a point per ping sent."""

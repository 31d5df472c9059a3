"""Shipped scenarios on the generic robot, for the tests that hand-work its motion.

The papers' scenarios run on their authors' robots (``robots.model``: the foot-bot models, the
Khepera III). Tests of a behaviour's logic whose expected commands, turns and positions are
worked out for the generic robot's continuous steering (`swarm_controllers.motion.ContinuousDrive`)
load their scenarios through `generic_scenario`; the platform models have tests of their own
(test_robot_models.py) and the end-to-end runs use each scenario as shipped.
"""

from __future__ import annotations

from collections.abc import Iterable
from typing import Any

from swarm_sim.scenario import Scenario, load_scenario


def generic_scenario(name: str | None = None, overrides: Iterable[str] = (), **fields: Any) -> Scenario:
    """`load_scenario` with ``robots.model=generic`` before the other overrides."""
    return load_scenario(name, ["robots.model=generic", *overrides], **fields)

"""The spiral search's scenario section (``controller.spiral``), declared in the DDSA and MDBSA
registry records (`swarm_controllers.spiral.registration`), and its check."""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, ClassVar

from swarm_sim.scenario import Section

if TYPE_CHECKING:
    from swarm_sim.scenario import Scenario


@dataclass(frozen=True)
class SpiralConfig(Section):
    """Square-spiral search (DDSA / MDBSA, Lu & Luna 2023). The regions themselves are world
    facts (the scenario's ``regions`` section)."""

    gap: float = 0.18
    """Distance g between adjacent spiral lines [m] (paper Sec. IV: 0.13 m detection radius
    plus room for encoder noise)."""
    arena_margin: float = 0.2
    """Spirals are clipped to the arena square shrunk by this much on every side [m]."""
    center_range: float = 0.75
    """MDBSA: robots talk to the center only within this distance of the depot centre [m]."""

    SECTION: ClassVar[str] = "spiral"


def check_spiral(scenario: Scenario) -> None:
    """Refuse spiral settings no planner can use (ValueError naming the key)."""
    sp = SpiralConfig.of(scenario)
    if not sp.gap > 0:
        raise ValueError("controller.spiral.gap: must be positive")
    if not sp.arena_margin >= 0:
        raise ValueError("controller.spiral.arena_margin: must not be negative")
    if not sp.arena_margin < scenario.arena.size / 2:
        raise ValueError("controller.spiral.arena_margin: leaves no arena to search")
    if not sp.center_range > 0:
        raise ValueError("controller.spiral.center_range: must be positive")

"""The controllers' own scenario sections (``controller.cpfa``, ``controller.spiral``).

Each is a frozen dataclass that the algorithms declare in their registry records
(`swarm_sim.algorithms`); the scenario loader builds it from the YAML with the same
key-naming errors as the world's sections, then runs the algorithm's check.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, ClassVar

from swarm_sim.scenario import Section

if TYPE_CHECKING:
    from swarm_sim.scenario import Scenario


@dataclass(frozen=True)
class CpfaConfig(Section):
    """Central-place foraging algorithm parameters (Hecker & Moses 2015, Table 1/3).

    Defaults are the values BCLab's CPFA implementation labels "according to Beyond
    Pheromones"; p_s and p_r are per draw of the reference controller (see `draw_rate`) and are
    rescaled to our tick by the behaviour.
    """

    probability_of_switching_to_searching: float = 0.045
    """p_s: chance per draw that a departing robot stops travelling and starts searching."""
    probability_of_returning_to_nest: float = 0.01
    """p_r: chance per draw that a searching robot gives up and returns."""
    uninformed_search_variation: float = 0.4
    """omega [rad]: std of the heading change of the correlated random walk."""
    rate_of_informed_search_decay: float = 0.1666
    """lambda_id [1/s]."""
    rate_of_site_fidelity: float = 5.0
    """lambda_sf: site fidelity with probability POIS(c, lambda_sf)."""
    rate_of_laying_pheromone: float = 5.0
    """lambda_lp: lay a pheromone waypoint with probability POIS(c, lambda_lp)."""
    rate_of_pheromone_decay: float = 0.025
    """lambda_pd [1/s]: strength exp(-lambda_pd * age)."""
    pheromone_threshold: float = 0.001
    """Waypoints weaker than this are forgotten."""
    search_step: float = 0.08
    """Distance between heading changes of the random walk [m]."""
    draw_rate: float = 0.2
    """How often [Hz] p_s and p_r are drawn in the reference implementation: the CPFA-ARGoS
    controller of the queue paper's lab draws both once every 5 s of its 16 Hz loop. The
    behaviour applies the same hazard per second at every tick of ours."""

    SECTION: ClassVar[str] = "cpfa"


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

"""The CPFA's scenario section (``controller.cpfa``), declared in its registry record
(`swarm_controllers.cpfa.registration`); the scenario loader builds it from the YAML with the
same key-naming errors as the world's sections."""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import ClassVar, Literal

from swarm_sim.scenario import ScenarioError, Section

CPFA_PARAMETER_SETS: dict[str, dict[str, float]] = {
    "beyond_pheromones": {
        "probability_of_switching_to_searching": 0.045,
        "probability_of_returning_to_nest": 0.01,
        "uninformed_search_variation": 0.4,
        "rate_of_informed_search_decay": 0.1666,
        "rate_of_site_fidelity": 5.0,
        "rate_of_laying_pheromone": 5.0,
        "rate_of_pheromone_decay": 0.025,
    },
    "queue_paper": {
        "probability_of_switching_to_searching": 0.765015191742,
        "probability_of_returning_to_nest": 0.0189370369448,
        "uninformed_search_variation": math.radians(3.67372660634),
        "rate_of_informed_search_decay": 0.346149969858,
        "rate_of_site_fidelity": 1.376331398,
        "rate_of_laying_pheromone": 14.4422484524,
        "rate_of_pheromone_decay": 0.337487746208,
    },
}
"""Named CPFA parameter sets (``controller.cpfa.parameter_set``).

``beyond_pheromones``: what BCLab's CPFA implementation labels "according to Beyond Pheromones"
(the defaults). ``queue_paper``: the evolved set in the queue paper's authors' experiment files
(``<CPFA ... />`` of ``experiments/Clustered_CPFA_r64_tag512_16by16.xml`` in
Tameem786/Collision_Free_CPFA and ``experiments/Clustered_CPFA_r40_tag256_16by16_TEST.xml`` in
Artglz/Collision_Free_CPFA, identical): ProbabilityOfSwitchingToSearching, ...ReturningToNest,
RateOfInformedSearchDecay, RateOfSiteFidelity, RateOfLayingPheromone, RateOfPheromoneDecay as
written, and UninformedSearchVariation = 3.67372660634, which ``CPFA_loop_functions::Init``
reads as degrees (``argos::CDegrees``, then ``ToRadians``): 0.0641 rad."""


@dataclass(frozen=True)
class CpfaConfig(Section):
    """Central-place foraging algorithm parameters (Hecker & Moses 2015, Table 1/3).

    Defaults are the values BCLab's CPFA implementation labels "according to Beyond
    Pheromones"; p_s and p_r are per draw of the reference controller (see `draw_rate`) and are
    rescaled to our tick by the behaviour.
    """

    parameter_set: Literal["custom", "beyond_pheromones", "queue_paper"] = "custom"
    """`custom`: the seven values below as given; a name: the values of that set
    (`CPFA_PARAMETER_SETS`), and giving one of the seven too is refused."""

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
    informed_search_time: Literal["seconds", "steps"] = "seconds"
    """The t of the informed walk's decay exp(-lambda_id t): seconds since the informed search
    began (CPFA-ROS), or walk steps taken since (the ARGoS CPFA: ``SearchTime++`` per step,
    ``CPFA_controller::Searching``; the queue paper's authors' code)."""

    informed_walk: Literal["sigma", "turn"] = "sigma"
    """How an informed search turns at each step: ``sigma``, by a draw of N(0, sigma) with sigma =
    omega + (4 pi - omega) exp(-lambda_id t) (H&M's informed-walk equation: a wide random walk
    relaxing to the uninformed one); ``turn``, as the ARGoS CPFA does (``CPFA_controller::Searching``
    and ``GetExponentialDecay``, Tameem786/Collision_Free_CPFA): by w + (2 pi - w) exp(-lambda_id t)
    wrapped to [-pi, pi], w a draw of N(0, omega), so the turn is nearly fixed, none at the first
    step, then about -1.8, pi, 2.2, 1.6 ... rad: a loop about the site that opens as t grows."""
    density_counts_find: bool = False
    """Whether the local resource density c at a find counts the resource just picked up (c = 1 +
    the others in reach), as the ARGoS CPFA does (``CPFA_controller::SetLocalResourceDensity``:
    ``ResourceDensity = 1``, then one per food within ``sqrt(2 x SearchRadiusSquared)`` = sqrt(2) x 4
    x ``FoodRadius`` of the robot: 0.283 m in the queue authors' experiment, where the reach is
    ``sensors.resource_detection_radius``), or the others only (H&M's c: the resources seen near
    the find). It sets the chances of laying pheromone and of site fidelity, POIS(c, lambda)."""

    SECTION: ClassVar[str] = "cpfa"

    def __post_init__(self) -> None:
        if self.parameter_set == "custom":
            return
        defaults = CPFA_PARAMETER_SETS["beyond_pheromones"]
        for key, value in CPFA_PARAMETER_SETS[self.parameter_set].items():
            given = getattr(self, key)
            if given != defaults[key] and given != value:
                raise ScenarioError(
                    f"controller.cpfa.{key}: given together with parameter_set "
                    f"{self.parameter_set!r} (set parameter_set: custom to give the values)"
                )
            object.__setattr__(self, key, value)

"""The DRTM paper's scenario sections (``controller.nest``, ``controller.threshold``,
``controller.example``).

Pang et al. 2023 (drtm_task_allocation.md): `NestConfig` is the nest's energy model of Sec. 3.1
(the ledger the nest server keeps, eqs. (8)-(9)); `ThresholdConfig` the response-threshold
foragers of Secs. 2.1-2.2 and 3.1, DRTM (eqs. (2)-(7)) and ARTM (Castello et al.) alike. Both
algorithms declare both sections, so a DRTM and an ARTM run of one scenario file differ only in
``controller.behaviour``. `ExampleRuleConfig` is the rule of the ARGoS foraging example, the
DRTM reference run's (``foraging_example``, `swarm_controllers.drtm.foraging_example`).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, ClassVar, Literal

from swarm_sim.scenario import Section

if TYPE_CHECKING:
    from swarm_sim.scenario import Scenario


@dataclass(frozen=True)
class NestConfig(Section):
    """The nest's energy ledger (Sec. 3.1). Energy is counted in the paper's units; F(t) is the
    ledger's energy over `token_energy` [tokens]."""

    token_energy: float = 1500.0
    """Energy units in one food token ("each food token contained 1500 energy units")."""
    step_energy: float = 1.0
    """Units a robot in S_S or S_R consumes per control tick ("one energy unit per step")."""
    avoidance_energy: float = 10.0
    """E_a: units one obstacle-avoidance event (OAE) consumes."""
    consumption_rate: float = 2.0
    """C_rate: tokens the nest consumes per minute of sim time."""
    initial_food: float = 5.0
    """F(0): net food in the nest at the start [tokens]."""
    desired_food: float = 20.0
    """F_d: the food the swarm keeps in the nest (eq. (2)) [tokens]."""
    oae_window: float | None = None
    """T_2 of eq. (5) [s]: OAEs this recent count as M_T2. None: L / (2 v) as in the paper
    (arena side over twice ``robots.max_linear_speed``)."""
    oae_window_states: Literal["all", "returning"] = "all"
    """Whose OAEs M_T2 counts: ``all`` (every forager's, S_S and S_R) or ``returning`` (only
    those of robots in S_R). Sec. 2.2 defines M_T2 as "the total number of OAEs over time T_2",
    then motivates T_2 with "the number of OAEs due to robots within state S_R can well reflect
    the traffic conditions"; the text supports both readings and the ledger charges every OAE
    either way. ``all`` is what our 20-seed runs used; ``returning`` is a factor of
    ``scripts/factors`` (drtm31, drtm43)."""

    SECTION: ClassVar[str] = "nest"

    def window(self, scenario: Scenario) -> float:
        """T_2 [s]."""
        if self.oae_window is not None:
            return self.oae_window
        return scenario.arena.size / (2.0 * scenario.robots.max_linear_speed)


@dataclass(frozen=True)
class ThresholdConfig(Section):
    """The response-threshold foragers (Secs. 2.1-2.2, 3.1); DRTM and ARTM share T_1 and n."""

    min_wait_steps: int = 50
    """T_1: ticks a robot waits in the nest before it first draws P_s (eq. (7))."""
    draw_period: int | None = None
    """Once t_1 >= T_1, a waiting robot that stays draws again after this many ticks. None: T_1,
    i.e. its timer restarts (Sec. 2: "initializes a timer t_1 = 0 ... when the waiting time
    expires ... uses the DRTM to calculate its foraging probability"); 1: every tick, as the ARGoS
    foraging example (whose minimum resting time is T_1) does, which turns any P_s above a few
    percent into leaving at once and leaves eq. (6) no time to act on k."""

    def period(self) -> int:
        """Ticks between draws."""
        return self.min_wait_steps if self.draw_period is None else self.draw_period
    exponent_min: int = 2
    """n of eq. (7) is an integer drawn uniformly in [exponent_min, exponent_max] per robot."""
    exponent_max: int = 9
    alpha: float = 3.0
    """DRTM: weight of the traffic flow density k (eq. (6)) [m^2]."""
    beta: float = 2.0
    """DRTM: weight of the mean OAEs M_A (eq. (6))."""
    drtm_bounded: bool = False
    """DRTM: clip eq. (6) to [threshold_min, threshold_max]. Off: Sec. 3.2 says theta = 0 when k
    and M_A are 0, which the bounds forbid; on: the reading of Sec. 3.1, which starts DRTM at
    theta_t0 "following the ARTM"."""
    initial_threshold: float = 3.3
    """ARTM: theta_t0."""
    threshold_min: float = 1.0
    """ARTM: theta stays in [threshold_min, threshold_max]."""
    threshold_max: float = 10.0
    artm_gain: float = 1.0
    """ARTM: theta moves by -artm_gain per token the stimulus moves (our reading of Castello et
    al.'s rule, see `swarm_controllers.drtm.response_threshold.ArtmThreshold`)."""
    walk_turn_std: float = 1.0
    """ASM noise epsilon of eq. (1): a random-walking robot drives at full speed and turns at a
    rate drawn each tick from N(0, walk_turn_std^2) [rad/s]."""
    settle_steps: int = 50
    """After a deposit, a waiting robot keeps approaching the light for at most this many ticks
    (stopping at once when something is ahead) to free the nest's edge, as the ARGoS foraging
    example's robots search for a place in the nest for 50 ticks."""

    SECTION: ClassVar[str] = "threshold"


@dataclass(frozen=True)
class ExampleRuleConfig(Section):
    """The ARGoS foraging example's ``<state>`` parameters (ilpincy/argos3-examples,
    ``CFootBotForaging::SStateData::Init`` in ``controllers/footbot_foraging/footbot_foraging.cpp``;
    values of ``experiments/foraging.argos``), named as in its XML; times in control ticks."""

    initial_rest_to_explore_prob: float = 0.1
    """RestToExploreProb at the start: a resting robot leaves with it once it has rested enough."""
    initial_explore_to_rest_prob: float = 0.1
    """ExploreToRestProb at the start: an explorer that found nothing for long gives up with it."""
    food_rule_explore_to_rest_delta_prob: float = 0.01
    """ExploreToRestProb falls by it on a find and rises by it on each draw that keeps exploring."""
    food_rule_rest_to_explore_delta_prob: float = 0.01
    """RestToExploreProb rises by it on a find and falls by it on each draw that keeps exploring."""
    collision_rule_explore_to_rest_delta_prob: float = 0.01
    """Each exploring tick with a collision raises ExploreToRestProb and lowers RestToExploreProb by it."""
    social_rule_rest_to_explore_delta_prob: float = 0.01
    """A resting robot told of another's successful exploration raises RestToExploreProb by it
    (and lowers it by it for an unsuccessful one)."""
    social_rule_explore_to_rest_delta_prob: float = 0.01
    """... and lowers ExploreToRestProb by it (raises it by it for an unsuccessful one)."""
    minimum_resting_time: int = 50
    """A resting robot draws only once it has rested more than this many ticks."""
    minimum_unsuccessful_explore_time: int = 600
    """An explorer draws to give up only after more than this many ticks without a find."""
    minimum_search_for_place_in_nest_time: int = 50
    """A returning robot rests after more than this many consecutive ticks in the nest."""

    SECTION: ClassVar[str] = "example"

    PROBABILITIES: ClassVar[tuple[str, ...]] = (
        "initial_rest_to_explore_prob", "initial_explore_to_rest_prob", "food_rule_explore_to_rest_delta_prob",
        "food_rule_rest_to_explore_delta_prob", "collision_rule_explore_to_rest_delta_prob",
        "social_rule_rest_to_explore_delta_prob", "social_rule_explore_to_rest_delta_prob")
    TIMES: ClassVar[tuple[str, ...]] = (
        "minimum_resting_time", "minimum_unsuccessful_explore_time", "minimum_search_for_place_in_nest_time")


def check_example(scenario: Scenario) -> None:
    """Refuse settings the example's rule cannot use (ValueError naming the key)."""
    example = ExampleRuleConfig.of(scenario)
    for key in ExampleRuleConfig.PROBABILITIES:
        if not 0.0 <= getattr(example, key) <= 1.0:
            raise ValueError(f"controller.example.{key}: must be a probability in [0, 1]")
    for key in ExampleRuleConfig.TIMES:
        if getattr(example, key) < 0:
            raise ValueError(f"controller.example.{key}: must not be negative [ticks]")


def check_nest(scenario: Scenario) -> None:
    """Refuse settings the nest and the foragers cannot use (ValueError naming the key)."""
    nest, th = NestConfig.of(scenario), ThresholdConfig.of(scenario)
    if not nest.token_energy > 0:
        raise ValueError("controller.nest.token_energy: must be positive")
    for key in ("step_energy", "avoidance_energy", "consumption_rate"):
        if not getattr(nest, key) >= 0:
            raise ValueError(f"controller.nest.{key}: must not be negative")
    if nest.oae_window is not None and not nest.oae_window > 0:
        raise ValueError("controller.nest.oae_window: must be positive (or null for L / 2v)")
    if th.min_wait_steps < 0:
        raise ValueError("controller.threshold.min_wait_steps: must not be negative")
    if th.period() < 1:
        raise ValueError("controller.threshold.draw_period: must be at least 1 (or null with min_wait_steps >= 1)")
    if not 1 <= th.exponent_min <= th.exponent_max:
        raise ValueError("controller.threshold.exponent_min: need 1 <= exponent_min <= exponent_max")
    if not 0 <= th.threshold_min <= th.initial_threshold <= th.threshold_max:
        raise ValueError("controller.threshold.initial_threshold: need 0 <= threshold_min <= "
                         "initial_threshold <= threshold_max")
    if not (th.walk_turn_std >= 0 and th.settle_steps >= 0):
        raise ValueError("controller.threshold.walk_turn_std: walk_turn_std and settle_steps must not be negative")
    if not scenario.resources.respawn:
        raise ValueError("resources.respawn: the nest task keeps N_f food tokens in the arena; set it true")

"""The spiral search's scenario section (``controller.spiral``), declared in the DDSA and MDBSA
registry records (`swarm_controllers.spiral.registration`), and its check."""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, ClassVar, Literal

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
    partner_radio: bool = True
    """MDBSA: the walkers of a region tell each other their progress (`protocol.WalkProgress`) and
    each stops where the other has been (the paper's Sec. IV: "A robot can communicate with
    another robot in the same region"; Fig. 5: they "meet at some point in their spiral path and
    complete the search"). False: a walk ends at the stop the center last sent (the partner's
    frontier as the center knew it), so the two overlap (this project's reading until 2026-11-27)."""
    waypoint_gaps: int = 1
    """On a straight leg of the spiral the robot aims this many gaps g ahead of its progress (never
    past the leg's end): with the foot-bot's stop-turn-go motion, a stop every ``waypoint_gaps * g``.
    The DDSA authors set a waypoint every gap (``SetTargetN..W``, MARSLab-UTRGV/DDSA-Distributed-
    Deterministic-Spiral-Search-Algorithm, luki-dev, ``source/DSA/DSA_controller.cpp``); their
    MDBSA every 3 gaps, and the remainder at a leg's end (``generateSpiralPath``, "create a point
    in every 3 searchGap", MARSLab-UTRGV/Adaptive-Multiple-Distributed-Spiral-Search-Algorithm,
    luki-dev, ``Centralized/source/DSA/DSA_loop_functions.cpp``). The paper says nothing of it."""
    next_walk_at: Literal["center_range", "depot"] = "center_range"
    """MDBSA: the way from a finished walk to the next. ``center_range``: straight from where the
    robot asked (`mdbsa.ASK_MARGIN` inside ``center_range``; it never enters the depot). ``depot``:
    by way of the depot centre + `mdbsa.DEPOT_POINT`, to within `mdbsa.DEPOT_POINT_HIT` of it, as the MDBSA
    authors' robot goes (once its point list is empty: ``DSA = START; SetTarget(CVector2(0.1,
    0.1))``; START takes the next walk at once, and its first point becomes the target only when
    ``TargetHit``, squared distance below ``TargetDistanceTolerance`` = 0.01:
    ``DSA_controller::ReachSpiralTargets`` and ``ControlStep``, luki-dev, both controllers), so
    every walk after the first starts across the depot (their nest). A robot with no walk left goes idle
    without it (their START sets IDLE and the region centre as its target at once). Our robots
    still ask within the center's range (the authors' robots read the assignment from shared
    memory anywhere)."""

    lane_yield: bool = True
    """A searcher on its lane yields (stops) to what is in its own lane ahead and swerves only
    after `ddsa.LANE_YIELD_TIMEOUT` (`ddsa.LaneAvoidance`: this project's rule since issue 4, for
    adjacent lanes one gap apart). False: every state avoids by the robot model's avoidance alone,
    as the authors' controllers do (``BaseController::CollisionDetection`` in ``Move``, no
    yielding: MARSLab-UTRGV DDSA and MDBSA, luki-dev, ``source/Base/BaseController.cpp``)."""

    lane_unjam: bool = True
    """With the lane rule: a lane still blocked after the yield timeout starts the robot model's
    avoidance turn at the blocking hit's bearing even when the model's own detection misses it (the
    foot-bot's cone on the summed readings misses a robot ahead when another is behind). False: the
    robot yields again, and a chain of robots each yielding to the next can stand for good (issue
    37: 3 of 20 DDSA runs at 32 robots before this became the default; CAUSES.md)."""

    ddsa_stem: Literal["own", "shared"] = "shared"
    """DDSA: where robot i's spiral starts. ``shared`` (the default, the authors' code): eqs. (1)-(2)
    read literally, as the DDSA authors' code walks them: every robot first drives to the depot
    centre, reached anywhere in the depot disc (their first target is the nest position, and
    ``TargetHit`` takes ``GetTarget() == NestPosition && IsInTheNest()``), then walks its first leg
    of i gaps out from it along one line, over robots 1..i-1's first legs (``generatePattern`` /
    ``calcDistanceToTravel``: F^N = i on circuit 1, each step relative to the last target;
    MARSLab-UTRGV/DDSA-Distributed-Deterministic-Spiral-Search-Algorithm, luki-dev,
    ``source/DSA/DSA_controller.cpp`` ``ReachSpiralTargets``, ``source/DSA/DSA_loop_functions.cpp``).
    The text agrees as far as it goes (Sec. III: spirals "starting from the central collection
    zone"). ``own``: ours before 2026-11-29, at the depot centre + (0, (i-1) g), where robot i-1's
    first leg ends, so no leg is walked twice and nobody passes through the nest to start
    (`geometry.ddsa_path`'s default stem; Sec. III: "each robot moves to its designated path")."""

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
    if not sp.waypoint_gaps >= 1:
        raise ValueError("controller.spiral.waypoint_gaps: must be at least 1")

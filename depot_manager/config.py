"""The queue paper's scenario sections: the queue strategies' (``controller.queue``), read by the
depot manager and by the robots' queue behaviour alike (queue_depot_traffic.md secs. IV, V, VII;
its check, that the layout fits the depot, is `depot_manager.geometry.check_queue`), and the
perimeter and docks around the depot (``docking``, a world section)."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import ClassVar, Literal

from swarm_sim.scenario.schema import Section, WorldSection


@dataclass(frozen=True)
class QueueConfig(Section):
    wrapping: Literal["single", "multi"] = "multi"
    """Queue wrapping inside the perimeter (sec. IV): single-queue or multi-queue wrapping."""
    joining: Literal["entry", "tail"] = "entry"
    """Endpoint finding (sec. V): entry-point joining or tail joining."""
    lane_spacing: float = 0.20
    """Distance between adjacent queue lanes [m] (sec. VII)."""
    slot_pitch: float | None = None
    """Distance between a line's cells along it [m]; None: `lane_spacing`. The paper gives none and
    the queue authors' code has no cells: their robots on the path stop for what their proximity
    ring reads ahead, so a standing line's robots stand about a ring's reach apart (the foot-bot:
    0.085 + 0.1 + 0.085 = 0.27 m centre to centre)."""
    inner_rule: Literal["own", "any"] = "own"
    """Single-queue inner-queue rules (sec. IV-A: dispatch only if no robot is between the
    inner entry point and the dock; leave the dock only if none is between it and the exit
    point): `own` counts the robots dispatched into that inner queue (robots of other inner
    queues are met at intersections, FCFS, as sec. IV-D says); `any` counts every robot on its
    cells, which on our shared ring nearly serialises the docks."""

    join_order: Literal["behind_tail", "anywhere"] = "behind_tail"
    """Where the depot manager lets a robot join an entry line: ``behind_tail``, only behind every
    robot on it (sec. V-B: "if v2 is the last robot in the queue, v1 will simply join the queue
    behind it"; sec. V-A's entry point is the line's first cell); or ``anywhere`` free, as the
    queue authors' tail joining does in their code: a carrier drives straight in and boards the
    spiral at its fifth lane, or at the innermost lane it crossed once blocked, ahead of the
    robots on the outer lanes, with no notion of a tail (Tameem786/Collision_Free_CPFA, branch
    CPFA-2.0, their Q_ST: ``CPFA_controller::Returning``, source/CPFA/CPFA_controller.cpp). Only
    the paper's text is the default; ``anywhere`` is what the authors ran."""

    boarding: Literal["radio", "innermost"] = "radio"
    """Tail joining: where a carrier asks to board. ``radio``, the paper's (sec. V-B): it asks the
    queued robots it meets on its way in and joins by their replies; ``innermost``, the queue
    authors' Q_ST code: no radio, it drives straight in and boards the innermost arc at the cell
    nearest to it (their ``CPFA_controller::Returning``, branch CPFA-2.0: a carrier heads for
    0.5 R + 0.1 m from the centre and boards the fifth arc, r = 1.0 m, at the first of its
    waypoints it comes within 0.15 m of; our innermost arc is at 0.99 m). A refused join is asked
    again from where it stands."""

    queued_motion: Literal["model", "continuous"] = "model"
    """How a robot drives on the queue's lines (joining its cell, queued, leaving): ``model``, by
    its robot model's motion (the foot-bot's stop-turn-go and path stop); ``continuous``, by the
    generic robot's continuous steering and brake, whatever the model. A diagnostic, neither the
    paper's nor the authors' (their foot-bots run stop-turn-go on the path too): it tells how much
    of the motion rule's cost falls on the queue rather than on foraging."""

    line_stop: Literal["model", "brake", "ring"] = "model"
    """What halts a robot on the queue's lines (queued or leaving) for what is ahead of it:
    ``model``, its robot model's path rule where it has one (the foot-bot's: the queue authors'
    ``CPFA_controller::CollisionDetection``, a ``Stop()`` for any proximity reading within +-30 deg of
    the heading, `swarm_controllers.queue.behaviour.PATH_CONE`), else our brake (the scan within
    `BRAKE_RANGE` of the front, `BRAKE_CONE`); ``brake``, our brake on every model; ``ring``, the
    authors' rule on every model, read from its scan as a proximity ring. A diagnostic beside
    `queued_motion`: together they split the cost of the motion on the lines into the steering and
    the stop rule."""

    cell_release: Literal["arrival", "departure"] = "arrival"
    """When a robot's cell on an entry line may be granted to the robot behind it: on its
    ``arrival`` at its next cell (the depot manager's cells are never shared), or on its
    ``departure``, as soon as it holds a grant beyond that cell and so moves off; the follower then
    closes up until its own stop rule halts it behind the leaver (the foot-bot's path stop, the
    generic robot's brake). ``departure`` is how the queue authors' robots follow one another:
    their code has no cells, a robot on the path drives from waypoint to waypoint and stops only
    for what its proximity ring reads within +-30 deg of its heading (Tameem786/
    Collision_Free_CPFA, branch CPFA-2.0, ``CPFA_controller::FollowingEntryPath`` and
    ``CollisionDetection``). With cells released on arrival a dense line moves as a caterpillar,
    each robot waiting for the one ahead to finish its move."""

    return_leg: Literal["centre", "rim"] = "centre"
    """Where a carrier's return leg from foraging aims, on a robot whose legs run blind (the
    foot-bot's stop-turn-go: a FORWARD runs its whole distance whatever the queue asks meanwhile):
    ``centre``, the depot centre (the CPFA's nest), so a leg under way when the carrier enters the
    perimeter, starts seeking or joins a line drives on across the lanes toward the depot until
    something stops it; ``rim``, `swarm_controllers.cpfa.behaviour.RIM_MARGIN` outside the
    perimeter, as the queue authors' carriers do: ``CPFA_controller::Returning`` (Tameem786/
    Collision_Free_CPFA, branch CPFA-2.0) aims a carrier outside the red circle at ``safeDistance =
    redCircleRadius + 0.1`` on its side, and inside it at ``redCircleRadius * 0.5 + 0.1``, where it
    boards (our seeker's own leg, to one lane outside the inner region). No effect on a robot that
    re-aims every tick."""

    entry_reach: float = 0.05
    """[m] a queued robot counts a cell of an entry line (not a dock) as reached within this
    distance, reports it and drives on to the next (docks and the other lines: 0.05 m,
    `swarm_controllers.queue.behaviour.SLOT_TOLERANCE`). The queue authors' robots take a waypoint
    of their path as reached within 0.1 m (``CPFA_controller::FollowingEntryPath``: "Waypoint
    reached threshold", Tameem786/Collision_Free_CPFA, branch CPFA-2.0). On the foot-bot a robot
    halted by its path stop behind the one ahead stands ~0.1 m short of its cell (the ring's reach,
    0.27 m centre to centre, against 0.2 m cells): within 0.05 m it has not reached it, so the cell
    behind it is not released to its follower until the robot ahead moves on."""

    brake_patience: float = 3.0
    """[s] a robot on the queue's lines (queued or leaving) that has been braked this long swerves
    round what blocks it, by its model's avoidance, for a second. Our addition, a deadlock breaker
    (two robots braking face to face, one pushed off its line, would wait for each other for
    good). The queue authors' robots on their path never swerve: ``CPFA_controller::
    CollisionDetection`` only calls ``Stop()`` in FOLLOWING_ENTRY_PATH and EXITING (Tameem786/
    Collision_Free_CPFA, branches main and CPFA-2.0); one beyond the run's duration is that rule."""

    seek_timeout: float = 120.0
    """Tail joining: a searcher that has not joined after this long [s, sim time] falls back to
    entry-point joining. Our addition, against livelock: the paper's searcher only switches to its
    fallback (the nearest line, followed to its endpoint) on reaching the inner region's boundary
    without meeting anyone, and the authors' Q_ST code has no give-up either. One beyond the run's duration: never."""

    SECTION: ClassVar[str] = "queue"



@dataclass(frozen=True)
class DockingConfig(WorldSection):
    """The depot's surroundings in the queue paper (sec. III, Fig. 2): the perimeter (red circle)
    around the depot and the K docks on its boundary; the scenario's ``docking`` section, declared
    by the ``docks`` delivery kind (`swarm_controllers.queue.registration`). Its checks against the
    depot and the arena are `depot_manager.docks.check_docks`.

    Bags recorded before this section existed carry its fields under ``depot``; `MOVED` names
    them, and the loader of a recorded scenario carries them here
    (`swarm_sim.scenario.scenario_from_dict`)."""

    perimeter_radius: float = 2.0
    """Radius of the perimeter (red circle) [m] around the depot; the paper's drop-off time runs
    from a carrier's entry into it."""
    docks: int = 4
    """Number K of docks on the depot boundary."""
    unload_time: float = 5.0
    """T_unload: a robot stays at its dock this long before its resource is dropped [s]. The
    paper gives no value; 5 s is our choice."""
    dock_radius: float = 0.06
    """A robot unloads while its centre is within this distance of the dock stop [m]."""
    dock_distance: float | None = None
    """Distance of the dock stops from the depot centre [m]; None: one robot radius outside
    the depot disc (where the queue layouts end)."""

    SECTION: ClassVar[str] = "docking"
    MOVED: ClassVar[Mapping[str, str]] = {
        f"depot.{name}": name for name in ("perimeter_radius", "docks", "unload_time", "dock_radius", "dock_distance")
    }

    def check(self) -> None:
        if self.unload_time < 0:
            raise ValueError("docking.unload_time: must not be negative")
        if self.dock_radius <= 0:
            raise ValueError("docking.dock_radius: must be positive")
        if self.docks < 1:
            raise ValueError("docking.docks: need at least one dock")
        if self.dock_distance is not None and self.dock_distance <= 0:
            raise ValueError("docking.dock_distance: must be positive")

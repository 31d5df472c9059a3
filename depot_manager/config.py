"""The queue strategies' scenario section (``controller.queue``), read by the depot manager and
by the robots' queue behaviour alike (queue_depot_traffic.md secs. IV, V, VII); its check, that
the layout fits the depot, is `depot_manager.geometry.check_queue`."""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar, Literal

from swarm_sim.scenario.schema import Section


@dataclass(frozen=True)
class QueueConfig(Section):
    wrapping: Literal["single", "multi"] = "multi"
    """Queue wrapping inside the perimeter (sec. IV): single-queue or multi-queue wrapping."""
    joining: Literal["entry", "tail"] = "entry"
    """Endpoint finding (sec. V): entry-point joining or tail joining."""
    lane_spacing: float = 0.20
    """Distance between adjacent queue lanes [m] (sec. VII)."""
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

    seek_timeout: float = 120.0
    """Tail joining: a searcher that has not joined after this long [s, sim time] falls back to
    entry-point joining. Our addition, against livelock: the paper's searcher only switches to its
    fallback (the nearest line, followed to its endpoint) on reaching the inner region's boundary
    without meeting anyone, and the authors' Q_ST code has no give-up either. One beyond the run's duration: never."""

    SECTION: ClassVar[str] = "queue"


"""The depot manager's core: `DepotReport`s in, `DepotGrant`s out (queue_depot_traffic.md
secs. IV-V; implements `swarm_sim.protocol.Server`).

ROS-free. Each tick the server applies the reports in the order given, then lets
`DepotAdmission` extend grants, and answers with one `DepotGrant` per robot whose grant or
``last`` flag changed (sorted by robot id), plus one refusal (cell -1, with the reason) per
refused join. Reports that cannot be applied (unknown robot, a cell not on the robot's route,
an unknown kind, ...) are ignored and counted in `rejections`: one robot's bad report must not
stop the depot. A robot the world declared dead (`robot_lost`) leaves the depot: its dock, inner
queue and slots are freed and its later reports refused.

Its `state` is what ``/depot/state`` carries (the queues, docks and owned slots; the run trace's
``queue_lengths`` series is read from it, `depot_manager.codec.OUTPUTS`), and `draw` what
``/depot/markers`` shows.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from depot_manager.admission import DepotAdmission
from depot_manager.config import QueueConfig
from depot_manager.geometry import DepotGeometryConfig, QueueLayout, make_layout
from depot_manager.protocol import DepotGrant, DepotReport, Refusal, ReportKind
from depot_manager.state import DepotView
from swarm_msgs_py.types import NS_PER_S
from swarm_sim.inbound import Reason, Rejections
from swarm_sim.protocol import Drawing, Lines, Points

MARKER_PERIOD = 1.0
"""Sim seconds between slot-occupancy marker updates."""

_ENTRY = (0.1, 0.1, 0.1, 0.9)
_EXIT = (0.1, 0.3, 0.9, 0.9)
_INNER = (0.6, 0.2, 0.8, 0.9)
DOCK_COLOUR = (0.1, 0.7, 0.2, 1.0)
"""RGBA of the docks in the depot's markers."""
_FREE = (0.7, 0.7, 0.7, 0.5)
_OWNED = (0.9, 0.1, 0.1, 0.9)


class DepotServer:
    """Depot manager core, stepped once per tick (see `swarm_sim.protocol`)."""

    def __init__(self, scenario, *, lookahead: int = 8) -> None:
        self.queue = queue = QueueConfig.of(scenario)
        self.layout: QueueLayout = make_layout(queue.wrapping, DepotGeometryConfig.from_scenario(scenario))
        self.admission = DepotAdmission(self.layout, lookahead=lookahead, inner_rule=queue.inner_rule,
                                       join_order=queue.join_order, cell_release=queue.cell_release)
        self.robots = frozenset(scenario.robot_names)
        self.rejections = Rejections()
        """Reports that could not be applied, by reason (the last one's detail kept)."""
        self.lost: set[str] = set()
        """Robots declared dead."""
        self._last: dict[str, bool] = {}
        self._state: tuple[int, dict[str, DepotView]] | None = None

    def state(self) -> dict[str, DepotView]:
        """``depot``: the queues, docks, inner queues and owned slots now. Asked every tick (the
        ``queue_lengths`` series reads it) but changed on few: kept while the admission's
        `version` stands."""
        adm = self.admission
        if self._state is None or self._state[0] != adm.version:
            s = adm.snapshot()
            self._state = (adm.version, {"depot": DepotView(tuple(zip(s.entry_lines, s.entry_queue_lengths)),
                                                            s.dock_occupants, s.inner_queue_counts, s.occupied)})
        return self._state[1]

    def robot_lost(self, robot: str, stamp_ns: int) -> None:
        """`robot` was declared dead: free everything it holds, refuse what it sends later."""
        self.lost.add(robot)
        self.admission.remove(robot)
        self._last.pop(robot, None)

    def step(self, stamp_ns: int, messages: Sequence[object]) -> tuple[DepotGrant, ...]:
        t = stamp_ns / NS_PER_S
        adm = self.admission
        out: list[DepotGrant] = []
        for m in messages:
            if not isinstance(m, DepotReport):
                continue
            if m.robot not in self.robots:  # a report from the bus names a robot of no run
                self.rejections.add("DepotReport", Reason.UNKNOWN_ROBOT, f"t={t:.3f} {m.robot[:40]!r}")
                continue
            if m.robot in self.lost:
                self.rejections.add("DepotReport", Reason.DEAD, f"t={t:.3f} {m.robot}")
                continue
            try:
                match m.kind:
                    case ReportKind.JOIN:
                        reason = adm.join(m.robot, m.line, m.cell, t)
                        if reason is not Refusal.NONE:
                            out.append(DepotGrant(stamp_ns, m.robot, m.line, -1, False, reason))
                    case ReportKind.AT:
                        adm.arrived(m.robot, m.line, m.cell, t)
                    case ReportKind.UNLOADED:
                        adm.unloaded(m.robot, t)
                    case _:
                        raise ValueError(f"unknown report kind {m.kind!r}")
            except (ValueError, TypeError) as e:
                kind = getattr(m.kind, "value", m.kind)
                self.rejections.add("DepotReport", Reason.REFUSED, f"t={t:.3f} {m.robot} {kind} {m.line}/{m.cell}: {e}")
        changed = adm.step(t)
        inside = adm.robots_inside
        lasts = adm.last_robots()
        last = {r: r in lasts for r in inside}
        for r in inside:
            if r in changed or last[r] != self._last.get(r):
                line, cell = changed.get(r) or adm.grant(r)
                out.append(DepotGrant(stamp_ns, r, line, cell, last[r]))
        self._last = last
        out.sort(key=lambda g: g.robot)  # stable: a refusal stays before its robot's grant
        return tuple(out)


def draw(server: DepotServer, stamp_ns: int) -> Drawing:
    """Every line, dock, entry and exit point of the layout, and which slots are owned."""
    layout, adm = server.layout, server.admission
    owned = {(line, cell) for line, cell, _ in adm.snapshot().occupied}
    cells = [(line, i, p) for line in adm.lines() for i, p in enumerate(adm.cells(line))]
    free = np.array([p for line, i, p in cells if (line, i) not in owned]).reshape(-1, 2)
    taken = np.array([p for line, i, p in cells if (line, i) in owned]).reshape(-1, 2)
    return (
        Lines("entry_lines", [ln.points for ln in layout.entry_lines], _ENTRY, 0.01),
        Lines("exit_lines", [ln.points for ln in layout.exit_lines], _EXIT, 0.01),
        Lines("inner_queues", [ln.points for ln in layout.inner_queues], _INNER, 0.01),
        Points("docks", 0, np.array([d.stop for d in layout.docks]), DOCK_COLOUR, server.queue.lane_spacing, cubes=True),
        Points("entry_points", 0, layout.entry_points, _ENTRY, 0.08),
        Points("exit_points", 0, layout.exit_points, _EXIT, 0.08),
        Points("slots_free", 0, free, _FREE, 0.04),
        Points("slots_owned", 0, taken, _OWNED, 0.06),
    )

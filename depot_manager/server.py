"""The depot manager's core: `DepotReport`s in, `DepotGrant`s out (queue_depot_traffic.md
secs. IV-V; implements `swarm_sim.protocol.Server`).

ROS-free. Each tick the server applies the reports in the order given, then lets
`DepotAdmission` extend grants, and answers with one `DepotGrant` per robot whose grant or
``last`` flag changed (sorted by robot id), plus one refusal (cell -1, with the reason) per
refused join. Reports that cannot be applied (unknown robot, a cell not on the robot's route,
an unknown kind, ...) are ignored and counted in `rejections`: one robot's bad report must not
stop the depot. A robot the world declared dead (`robot_lost`) leaves the depot: its dock, inner
queue and slots are freed and its later reports refused. `history` keeps the entry-line queue lengths over time for the metrics.
"""

from __future__ import annotations

from collections.abc import Sequence

from depot_manager.admission import DepotAdmission
from depot_manager.config import QueueConfig
from depot_manager.geometry import DepotGeometryConfig, QueueLayout, make_layout
from depot_manager.protocol import DepotGrant, DepotReport, Refusal, ReportKind
from swarm_sim.inbound import Reason, Rejections
from swarm_sim.types import NS_PER_S


class DepotServer:
    """Depot manager core, stepped once per tick (see `swarm_sim.protocol`)."""

    def __init__(self, scenario, *, lookahead: int = 8) -> None:
        queue = QueueConfig.of(scenario)
        self.layout: QueueLayout = make_layout(queue.wrapping, DepotGeometryConfig.from_scenario(scenario))
        self.admission = DepotAdmission(self.layout, lookahead=lookahead, inner_rule=queue.inner_rule)
        self.robots = frozenset(scenario.robot_names)
        self.rejections = Rejections()
        """Reports that could not be applied, by reason (the last one's detail kept)."""
        self.lost: set[str] = set()
        """Robots declared dead."""
        self.history: list[tuple[float, tuple[int, ...]]] = []
        """(t [s], robots per entry line), appended whenever the queue lengths change."""
        self._last: dict[str, bool] = {}

    def series(self) -> dict[str, list[tuple[float, tuple[int, ...]]]]:
        """The run trace's ``queue_lengths``: (t [s], robots queued per entry line) on change."""
        return {"queue_lengths": list(self.history)}

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
        lengths = adm.entry_queue_lengths()
        if not self.history or self.history[-1][1] != lengths:
            self.history.append((t, lengths))
        out.sort(key=lambda g: g.robot)  # stable: a refusal stays before its robot's grant
        return tuple(out)

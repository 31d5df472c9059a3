"""Delivery queue strategies Q_SE, Q_ST, Q_ME, Q_MT (queue_depot_traffic.md, secs. III-VI).

A robot forages with the CPFA (`swarm_controllers.cpfa.behaviour`) and, once it carries a resource to the
depot's perimeter, queues under the depot manager's grants (`depot_manager.server`): the
manager owns every queue slot, the robot only drives to the slots it was granted and reports
each one it reaches. The scenario chooses the wrapping (``controller.queue.wrapping``: single or multi) and
the endpoint finding (``controller.queue.joining``: entry or tail), so Q_SE = single + entry, Q_ST =
single + tail, Q_ME = multi + entry, Q_MT = multi + tail.

Phases of a delivery, and the choices the paper leaves open:

* **Foraging** (CPFA). Only carriers may enter the perimeter (sec. III): the CPFA keeps its
  sites and walk legs out of the perimeter disc (plus `KEEP_OUT_BAND`), a give-up return ends
  at its edge, and a non-carrier inside the band is steered out radially, or round the disc
  the short way when its travel would cut through it, on a two-lane ring road (counter-
  clockwise on the inner lane, clockwise on the outer) so that robots rounding the perimeter
  in opposite directions do not meet head on. The CPFA is not stepped while the
  robot queues; when the robot has left the perimeter it is stepped again, sees the drop and
  lays pheromone / chooses its next site then (its view of the delivery time is the exit).
* **Entry-point joining** (sec. V-A). The perimeter is cut into arcs whose preferred tangent
  direction leads to the nearest entry point along the circle (the arcs meet halfway between
  neighbouring entry points). The robot drives along a circle one lane outside the perimeter
  (so it does not collide with the outermost queue lane), asks to join slot 0 of that entry
  line when it is at the entry point, waits there while the manager refuses (line full), and
  then follows the entry line slot by slot to the endpoint and on.
* **Tail joining** (sec. V-B). The robot heads straight in, toward the inner region (it stops
  one lane outside the inner region's boundary: the inner queues must stay clear). Whenever its
  scan sees something within the radio range gamma it broadcasts a `RadioQuery` (at most every
  `QUERY_PERIOD`); queued robots within gamma answer where they are queued and whether they
  are last (the manager tells each queued robot whether it is last), and other searchers answer
  that they are searching. Hearing a searcher, it yields with probability 1/2 for
  `YIELD_TIME` (the paper's "randomly yielding"). Hearing the last robot of an entry line, it
  asks to join the slot behind it. Hearing only robots that are not last, it goes backwards
  along their line (opposite to the queue's direction) to about gamma behind the lowest slot it
  heard of, and asks again. Reaching the inner region's boundary without hearing anyone, it
  takes the nearest slot of the nearest entry line (the fallback) and asks to join there; a
  refusal sends it backwards along that line. After ``controller.queue.seek_timeout`` without
  joining it falls back to entry-point joining (our addition).
* **Queued**. The robot drives slot to slot along its route (entry line, then for the single
  queue the inner queue the manager dispatched it to, then the exit line), reporting every slot
  it reaches. It does not swerve in the queue (the slots are the manager's, and swerving would
  take it into a neighbouring lane); it only brakes when something is right in front (on a robot
  model with a path rule of its own, the authors' foot-bot, that rule: `PATH_CONE`), and
  swerves round it only after ``controller.queue.brake_patience`` (a deadlock breaker). At the
  dock it waits for the world to drop its resource (T_unload), reports ``unloaded``, and goes
  on as granted (a robot whose resource was dropped on the way, in a dock's zone it stood in for
  T_unload, reports ``unloaded`` on reaching its dock). At the last exit slot (on the perimeter) it reports that slot and drives out
  radially, then forages again.
"""

from __future__ import annotations

import math
from enum import Enum
from functools import lru_cache

import numpy as np

from depot_manager.admission import DepotAdmission
from depot_manager.config import DockingConfig, QueueConfig
from depot_manager.geometry import DepotGeometryConfig, QueueLayout, make_layout
from depot_manager.protocol import DepotGrant, DepotReport, RadioQuery, RadioReply, Refusal, ReportKind, within_range
from swarm_controllers.api import new_command
from swarm_controllers.avoidance import ray_angles, ray_window
from swarm_controllers.cpfa.behaviour import CpfaBehaviour
from swarm_controllers.motion import ContinuousDrive, Drive, drive_for
from swarm_controllers.robots.ring import RingSensor
from swarm_msgs_py.types import BehaviourStatus, Command, Observation, RobotId, slot_constructor
from swarm_sim.inbound import Reason, Rejections
from swarm_sim.messaging import per_inbox
from swarm_sim.scenario import Scenario

_new_status = slot_constructor(BehaviourStatus)

KEEP_OUT_BAND = 0.25
"""Non-carriers keep this far outside the perimeter [m]."""
QUERY_PERIOD = 0.5
"""Tail joining: at most one radio query per this many seconds [s]."""
YIELD_TIME = 1.0
"""Tail joining: how long a yielding searcher stands still [s]."""
RETRY_PERIOD = 1.0
"""How often a refused join is asked again [s]."""
SLOT_TOLERANCE = 0.05
"""A slot counts as reached within this distance [m]."""
BRAKE_RANGE = 0.08
"""Queued robots stop when the scan sees something this close right in front (within
`BRAKE_CONE`) [m from the centre]; robots in the neighbouring lane, a lane spacing away, must
not trigger it."""
BRAKE_CONE = math.radians(25.0)
"""Half-angle of the braking cone about the heading [rad]."""
PATH_CONE = 30.0
"""[deg] a robot on a queue's path stops for what its proximity ring reads within this angle of its
heading, on a robot model with a path rule of its own (`swarm_controllers.motion.Drive.path_stop`):
the queue authors' ``GoStraightAngleRangeInDegreesInRegion`` (Artglz and Tameem786/
Collision_Free_CPFA, ``CPFA_controller::CollisionDetection``)."""
SWERVE_TIME = 1.0
"""[s] how long a robot whose brake patience ran out (`QueueConfig.brake_patience`) swerves before
it tries its line again."""


def _no_path_rule(ranges: np.ndarray, cone: float) -> None:
    """``line_stop: brake``: no path rule, our brake decides."""
    return None


def _ring_stop(scenario: Scenario, drive: Drive):
    """``line_stop: ring``: the drive's own path rule, and where it has none the authors' (a ``Stop()``
    for the proximity ring's readings within the cone), read from the scan."""
    blocks = RingSensor(scenario).blocks

    def stop(ranges: np.ndarray, cone: float) -> bool:
        own = drive.path_stop(ranges, cone)
        return blocks(ranges, cone) if own is None else own

    return stop


class Phase(Enum):
    FORAGING = "foraging"
    TO_ENTRY = "to_entry"
    SEEKING = "seeking"
    JOINING = "joining"
    QUEUED = "queued"
    LEAVING = "leaving"


_FORAGING, _TO_ENTRY, _SEEKING, _JOINING, _QUEUED, _LEAVING = (
    Phase.FORAGING, Phase.TO_ENTRY, Phase.SEEKING, Phase.JOINING, Phase.QUEUED, Phase.LEAVING
)
"""The phases every tick compares against, as module constants (a member looked up on its Enum
class costs ~0.1 us in Python 3.11; see `swarm_controllers.cpfa.behaviour`)."""


@per_inbox
def _granted(messages: tuple[object, ...]) -> frozenset[str]:
    """The robots a grant among a tick's messages is for (once per tick in a batch run)."""
    return frozenset(m.robot for m in messages if isinstance(m, DepotGrant))


@lru_cache(maxsize=8)
def _queues(
    geometry: DepotGeometryConfig, kind: str
) -> tuple[QueueLayout, dict[str, np.ndarray], dict[str, list[tuple[float, float]]], frozenset[tuple[str, int]]]:
    """The layout, every line's slots and the docks' slots, computed once per process (the manager's
    cells), the slots also as (x, y) float pairs: a queued robot looks one or two up every tick,
    and a row of an array unpacked into numpy scalars and computed with cost ~0.5 us more (measured)."""
    layout = make_layout(kind, geometry)
    admission = DepotAdmission(layout)
    cells = {line: admission.cells(line) for line in admission.lines()}
    slots = {line: [tuple(xy) for xy in points.tolist()] for line, points in cells.items()}
    return layout, cells, slots, admission.dock_slots()


class QueueBehaviour:
    """One robot foraging with the CPFA and delivering through the depot's queues."""

    # Slots, not a __dict__: see `CpfaBehaviour`.
    __slots__ = (
        "_R", "_avoid", "_brake_range", "_braked_since", "_carrying", "_cell", "_cells",
        "_center", "_cpfa", "_cpfa_step", "_docks", "_entry", "_entry_angles", "_entry_lines",
        "_detour_far", "_drive", "_entry_reach", "_exit_lines", "_front", "_gamma", "_goal", "_grant", "_join",
        "_keep_out", "_lane", "_last", "_layout", "_leave_to", "_line", "_line_drive", "_line_to_point", "_patience",
        "_path_stop", "_phase", "_query_at", "_to_point", "_retry_at", "_rng", "_innermost", "_seek_time",
        "_seek_until", "_slots", "_stamp_ns", "_tail", "_yield_until", "rejections", "robot",
    )

    def __init__(self, scenario: Scenario, robot: RobotId, rng: np.random.Generator) -> None:
        depot, queue = scenario.depot, QueueConfig.of(scenario)
        self.robot = robot
        self._rng = rng
        self.rejections = Rejections()
        """Grants and radio replies naming a line or slot our layout does not have (dropped)."""
        self._drive = drive_for(scenario, rng)
        """The robot's motion layer, shared with its CPFA (one ``BaseController`` per robot)."""
        self._to_point = self._drive.to_point
        self._line_drive = ContinuousDrive(scenario) if queue.queued_motion == "continuous" else self._drive
        """How the robot drives along the queue's lines (`QueueConfig.queued_motion`)."""
        self._line_to_point = self._line_drive.to_point
        self._path_stop = (_no_path_rule if queue.line_stop == "brake" else
                           _ring_stop(scenario, self._line_drive) if queue.line_stop == "ring"
                           else self._line_drive.path_stop)
        """The stop rule on the lines (`QueueConfig.line_stop`): True stopped, False not, None: brake."""
        self._center = (float(depot.center[0]), float(depot.center[1]))
        self._R = DockingConfig.of(scenario).perimeter_radius
        self._lane = queue.lane_spacing
        self._gamma = scenario.robots.radio_range
        self._tail = queue.joining == "tail"
        self._seek_time = queue.seek_timeout
        self._patience = queue.brake_patience
        self._keep_out = self._R + KEEP_OUT_BAND
        """Non-carriers stay outside this radius about the depot centre [m]."""
        self._detour_far = self._drive.blind_legs
        """Check a non-carrier's path against the disc from any distance, not only near it: a
        blind leg started far out would cross the perimeter (``_forage``)."""
        self._cpfa = CpfaBehaviour(scenario, robot, rng, keep_out=self._keep_out, perimeter=self._R,
                                   drive=self._drive, carrier_rim=queue.return_leg == "rim")
        self._cpfa_step = self._cpfa.step
        self._avoid = self._drive.avoidance(0.1)
        self._layout, self._cells, self._slots, self._docks = _queues(
            DepotGeometryConfig.from_scenario(scenario), queue.wrapping)
        self._entry_lines = tuple(line.name for line in self._layout.entry_lines)
        self._entry_angles = np.array(
            [math.atan2(p[1] - self._center[1], p[0] - self._center[0]) for p in self._layout.entry_points]
        )
        self._exit_lines = {line.name for line in self._layout.exit_lines}
        self._entry_reach = queue.entry_reach
        """How near a queued robot must come to a cell of an entry line to have reached it
        (`QueueConfig.entry_reach`); a dock's cell and the other lines': `SLOT_TOLERANCE`."""
        self._innermost = _innermost_arc(self._cells, self._entry_lines, self._center, self._lane) \
            if queue.boarding == "innermost" else None
        """``boarding: innermost``: the innermost arc's cells, as (line, cell index, x, y) arrays."""
        self._front = ray_window(i for i, a in enumerate(ray_angles(scenario.sensors.scan)) if abs(a) <= BRAKE_CONE)
        """The rays of the braking cone."""
        self._brake_range = float(np.float32(BRAKE_RANGE))
        """BRAKE_RANGE as the float32 the scan's ranges are compared with (numpy compares a
        float32 with a Python float in float32), for comparing the rays read as Python floats."""
        self._phase = Phase.FORAGING
        self._carrying = False
        self._line = ""  # the line the robot is on (or joining)
        self._cell = -1  # the last slot of `_line` it reached
        self._grant: tuple[str, int] | None = None
        self._last = False
        self._entry = 0  # entry-joining: which entry line
        self._retry_at = 0.0
        self._query_at = 0.0
        self._seek_until = 0.0
        self._yield_until = 0.0
        self._goal: tuple[float, float] | None = None  # tail joining: where to look next
        self._join: tuple[str, int] | None = None  # the join asked for, awaiting an answer
        self._leave_to = (0.0, 0.0)
        self._braked_since = math.inf
        self._stamp_ns = 0

    # ------------------------------------------------------------------ views

    @property
    def phase(self) -> Phase:
        return self._phase

    @property
    def cpfa(self) -> CpfaBehaviour:
        return self._cpfa

    def status(self, stamp_ns: int | None = None) -> BehaviourStatus:
        """The CPFA's status with the phase, line and cell: built here from the CPFA's fields (the
        controller node asks every tick, the batch runner for the state rules: ~2.8 -> ~1 us; members' text
        as in `CpfaBehaviour.status`)."""
        cpfa = self._cpfa
        phase = self._phase
        own = 0 if self._avoid is cpfa.avoidance else self._avoid.events  # a model's one avoidance
        return _new_status(
            self.robot, self._stamp_ns if stamp_ns is None else stamp_ns,
            (cpfa.state if phase is _FORAGING else phase)._name_, cpfa.obstacle_avoidance_events + own,
            cpfa.trips, (("search", cpfa.search_mode._value_), ("line", self._line), ("cell", str(self._cell))),
        )

    # ------------------------------------------------------------------ the tick

    def step(self, obs: Observation) -> Command:
        self._stamp_ns = obs.stamp_ns
        self._drive.begin(obs.stamp_ns)
        out: list[object] = []
        carrying = bool(obs.sensed.carrying)
        dropped = self._carrying and not carrying
        self._carrying = carrying
        phase = self._phase
        if obs.messages and (phase is _QUEUED or phase is _SEEKING or self.robot in _granted(obs.messages)):
            self._handle(obs, out)
            phase = self._phase
        pose = obs.pose
        cx, cy = self._center
        r = math.hypot(pose.x - cx, pose.y - cy)
        if phase is _FORAGING:
            if not (carrying and r <= self._keep_out):
                return self._forage(obs, r, out)
            self._begin_delivery(obs, r, out)
            phase = self._phase
        if dropped and phase is _QUEUED and (self._line, self._cell) in self._docks:
            out.append(DepotReport(obs.stamp_ns, self.robot, ReportKind.UNLOADED, self._line, self._cell))
        if phase is _TO_ENTRY:
            linear, angular = self._to_entry(obs, r, out)
        elif phase is _SEEKING:
            linear, angular = self._seek(obs, r, out)
        elif phase is _JOINING:
            linear, angular = self._joining(obs, out)
        elif phase is _QUEUED:
            linear, angular = self._queued(obs, out)
        else:
            linear, angular = self._leaving(obs, r)
            if self._phase is _FORAGING:
                return self._forage(obs, r, out)
        if phase is _TO_ENTRY or phase is _SEEKING or obs.t - self._braked_since >= self._patience:
            override = self._avoid.update(obs.ranges)
            if override is not None:
                linear, angular = override.linear, override.angular
            if obs.t - self._braked_since >= self._patience + SWERVE_TIME:
                self._braked_since = math.inf  # swerved for a second: try the line again
        elif (phase is _QUEUED or phase is _LEAVING) and self._path_stop(obs.ranges, PATH_CONE):
            linear = angular = 0.0  # the robot model's own rule on a path (the authors' foot-bot: Stop())
            self._braked_since = min(self._braked_since, obs.t)
        elif linear > 0.0 and min(obs.ranges[self._front].tolist()) < self._brake_range:
            linear = 0.0
            self._braked_since = min(self._braked_since, obs.t)
        else:
            self._braked_since = math.inf
        return new_command(linear, angular, tuple(out))

    # ------------------------------------------------------------------ messages

    def _handle(self, obs: Observation, out: list[object]) -> None:
        """The tick's messages, in order. Only for a robot queued or seeking or one a grant is for
        (`step`): only queued and seeking robots answer queries and take replies, and only a grant
        can change the phase."""
        x, y = obs.pose.x, obs.pose.y
        for m in obs.messages:
            if isinstance(m, DepotGrant):
                if m.robot == self.robot:
                    self._on_grant(m, obs)
            elif isinstance(m, RadioQuery):
                if m.sender != self.robot and within_range(m, x, y, self._gamma):
                    reply = self._reply(m, obs)
                    if reply is not None:
                        out.append(reply)
            elif isinstance(m, RadioReply):
                if m.to == self.robot and self._phase is _SEEKING and within_range(m, x, y, self._gamma):
                    self._on_reply(m, obs, out)

    def _valid_slot(self, what: str, line: str, cell: int) -> bool:
        """Whether (line, cell) names a slot of our layout: messages from the bus are untrusted."""
        cells = self._cells.get(line)
        if cells is None or not 0 <= cell < len(cells):
            self.rejections.add(what, Reason.REFUSED, f"no slot {line[:40]!r}/{cell} in our layout")
            return False
        return True

    def _on_grant(self, grant: DepotGrant, obs: Observation) -> None:
        if grant.cell >= 0 and not self._valid_slot("DepotGrant", grant.line, grant.cell):
            return
        if grant.cell < 0:  # a refused join
            if self._phase is Phase.JOINING and self._join is not None and grant.line == self._join[0]:
                line, cell = self._join
                self._join = None
                self._retry_at = obs.t + RETRY_PERIOD
                if not self._tail:
                    self._phase = Phase.TO_ENTRY  # wait at the entry point, ask again
                    return
                self._phase = Phase.SEEKING
                if grant.reason is Refusal.NOT_BEHIND_TAIL:
                    self._back_along(line, cell)
            return
        if self._phase is Phase.JOINING and self._join is not None:
            self._line, self._cell = self._join[0], self._join[1] - 1
            self._join = None
            self._phase = Phase.QUEUED
        self._grant = (grant.line, grant.cell)
        self._last = grant.last

    def _reply(self, query: RadioQuery, obs: Observation) -> RadioReply | None:
        x, y = obs.pose.x, obs.pose.y
        if self._phase is Phase.QUEUED and self._line in self._entry_lines:
            return RadioReply(obs.stamp_ns, self.robot, query.sender, x, y, self._line,
                              max(self._cell, 0), self._last)
        if self._phase is Phase.SEEKING:
            return RadioReply(obs.stamp_ns, self.robot, query.sender, x, y, "", -1, False)
        return None

    def _on_reply(self, reply: RadioReply, obs: Observation, out: list[object]) -> None:
        if not reply.line:  # another searcher: yield at random
            if self._rng.random() < 0.5:
                self._yield_until = obs.t + YIELD_TIME
            return
        if not self._valid_slot("RadioReply", reply.line, reply.cell) or reply.line not in self._entry_lines:
            return
        if self._join is not None:
            return
        if reply.last and reply.cell > 0:
            self._request_join(reply.line, reply.cell - 1, obs, out)
        elif not reply.last:
            self._back_along(reply.line, reply.cell)

    # ------------------------------------------------------------------ phases

    def _forage(self, obs: Observation, r: float, out: list[object]) -> Command:
        command = self._cpfa_step(obs)
        if out:  # radio replies of this tick go out first
            command = new_command(command.linear, command.angular, (*out, *command.messages))
        if self._carrying or (r > self._keep_out and not self._detour_far):
            return command
        messages = command.messages
        cx, cy = self._center
        x, y = obs.pose.x, obs.pose.y
        ux, uy = ((x - cx) / r, (y - cy) / r) if r > 1e-9 else (1.0, 0.0)
        if r < self._R + 0.5 * KEEP_OUT_BAND:  # inside: straight out
            goal = (cx + ux * (self._R + 2 * KEEP_OUT_BAND), cy + uy * (self._R + 2 * KEEP_OUT_BAND))
            return new_command(*self._to_point(x, y, obs.pose.yaw, *goal), messages)
        tx, ty = self._cpfa.target
        if _segment_hits_disc((x, y), (tx, ty), self._center, self._R + 0.5 * KEEP_OUT_BAND):
            # Round the disc the short way, on a two-lane ring road: counter-clockwise on the
            # inner lane, clockwise on the outer one, so robots rounding it never meet head on.
            side = 1.0 if (tx - x) * -uy + (ty - y) * ux >= 0 else -1.0
            rho = self._R + (0.6 if side > 0 else 1.6) * KEEP_OUT_BAND
            phi = math.atan2(uy, ux) + side * 0.3 / rho
            goal = (cx + rho * math.cos(phi), cy + rho * math.sin(phi))
            return new_command(*self._to_point(x, y, obs.pose.yaw, *goal), messages)
        return command

    def _begin_delivery(self, obs: Observation, r: float, out: list[object]) -> None:
        self._grant = None
        self._line, self._cell = "", -1
        if self._tail:
            self._phase = Phase.SEEKING
            self._seek_until = obs.t + self._seek_time
            self._goal = None
        else:
            self._start_entry_joining(obs)

    def _start_entry_joining(self, obs: Observation) -> None:
        bearing = math.atan2(obs.pose.y - self._center[1], obs.pose.x - self._center[0])
        gaps = np.abs(np.remainder(self._entry_angles - bearing + math.pi, 2 * math.pi) - math.pi)
        self._entry = int(np.argmin(gaps))
        self._phase = Phase.TO_ENTRY

    def _to_entry(self, obs: Observation, r: float, out: list[object]) -> tuple[float, float]:
        """Along the circle one lane outside the perimeter, in the arc's preferred direction."""
        x, y = obs.pose.x, obs.pose.y
        cx, cy = self._center
        line = self._entry_lines[self._entry]
        entry = self._slots[line][0]
        target_bearing = self._entry_angles[self._entry]
        bearing = math.atan2(y - cy, x - cx)
        delta = math.remainder(target_bearing - bearing, 2 * math.pi)
        ring = self._R + self._lane
        if abs(delta) * ring < 0.15:
            d = math.hypot(entry[0] - x, entry[1] - y)
            if d <= 2 * SLOT_TOLERANCE and self._join is None and obs.t >= self._retry_at:
                self._request_join(line, 0, obs, out)
            if d <= SLOT_TOLERANCE:
                return 0.0, 0.0
            return self._to_point(x, y, obs.pose.yaw, entry[0], entry[1])
        step = math.copysign(min(abs(delta), 0.3 / ring), delta)
        goal = (cx + ring * math.cos(bearing + step), cy + ring * math.sin(bearing + step))
        return self._to_point(x, y, obs.pose.yaw, *goal)

    def _seek(self, obs: Observation, r: float, out: list[object]) -> tuple[float, float]:
        x, y = obs.pose.x, obs.pose.y
        if obs.t >= self._seek_until:
            self._start_entry_joining(obs)
            return self._to_entry(obs, r, out)
        if obs.t < self._yield_until:
            return 0.0, 0.0
        if self._innermost is not None:
            return self._board_innermost(obs, r, out)
        near = bool(np.min(obs.ranges) < self._gamma)
        if near and obs.t >= self._query_at:
            self._query_at = obs.t + QUERY_PERIOD
            out.append(RadioQuery(obs.stamp_ns, self.robot, float(x), float(y)))
        if self._join is not None:  # a reply this tick made it ask to join
            return self._joining(obs, out)
        cx, cy = self._center
        boundary = self._layout.inner_radius + self._lane
        if self._goal is None and r <= boundary + SLOT_TOLERANCE:
            if obs.t < self._retry_at:
                return 0.0, 0.0  # at the inner region's boundary: never into it
            line, cell = self._nearest_slot(x, y)  # fallback: the nearest line
            self._request_join(line, cell, obs, out)
            return self._joining(obs, out)
        if self._goal is None:  # straight in, up to the inner region's boundary
            gx, gy = cx + (x - cx) / r * boundary, cy + (y - cy) / r * boundary
        else:
            gx, gy = self._goal
            if math.hypot(gx - x, gy - y) < self._gamma / 2:
                self._goal = None  # looked there: head in again, asking as we go
        return self._to_point(x, y, obs.pose.yaw, gx, gy)

    def _board_innermost(self, obs: Observation, r: float, out: list[object]) -> tuple[float, float]:
        """``boarding: innermost``: straight in to one lane outside the inner region, then ask for
        the nearest cell of the innermost arc (the queue authors' Q_ST, `QueueConfig.boarding`)."""
        if self._join is not None:
            return self._joining(obs, out)
        x, y = obs.pose.x, obs.pose.y
        cx, cy = self._center
        boundary = self._layout.inner_radius + self._lane
        if r <= boundary + SLOT_TOLERANCE:
            if obs.t >= self._retry_at:
                lines, cells, xy = self._innermost
                i = int(np.argmin(np.hypot(*(xy - (x, y)).T)))
                self._request_join(lines[i], int(cells[i]), obs, out)
                return self._joining(obs, out)
            return 0.0, 0.0
        return self._to_point(x, y, obs.pose.yaw, cx + (x - cx) / r * boundary, cy + (y - cy) / r * boundary)

    def _joining(self, obs: Observation, out: list[object]) -> tuple[float, float]:
        """Asked to join (line, cell); drive there while the manager answers."""
        if self._join is None:
            return 0.0, 0.0
        line, cell = self._join
        tx, ty = self._slots[line][cell]
        if math.hypot(tx - obs.pose.x, ty - obs.pose.y) <= SLOT_TOLERANCE:
            return 0.0, 0.0
        return self._line_to_point(obs.pose.x, obs.pose.y, obs.pose.yaw, tx, ty)

    def _queued(self, obs: Observation, out: list[object]) -> tuple[float, float]:
        x, y = obs.pose.x, obs.pose.y
        nxt = self._next_slot()
        if nxt is None:
            return 0.0, 0.0
        line, cell = nxt
        tx, ty = self._slots[line][cell]
        on_entry = line in self._entry_lines and (line, cell) not in self._docks
        reach = self._entry_reach if on_entry else SLOT_TOLERANCE
        if math.hypot(tx - x, ty - y) <= reach:
            self._line, self._cell = line, cell
            out.append(DepotReport(obs.stamp_ns, self.robot, ReportKind.AT, line, cell))
            if not self._carrying and (line, cell) in self._docks:
                # Its resource was dropped on the way (it stood in a dock's zone for T_unload): there
                # is nothing left to unload, so its dock is done with it (else the dock waits forever).
                out.append(DepotReport(obs.stamp_ns, self.robot, ReportKind.UNLOADED, line, cell))
            if line in self._exit_lines and cell == len(self._cells[line]) - 1:
                cx, cy = self._center
                r = math.hypot(x - cx, y - cy)
                reach = self._R + 2 * KEEP_OUT_BAND
                self._leave_to = (cx + (x - cx) / r * reach, cy + (y - cy) / r * reach)
                self._phase = Phase.LEAVING
                return 0.0, 0.0
            nxt = self._next_slot()
            if nxt is None:
                return 0.0, 0.0
            tx, ty = self._slots[nxt[0]][nxt[1]]
        return self._line_to_point(x, y, obs.pose.yaw, tx, ty)

    def _leaving(self, obs: Observation, r: float) -> tuple[float, float]:
        if r >= self._R + KEEP_OUT_BAND + 0.05:
            self._phase = Phase.FORAGING
            self._line, self._cell, self._grant = "", -1, None
            return 0.0, 0.0
        return self._line_to_point(obs.pose.x, obs.pose.y, obs.pose.yaw, *self._leave_to)

    # ------------------------------------------------------------------ helpers

    def _next_slot(self) -> tuple[str, int] | None:
        """The next slot along the route within the grant, None if the robot must wait."""
        if self._grant is None:
            return None
        g_line, g_cell = self._grant
        if g_line == self._line:
            return (g_line, self._cell + 1) if self._cell < g_cell else None
        if self._cell < len(self._cells[self._line]) - 1:  # finish the current line first
            return self._line, self._cell + 1
        return (g_line, 0) if g_cell >= 0 else None

    def _request_join(self, line: str, cell: int, obs: Observation, out: list[object]) -> None:
        self._join = (line, cell)
        self._phase = Phase.JOINING
        out.append(DepotReport(obs.stamp_ns, self.robot, ReportKind.JOIN, line, cell))

    def _back_along(self, line: str, cell: int) -> None:
        """Look for the tail about gamma behind `cell` of `line` (against the queue's flow)."""
        back = max(0, cell - max(1, round(self._gamma / self._lane)))
        self._line, self._cell = line, -1
        self._goal = tuple(float(v) for v in self._cells[line][back])

    def _nearest_slot(self, x: float, y: float) -> tuple[str, int]:
        best = None
        for line in self._entry_lines:
            d = np.hypot(*(self._cells[line] - (x, y)).T)
            i = int(np.argmin(d))
            if best is None or d[i] < best[0]:
                best = (float(d[i]), line, i)
        return best[1], best[2]


def _innermost_arc(cells: dict, lines: tuple[str, ...], center: tuple[float, float], lane: float) -> tuple:
    """The entry lines' cells within half a lane of the innermost one's distance from the centre:
    (line names, cell indices, (n, 2) positions)."""
    found = [(line, i, xy) for line in lines for i, xy in enumerate(cells[line])]
    r = np.array([math.hypot(xy[0] - center[0], xy[1] - center[1]) for _, _, xy in found])
    keep = [k for k in range(len(found)) if r[k] < r.min() + lane / 2]
    return (tuple(found[k][0] for k in keep), np.array([found[k][1] for k in keep]),
            np.array([found[k][2] for k in keep], dtype=float))


def _segment_hits_disc(p, q, c, radius: float) -> bool:
    px, py = p[0] - c[0], p[1] - c[1]
    dx, dy = q[0] - p[0], q[1] - p[1]
    L2 = dx * dx + dy * dy
    t = 0.0 if L2 < 1e-12 else max(0.0, min(1.0, -(px * dx + py * dy) / L2))
    return (px + t * dx) ** 2 + (py + t * dy) ** 2 < radius * radius

"""The multiple distributed bidirectional spiral algorithm (MDBSA) behaviour, both versions.

Lu & Luna, CRV 2023, Sec. IV and Fig. 3 (../shared/papers/mdbsa_spiral_search.md). The arena
is split into N_R square regions with one square spiral each (`center.region_paths`, eqs.
(3)-(5)). A robot asks the center (`center.CenterServer`, over `swarm_sim.protocol`) for a
region, walks that region's spiral from ``s0`` in ``direction`` up to ``stop_s``, carries
every resource it finds to the drop zone, goes back to where it found it and resumes; when
its walk is over it returns to the center for a new one. MDBSA-C (``depot.delivery: depot``)
delivers to the central depot, MDBSA-D (``depot.delivery: region_centers``) to its region's own center.

Talking to the center (it hears robots only within ``controller.spiral.center_range`` of the
depot centre, and answers two ticks later):

* **Start**: the robots start on a grid around the depot. A robot within range reports
  ``ProgressReport(region=-1, done=True)`` at once; one outside drives toward the depot centre
  first. It then waits, parked, for its `RegionAssignment` (messages in ``obs.messages``; only
  those with ``robot == self.robot`` concern it) and re-sends its report if no answer came
  within `ASK_RETRY` seconds.
* **Idle** (region -1; the paper: "If there are no available paths to assign or share, the
  robot becomes idle"): the robot drives to the center of the region it walked last (a robot
  that never walked one: the nearest region center) and stops within
  ``regions.center_radius`` of it, as the authors' controllers do (``DSA = IDLE;
  SetTarget(regionCenters[PreRegionID])``, ``Stop()`` once within ``RegionRadius``:
  MARSLab-UTRGV/Adaptive-Multiple-Distributed-Spiral-Search-Algorithm, branch luki-dev,
  c890aa1 "the version for the submission", Centralized/ and Distributed/
  source/DSA/DSA_controller.cpp, ``ControlStep``). It does not ask again: in the authors'
  code IDLE is final, and under the paper's rules nothing becomes sharable later (both
  walkers of a region end together), so "idle until there is a path available" never ends
  either. Idling at the center instead walled off the drop zone (issue 11). Consequence: a
  region freed later by a robot declared dead is not taken up by idle robots.
* **End of a walk**: back to the center (stopping `ASK_MARGIN` inside the range), report
  ``done=True`` with the arc length reached, wait for the next walk; with
  ``controller.spiral.next_walk_at: depot`` a robot given a new walk first drives to within
  `DEPOT_POINT_HIT` of `DEPOT_POINT` (the authors' point by the nest; an idle one goes straight to its idle spot).
* **MDBSA-C on each delivery**: the route to the depot passes the center, so the carrier
  reports its progress (``done=False``) once per trip on entering the range; if its partner's
  frontier moved meanwhile the center answers with the walk's new ``stop_s`` (same region and
  direction), which the robot adopts (`CenterServer` docstring).

Choices where the paper leaves a detail open:

* **Meeting the partner** (paper: "A robot can communicate with another robot in the same
  region"; the two walkers "meet at some point in their spiral path and complete the search"):
  a walker sends its frontier (`WalkProgress`) each time it has got ``waypoint_gaps`` gaps
  further (the authors' waypoint spacing) and when its walk ends, and the walker of the same
  region in the other direction moves its stop there (never away from itself), as the
  authors' robots compare their next point with the partner's in shared memory at each
  waypoint. The two overlap by about that spacing, never leave a gap.
  With ``controller.spiral.partner_radio: false`` a walk ends at the stop the center last sent
  (the partner's frontier at assignment, or at an MDBSA-C robot's last pass); MDBSA-D robots,
  which never pass the center mid-walk, then walk most of each other's stretch. Measured
  (experiment 2, 20 foot-bots, seed 0): the first finisher idles at the region's centre while
  its partner still walks the inner rings round it, which is most of MDBSA-D's collision time.
* **Walk coordinates**: a reverse walk (direction -1) follows ``path.reversed()``; its arc
  length u maps to the center's s = L - u (and back). Progress is, as in DDSA, the arc length
  of the last waypoint reached plus the projection onto the current leg, never decreasing,
  clamped to the stop.
* **Lane following, finding, resuming, avoidance**: as the DDSA behaviour (`ddsa.py`): steer
  ``controller.spiral.waypoint_gaps`` gaps ahead of the progress on the current leg; steer to
  the nearest resource seen while searching; the find position is the progress when
  ``obs.sensed.carrying`` turns True, and the robot drives back to it (TRAVELING to the walk's
  start is the same motion); `LaneAvoidance`
  on the lane and on the last ``approach_radius`` to it (a reverse walk starts on the outer
  lane, 0.2 m from the wall, which the general avoidance would never let a robot reach head
  on), the general avoidance (turning right) elsewhere. Avoidance runs every tick in every
  state, as the authors' ``BaseController::Move`` does: a robot standing still (waiting for
  the center's answer, idle at its region center) turns in place away from what comes at its
  front and does not drive off (`LaneAvoidance.parked`).
* **Delivery target**: MDBSA-C the ``depot`` drop zone's centre; MDBSA-D the ``region_<i>``
  drop zone of the walk's region (the world drops as soon as the carrier is inside it). A
  resource picked up outside a walk (driving over it) goes to the nearest region center.
  A robot picks up whatever it passes, also on its way out (the world's gripper; the authors'
  robots search while travelling too, ``SetHoldingFood`` in SEARCHING), and an MDBSA-D carrier
  that then crosses another region's centre drops its load there (the world drops in any zone
  a carrier enters; the authors' robot would carry it to its own region's centre).
  With ``depot.delivery: region_centers`` the depot disc is not a drop zone, so MDBSA-D
  carriers crossing it keep their load; construction refuses a scenario whose drop zones do
  not match the version.

Deterministic: the generator is accepted for the factory signature and never drawn from.
"""

from __future__ import annotations

import math
from enum import Enum

import numpy as np

from swarm_controllers.motion import drive_for
from swarm_controllers.spiral.center import region_paths
from swarm_controllers.spiral.config import SpiralConfig
from swarm_controllers.spiral.ddsa import LaneAvoidance
from swarm_controllers.spiral.geometry import SpiralPath
from swarm_controllers.spiral.protocol import ProgressReport, RegionAssignment, WalkProgress
from swarm_controllers.spiral.regions import RegionConfig
from swarm_msgs_py.types import STOP, BehaviourStatus, Command, Observation, Pose2D, RobotId
from swarm_sim.scenario import Scenario
from swarm_sim.sites import drop_zones

ASK_RETRY = 2.0
"""A report unanswered this long [s, sim time] is sent again (the answer normally takes two ticks)."""
ASK_MARGIN = 0.1
"""A robot heading for the center stops this far inside its range [m] before reporting."""
DEPOT_POINT = (0.1, 0.1)
"""``controller.spiral.next_walk_at: depot``: the point a walker passes on its way to a new walk
[m from the depot centre, world axes]: the authors' ``SetTarget(CVector2(0.1, 0.1))``, their nest at (0, 0)
("can not set it to (0,0) since the TargetHit will avoid to go to the center")."""
DEPOT_POINT_HIT = 0.1
"""... and how close it must come to it before going on [m]: ``TargetHit``'s squared-distance test
against ``TargetDistanceTolerance`` = 0.01 m^2."""
_EPS = 1e-9


class MdbsaState(Enum):
    """Fig. 3 of the paper, folded into the states a robot can be observed in."""

    TO_CENTER = "to_center"
    """Driving into the center's range to ask for a walk (at the start, or a walk is over)."""
    WAITING = "waiting"
    """Parked in range, waiting for the center's answer."""
    IDLE = "idle"
    """Nothing to walk (region -1): to the last region's center and stopped there, for good."""
    TRAVELING = "traveling"
    """Driving to where the assigned walk begins."""
    SEARCHING = "searching"
    """Walking the region's spiral (or steering to a resource seen from it)."""
    DELIVERING = "delivering"
    """Carrying a resource to the depot (MDBSA-C) or the region's center (MDBSA-D)."""
    RESUMING = "resuming"
    """Driving back to where the last resource was found."""


class _Walk:
    """One assignment, walked along the oriented path; u is arc length along the walk [m]."""

    def __init__(self, a: RegionAssignment, path: SpiralPath) -> None:
        self.region = a.region
        self.direction = 1 if a.direction >= 0 else -1
        self.length = path.length
        self.path = path if self.direction > 0 else path.reversed()
        self.wp = [(float(x), float(y)) for x, y in self.path.waypoints]
        self.cum = [float(c) for c in self.path.cumulative]
        self.u = self.to_u(a.s0)
        self.stop_u = max(self.u, self.to_u(a.stop_s))
        self.next = self.path.next_waypoint_index(self.u)
        self.sent_u = -math.inf
        """The progress last told the partner (`WalkProgress`) [m along the walk]."""

    def to_u(self, s: float) -> float:
        """Center arc length s [m from the spiral's start] -> walk arc length u (an involution)."""
        s = min(max(float(s), 0.0), self.length)
        return s if self.direction > 0 else self.length - s

    @property
    def s(self) -> float:
        """Progress as the center counts it [m from the spiral's start]."""
        return self.to_u(self.u)

    def stop_at(self, s: float) -> None:
        """The partner has been up to `s` [m from the spiral's start]: the stop moves there if
        that is nearer, never behind the progress."""
        self.stop_u = max(self.u, min(self.stop_u, self.to_u(s)))

    @property
    def over(self) -> bool:
        return self.u >= self.stop_u - _EPS or self.next >= len(self.wp)


class MdbsaBehaviour:
    """One robot of MDBSA-C or MDBSA-D. See the module docstring for the rules and choices."""

    def __init__(self, scenario: Scenario, robot: RobotId,
                 rng: np.random.Generator | None = None) -> None:
        if robot not in scenario.robot_names:
            raise ValueError(f"{robot} is not one of the scenario's {scenario.robots.count} robots")
        self.robot = robot
        self.distributed = scenario.depot.delivery == "region_centers"
        """MDBSA-D (each region's resources go to its centre) rather than MDBSA-C (all to the
        depot): the world's delivery sites say which."""
        sp = SpiralConfig.of(scenario)
        self.paths: list[SpiralPath] = region_paths(scenario)
        """Every region's spiral [m, world frame], as the center has them."""
        zones = {z.name: z for z in drop_zones(scenario)}
        names = [f"region_{i}" for i in range(len(self.paths))] if self.distributed else ["depot"]
        self._drops = [(float(zones[n].center[0]), float(zones[n].center[1])) for n in names]
        self._center = (float(scenario.depot.center[0]), float(scenario.depot.center[1]))
        self._range = float(sp.center_range)
        self._ask_r2 = max(self._range - ASK_MARGIN, 0.5 * self._range) ** 2
        self._depot_point = ((self._center[0] + DEPOT_POINT[0], self._center[1] + DEPOT_POINT[1])
                      if sp.next_walk_at == "depot" else None)
        """Where a walker passes on its way from one walk to the next [m, world frame]; None: it
        does not."""
        self._via_depot = False
        """On the way to a new walk, `DEPOT_POINT` is still ahead."""
        self._idle_r2 = float(RegionConfig.of(scenario).center_radius) ** 2
        self._drive = drive_for(scenario, rng)
        self._to_point = self._drive.to_point
        self._avoidance = LaneAvoidance(scenario, self._drive)
        tol = min(scenario.controller.arrival_tolerance, sp.gap / 4.0)
        self._wp_tol2 = tol**2
        self._arrival2 = scenario.controller.arrival_tolerance**2
        self._carrot = sp.gap * sp.waypoint_gaps
        self._radio = sp.partner_radio

        self._state = MdbsaState.TO_CENTER
        self._walk: _Walk | None = None
        self._after_delivery = MdbsaState.TO_CENTER
        self._carrying = False
        self._reported_trip = False
        self._asked_at = -math.inf
        self._asked_ns = -1
        self._idle_at: tuple[float, float] | None = None
        """Where an idle robot stops [m, world frame]: its last region's center."""
        self._outbox: list[object] = []
        self._trips = 0
        self._stamp_ns = 0

    # ------------------------------------------------------------------ read-only views

    @property
    def state(self) -> MdbsaState:
        return self._state

    @property
    def region(self) -> int:
        """The region of the current (or last, until a new answer) walk; -1 if none."""
        return self._walk.region if self._walk is not None else -1

    @property
    def direction(self) -> int:
        return self._walk.direction if self._walk is not None else 0

    @property
    def progress(self) -> float:
        """Arc length reached [m from the region spiral's start, the center's convention]."""
        return self._walk.s if self._walk is not None else 0.0

    @property
    def stop(self) -> float | None:
        """Where the current walk ends [m from the spiral's start]; None without a walk."""
        return self._walk.to_u(self._walk.stop_u) if self._walk is not None else None

    @property
    def trips(self) -> int:
        return self._trips

    @property
    def obstacle_avoidance_events(self) -> int:
        return self._avoidance.events

    def status(self, stamp_ns: int | None = None) -> BehaviourStatus:
        w = self._walk
        extra = [("region", str(self.region))]
        if w is not None:
            extra.append(("direction", str(w.direction)))
            extra.append(("progress", f"{w.s:.3f}/{w.length:.3f}"))
        return BehaviourStatus(
            robot=self.robot,
            stamp_ns=self._stamp_ns if stamp_ns is None else stamp_ns,
            state=self._state.name,
            obstacle_avoidance_events=self._avoidance.events,
            trips=self._trips,
            extra=tuple(extra),
        )

    # ------------------------------------------------------------------ the tick

    def step(self, obs: Observation) -> Command:
        self._stamp_ns = obs.stamp_ns
        self._drive.begin(obs.stamp_ns)
        self._outbox = []
        for m in obs.messages:
            if isinstance(m, RegionAssignment) and m.robot == self.robot:
                self._on_assignment(m, obs.pose)
            elif isinstance(m, WalkProgress) and self._radio:
                self._on_partner(m)
        self._on_carrying(bool(obs.sensed.carrying))
        state = self._state
        if state is MdbsaState.WAITING:
            self._waiting(obs)
            return self._standing(obs)
        if state is MdbsaState.IDLE and self._at_idle_spot(obs):
            return self._standing(obs)
        override = self._avoidance.update(obs.ranges, obs.t, on_lane=self._on_lane(obs))
        if state is MdbsaState.SEARCHING:
            linear, angular = self._searching(obs)
        elif state is MdbsaState.TRAVELING or state is MdbsaState.RESUMING:
            linear, angular = self._to_walk(obs)
        elif state is MdbsaState.DELIVERING:
            linear, angular = self._delivering(obs)
        elif state is MdbsaState.IDLE:
            assert self._idle_at is not None
            linear, angular = self._to_point(obs.pose.x, obs.pose.y, obs.pose.yaw, *self._idle_at)
        else:
            linear, angular = self._to_center(obs)
        if self._state is MdbsaState.WAITING:  # just reported; stand from now on
            return self._standing(obs)
        if override is not None:
            return self._command(override.linear, override.angular)
        return self._command(linear, angular)

    def _on_lane(self, obs: Observation) -> bool:
        """Searching, or on the last approach to the lane point a walk (re)starts from."""
        state, w = self._state, self._walk
        if state is MdbsaState.SEARCHING:
            return True
        if (state is MdbsaState.TRAVELING or state is MdbsaState.RESUMING) and w is not None:
            tx, ty = w.path.point_at(w.u)
            d = math.hypot(float(tx) - obs.pose.x, float(ty) - obs.pose.y)
            return d < self._avoidance.approach_radius
        return False

    def _standing(self, obs: Observation) -> Command:
        """A robot that stands still: avoidance turns in place only (`LaneAvoidance.parked`)."""
        c = self._avoidance.parked(obs.ranges)
        return self._command(c.linear, c.angular)

    def _at_idle_spot(self, obs: Observation) -> bool:
        assert self._idle_at is not None
        x, y = self._idle_at
        return (obs.pose.x - x) ** 2 + (obs.pose.y - y) ** 2 <= self._idle_r2

    def _command(self, linear: float, angular: float) -> Command:
        if not self._outbox:
            return Command(linear, angular) if (linear, angular) != (0.0, 0.0) else STOP
        return Command(linear, angular, tuple(self._outbox))

    # ------------------------------------------------------------------ events

    def _on_assignment(self, m: RegionAssignment, pose: Pose2D) -> None:
        w = self._walk
        # An answer to our last ask is stamped after it; anything older (an update the center
        # sent while we were about to ask) is not the answer.
        asked = self._state is MdbsaState.WAITING and m.stamp_ns > self._asked_ns
        if not asked and w is not None and m.region == w.region and m.direction == w.direction:
            # The center passes on the partner's frontier: the stop only moves toward us.
            w.stop_at(m.stop_s)
            return
        if self._state is MdbsaState.WAITING and not asked:
            return
        if m.region < 0:
            if asked:
                self._go_idle(pose)
            return  # an idle answer while walking is stale: keep walking
        if not 0 <= m.region < len(self.paths) or self._state is MdbsaState.IDLE:
            return
        self._via_depot = self._depot_point is not None and w is not None
        self._walk = _Walk(m, self.paths[m.region])
        if self._state is MdbsaState.DELIVERING:
            self._after_delivery = MdbsaState.TRAVELING
        else:
            self._state = MdbsaState.TRAVELING

    def _on_partner(self, m: WalkProgress) -> None:
        """The other walker of our region has been up to ``m.s``: our walk stops there at the latest."""
        w = self._walk
        if w is None or m.robot == self.robot or m.region != w.region or m.direction != -w.direction:
            return
        if math.isfinite(m.s):
            w.stop_at(m.s)

    def _on_carrying(self, carrying: bool) -> None:
        if carrying == self._carrying:
            return
        self._carrying = carrying
        if carrying:
            state = self._state
            if state is MdbsaState.DELIVERING:
                return
            if state is MdbsaState.SEARCHING:
                self._after_delivery = MdbsaState.RESUMING
            elif state in (MdbsaState.WAITING, MdbsaState.IDLE):
                self._after_delivery = MdbsaState.TO_CENTER
            else:
                self._after_delivery = state
            self._state = MdbsaState.DELIVERING
            self._reported_trip = False
        else:
            self._trips += 1
            if self._state is MdbsaState.DELIVERING:
                self._state = self._after_delivery

    def _go_idle(self, pose: Pose2D) -> None:
        """Idle for good: to the center of the region walked last (else the nearest one)."""
        if self._walk is not None:
            start = self.paths[self._walk.region].start
        else:
            start = min((p.start for p in self.paths),
                        key=lambda c: (c[0] - pose.x) ** 2 + (c[1] - pose.y) ** 2)
        self._idle_at = (float(start[0]), float(start[1]))
        self._walk = None
        self._state = MdbsaState.IDLE

    # ------------------------------------------------------------------ talking to the center

    def _report(self, obs: Observation, *, done: bool) -> None:
        w = self._walk
        self._outbox.append(ProgressReport(
            stamp_ns=obs.stamp_ns, robot=self.robot, x=float(obs.pose.x), y=float(obs.pose.y),
            region=w.region if w is not None else -1,
            s=float(w.s) if w is not None else 0.0, done=done))

    def _ask(self, obs: Observation) -> None:
        """Report the walk over (or ask for the first / next one) and wait for the answer."""
        self._report(obs, done=True)
        self._asked_at = obs.t
        self._asked_ns = obs.stamp_ns
        self._state = MdbsaState.WAITING

    def _d2_center(self, obs: Observation) -> float:
        return (obs.pose.x - self._center[0]) ** 2 + (obs.pose.y - self._center[1]) ** 2

    def _waiting(self, obs: Observation) -> None:
        """WAITING: ask again when no answer came in time, from within range (else drive back
        first)."""
        if obs.t < self._asked_at + ASK_RETRY - _EPS:
            return
        if self._d2_center(obs) <= self._range**2:
            self._ask(obs)
        else:
            self._state = MdbsaState.TO_CENTER

    # ------------------------------------------------------------------ states

    def _to_center(self, obs: Observation) -> tuple[float, float]:
        if self._d2_center(obs) <= self._ask_r2:
            self._ask(obs)
            return 0.0, 0.0
        pose = obs.pose
        return self._to_point(pose.x, pose.y, pose.yaw, *self._center)

    def _walk_over(self, obs: Observation) -> tuple[float, float]:
        self._state = MdbsaState.TO_CENTER
        return self._to_center(obs)

    def _searching(self, obs: Observation) -> tuple[float, float]:
        w = self._walk
        if w is None:
            return self._walk_over(obs)
        pose = obs.pose
        x, y = pose.x, pose.y
        wp, cum, n = w.wp, w.cum, len(w.wp)
        while w.next < n and cum[w.next] <= w.stop_u + _EPS:
            tx, ty = wp[w.next]
            if (tx - x) ** 2 + (ty - y) ** 2 >= self._wp_tol2:
                break
            w.u = max(w.u, cum[w.next])
            w.next += 1
        if w.next < n:
            self._project(w, x, y)
        if self._radio and (w.u - w.sent_u >= self._carrot - _EPS or (w.over and w.u > w.sent_u)):
            self._outbox.append(WalkProgress(obs.stamp_ns, self.robot, w.region, w.direction, float(w.s)))
            w.sent_u = w.u
        if w.over:
            return self._walk_over(obs)
        if obs.sensed.resources and not self._carrying:
            rx, ry = obs.sensed.resources[0]
            return self._to_point(x, y, pose.yaw, float(rx), float(ry))
        tx, ty = self._lane_target(w)
        return self._to_point(x, y, pose.yaw, tx, ty)

    @staticmethod
    def _project(w: _Walk, x: float, y: float) -> None:
        """Progress = projection onto the current leg, clamped to the leg and the stop."""
        k = w.next
        if k == 0:
            return
        ax, ay = w.wp[k - 1]
        bx, by = w.wp[k]
        dx, dy = bx - ax, by - ay
        seg2 = dx * dx + dy * dy
        if seg2 <= 0.0:
            return
        t = min(max(((x - ax) * dx + (y - ay) * dy) / seg2, 0.0), 1.0)
        u = min(w.cum[k - 1] + t * (w.cum[k] - w.cum[k - 1]), w.stop_u)
        if u > w.u:
            w.u = u

    def _lane_target(self, w: _Walk) -> tuple[float, float]:
        """`_carrot` ahead of the progress on the current leg, never past the leg or the stop."""
        k = w.next
        if k == 0:
            return w.wp[0]
        c0, c1 = w.cum[k - 1], w.cum[k]
        u = min(w.u + self._carrot, c1, w.stop_u)
        if c1 <= c0:
            return w.wp[k]
        (ax, ay), (bx, by) = w.wp[k - 1], w.wp[k]
        t = (u - c0) / (c1 - c0)
        return ax + t * (bx - ax), ay + t * (by - ay)

    def _to_walk(self, obs: Observation) -> tuple[float, float]:
        """TRAVELING / RESUMING: to the walk's progress point (a new walk after another: by way
        of `DEPOT_POINT`, with ``next_walk_at: depot``), then search from there."""
        w = self._walk
        if w is None or w.over:
            return self._walk_over(obs)
        pose = obs.pose
        if self._via_depot and self._state is MdbsaState.TRAVELING:
            assert self._depot_point is not None
            nx, ny = self._depot_point
            if (pose.x - nx) ** 2 + (pose.y - ny) ** 2 > DEPOT_POINT_HIT**2:
                return self._to_point(pose.x, pose.y, pose.yaw, nx, ny)
            self._via_depot = False
        tx, ty = (float(v) for v in w.path.point_at(w.u))
        if (tx - pose.x) ** 2 + (ty - pose.y) ** 2 < self._wp_tol2:
            w.next = max(w.path.next_waypoint_index(w.u), 1)
            self._state = MdbsaState.SEARCHING
            return self._searching(obs)
        return self._to_point(pose.x, pose.y, pose.yaw, tx, ty)

    def _delivering(self, obs: Observation) -> tuple[float, float]:
        pose = obs.pose
        x, y = pose.x, pose.y
        w = self._walk
        if not self.distributed:
            if (not self._reported_trip and w is not None and not w.over
                    and self._d2_center(obs) <= self._ask_r2):
                self._report(obs, done=False)
                self._reported_trip = True
            tx, ty = self._drops[0]
        elif w is not None and not w.over:
            tx, ty = self._drops[w.region]
        else:
            tx, ty = min(self._drops, key=lambda c: (c[0] - x) ** 2 + (c[1] - y) ** 2)
        if (tx - x) ** 2 + (ty - y) ** 2 < self._arrival2:
            return 0.0, 0.0  # inside the zone: the world drops it this tick or the next
        return self._to_point(x, y, pose.yaw, tx, ty)

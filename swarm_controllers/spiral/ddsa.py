"""The distributed deterministic spiral algorithm (DDSA) behaviour.

Lu & Luna, CRV 2023, Sec. III and Fig. 2 (../shared/papers/mdbsa_spiral_search.md), after
Fricke et al.'s DDSA: robot i of r walks its own square spiral of the interlocking set
(eqs. (1)-(2), `swarm_controllers.spiral.geometry.ddsa_path`) outward from the depot centre, carries
each resource it finds to the centre, goes back to where it found it and resumes the spiral.
No centre node is needed: the path depends only on (r, i, gap, arena), all in the scenario.

Choices where the paper leaves a detail open:

* **Robot numbering**: robot index k (``robot_k``) is DDSA robot i = k + 1 of r =
  ``robots.count`` (the paper's ids are 1-based).
* **Path**: ``ddsa_path(depot centre, r, i, gap, arena half-side - arena_margin)``, every robot's
  from the depot centre (reached anywhere in the depot) and out over the lower robots' first legs,
  as the authors' code walks it (``controller.spiral.ddsa_stem: shared``); ``own`` starts robot i
  at centre + (0, (i-1) g), where robot i-1's first leg ends, and drives there from its start
  cell. The path is walked leg by leg with `go_to_point_twist`
  toward the point ``controller.spiral.waypoint_gaps`` gaps (one, the DDSA authors' waypoint
  spacing) ahead of the progress on the current leg (the leg's end when nearer), so a robot
  pushed off its lane steers back onto it instead of cutting across to a far corner; a
  waypoint counts as reached within ``min(arrival_tolerance, gap / 4)`` so corners are not cut
  by more than a quarter of the line spacing.
* **Finding**: the world picks a resource up only within ``pickup_radius`` (0.05 m) while the
  paper's robots detect at 0.13 m and the lines are 0.18 m apart, so a searcher that sees a
  resource (``obs.sensed.resources``, nearest first) steers to the nearest one; otherwise a resource
  half-way between two lines would be seen and never collected. Once it disappears (picked up
  by us or someone else) the robot heads for its next waypoint again.
* **"Where it found it"** is the robot's *progress* along its path, an arc length s [m]: the
  arc length of the last waypoint reached plus the projection of the robot's position onto
  the current leg (clamped to the leg, never decreasing). The find position is s at the tick
  ``obs.sensed.carrying`` turns True. RESUMING drives straight to ``path.point_at(s)`` and SEARCHING
  continues from there, so the remaining resources of a cluster, seen from that point, are
  collected on the following trips. A pickup outside SEARCHING (driving over a resource while
  resuming) keeps the old s: the robot delivers it and resumes where it was.
* **Returning**: straight for the depot centre; the world drops the resource in the depot
  drop zone, and ``obs.sensed.carrying`` turning False completes a trip (trips += 1).
* **DONE** (the paper: "If a robot completes the search along its entire spiral path without
  finding a target, it returns to the center and awaits further instructions until the
  completion of the foraging task"): the robot stops where its path ends and stays there.
  DDSA has no centre that could ever send an instruction, so where it waits is the only
  thing the sentence decides, and the authors' code, which produced the paper's figures,
  waits where the pattern ends: ``DSA_controller::ReachSpiralTargets`` sets ``DSA = IDLE;
  Stop();`` once the pattern is empty (MARSLab-UTRGV/DDSA-Distributed-Deterministic-Spiral-
  Search-Algorithm, branch luki-dev, "The version for the submission", source/DSA/
  DSA_controller.cpp), as the lab's older DSA did with its return to the nest commented out
  (BCLab-UNM/iAnt-ARGoS, source/DSA/DSA_controller.cpp, ``ReachSpiralTargets``). Driving
  back into the depot instead parked the finished robots on the drop disc's rim where they
  walled off the carriers (issue 11, experiment 2 at 32 robots in the issue-4 world, seeds
  0-4: 8-10 robots parked there, 0-1 deliveries in the last 4 minutes, 1.18 ± 0.24
  resources per robot; stopping at the path's end: none there, 20-24 deliveries in the last
  4 minutes, 5.27 ± 0.31 per robot).
  A finished robot keeps obstacle avoidance on every tick as ``BaseController::Move`` does
  (`LaneAvoidance.parked`: it turns in place away from what comes at its front, never
  drives off). A finished robot that still picks something up (pushed onto a resource)
  delivers it and comes back to its path's end.
* **Obstacle avoidance**: `LaneAvoidance` while SEARCHING and on the last
  ``approach_radius`` of RESUMING (the find position may lie on an outer lane, 0.2 m from a
  wall, closer than the general avoidance lets a robot drive), the general scan avoidance with
  a fixed right turn (`ObstacleAvoidance(keep_right=True)`) and a straight escape run of one robot diameter
  (`AvoidThenEscape`) in every other moving state. Either has priority over the state machine
  and counts events. (CPFA keeps the free-side turn.)

Deterministic: the generator is accepted for the factory signature and never drawn from.

Searchers on adjacent lanes (issue 4). Near the centre adjacent rings are one gap (0.18 m)
apart for 0.17 m robots, so the general avoidance (0.3 m, 2 rad front sector) fired between
neighbours walking adjacent rings, and its turns pushed searchers off their own line into the
neighbour's stripe. The paper does not say how its robots avoid this (the ARGoS foot-bot
proximity sensors reach only ~0.1 m). Our fix: a searcher reacts only to what is *in its own
lane ahead* (body-frame hits with |y| < g/2, so a robot on the next lane, whose near side is
g - radius > g/2 away, is ignored) and *yields* (stops) instead of swerving; a lane still
blocked after `LANE_YIELD_TIMEOUT` (two searchers yielding to each other, a parked robot)
falls back to the general avoidance; and it steers back onto its lane (above). Distance from
a searcher to its own path, 8 robots, 12 min, seeds 0-7 (tested in test_ddsa.py on a shorter
run): mean 0.051 -> 0.003 m, max 0.72-1.15 -> 0.07-0.20 m (the largest in the first minute,
when all robots leave the crowded centre).

The general avoidance's trigger is the scenario's (``controller.avoidance``). Since issue 11 the
spiral scenarios use the authors' foot-bot trigger, 0.185 m from the centre in a +-37.5 deg
front sector (``BaseController::CollisionDetection``), instead of the default 0.3 m / 2 rad:
with the authors' 0.18 m nest the default kept carriers ringed around it (experiment 3, 16
robots, 300 resources, seed 0: 108 deliveries, 8 robots within 0.6 m of the centre in the last
minute; with the authors' trigger 190 and 1).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from enum import Enum

import numpy as np

from swarm_controllers.avoidance import ray_angles
from swarm_controllers.motion import Drive, drive_for
from swarm_controllers.spiral.config import SpiralConfig
from swarm_controllers.spiral.geometry import SpiralPath, ddsa_path
from swarm_msgs_py.types import (
    STOP,
    BehaviourStatus,
    Command,
    Observation,
    Pose2D,
    RobotId,
    robot_index,
)
from swarm_sim.scenario import Scenario

LANE_YIELD_TIMEOUT = 3.0
"""A searcher whose lane stays blocked this long [s, sim time] swerves after all."""


class LaneAvoidance:
    """Obstacle avoidance for a robot walking a spiral lane: yield to what is in the lane.

    Lanes are one gap g apart and the robots nearly as wide, so on its lane a robot watches
    only its own lane ahead: a hit r of a front-sector ray at angle a (the general avoidance's
    sector), at body-frame (x, y) = r (cos a, sin a), counts when 0 < x <= `lookahead` and
    |y| < g / 2. A robot walking the next lane has its near side g - radius from our line,
    beyond g / 2 whenever the robots are narrower than the gap, and is ignored. A blocked lane
    makes the robot stop (one avoidance event per yield episode); if it is still blocked after
    `yield_timeout` the general avoidance (`AvoidThenEscape` turning right,
    `ObstacleAvoidance(keep_right=True)`) takes over until its turn and escape run are done. Off the lane (``on_lane=False``) the general avoidance applies as is.
    Once the general avoidance has started an episode it keeps priority until the episode
    ends, so its state never goes stale between calls.
    """

    def __init__(self, scenario: Scenario, drive: Drive | None = None, *, lookahead: float | None = None,
                 yield_timeout: float = LANE_YIELD_TIMEOUT) -> None:
        """drive: the robot's motion layer, whose avoidance is the general one (default: the robot
        model's). lookahead [m from the robot's centre]: default one robot diameter (it must stay
        below ``controller.spiral.arena_margin`` so the wall beyond a lane's end does not
        block the lane). yield_timeout [s, sim time]."""
        r = scenario.robots
        drive = drive_for(scenario) if drive is None else drive
        self.general = drive.avoidance(r.diameter, keep_right=True)
        self.lookahead = r.diameter if lookahead is None else float(lookahead)
        self.approach_radius = scenario.controller.avoidance.distance + r.diameter / 2.0
        """A robot this close to a point of its lane [m] drives onto it in lane mode: the general
        avoidance keeps it `AvoidanceConfig.distance` from everything ahead, so it could never
        reach the outer lanes (``arena_margin`` = 0.2 m from the walls) head on."""
        self.half_width = SpiralConfig.of(scenario).gap / 2.0
        self.yield_timeout = float(yield_timeout)
        self.lane_yield = SpiralConfig.of(scenario).lane_yield
        """False: the lane rule is off and the general avoidance applies on the lane too."""
        self._collide = getattr(self.general, "collide", None) if SpiralConfig.of(scenario).lane_unjam else None
        """``controller.spiral.lane_unjam``: start the general avoidance's turn at a lane hit it missed.
        Only the foot-bot's `StopTurnGo` can miss one (its cone on the summed readings); the other
        avoidances detect a lane hit themselves and have no such method."""
        half_front = scenario.controller.avoidance.front_fov / 2.0 + 1e-12
        front = [(i, a) for i, a in enumerate(ray_angles(scenario.sensors.scan)) if abs(a) <= half_front]
        self._rays = [(i, math.cos(a), abs(math.sin(a))) for i, a in front]
        self._angles = [math.degrees(a) for _, a in front]
        self._yield_since: float | None = None
        self._yields = 0
        self._general_on = False

    @property
    def events(self) -> int:
        """Avoidance episodes so far: yields plus general avoidance turns."""
        return self._yields + self.general.events

    @property
    def yields(self) -> int:
        """Yield episodes so far."""
        return self._yields

    @property
    def yielding(self) -> bool:
        return self._yield_since is not None

    def lane_blocked(self, ranges: np.ndarray | Sequence[float]) -> bool:
        """Whether something is in the lane ahead (see the class docstring)."""
        for i, c, s in self._rays:
            v = float(ranges[i])
            if v < math.inf and 0.0 < v * c <= self.lookahead and v * s < self.half_width:
                return True
        return False

    def update(self, ranges: np.ndarray | Sequence[float], t: float, *,
               on_lane: bool) -> Command | None:
        """The command overriding the behaviour this tick, or None. t: sim time [s]."""
        if self._general_on or not on_lane or not self.lane_yield:
            self._yield_since = None
            return self._general(ranges)
        if not self.lane_blocked(ranges):
            self._yield_since = None
            return None
        if self._yield_since is None:
            self._yield_since = t
            self._yields += 1
        if t - self._yield_since < self.yield_timeout - 1e-9:  # stamps are ns: no drift
            return STOP
        self._yield_since = None
        command = self._general(ranges)
        if command is None and self._collide is not None:
            self._collide(self._lane_bearing(ranges))
            command = self._general(ranges)
        return STOP if command is None else command

    def _lane_bearing(self, ranges: np.ndarray | Sequence[float]) -> float:
        """The bearing [deg, body frame] of the nearest hit in the lane ahead."""
        best, bearing = math.inf, 0.0
        for (i, c, s), a in zip(self._rays, self._angles):
            v = float(ranges[i])
            if v < best and 0.0 < v * c <= self.lookahead and v * s < self.half_width:
                best, bearing = v, a
        return bearing

    def parked(self, ranges: np.ndarray | Sequence[float]) -> Command:
        """The command of a robot that stands still (path finished, waiting at or idle away
        from the center): a turn in place away from what its front sector sees
        (`AvoidThenEscape.turn_only`, counted as an avoidance event), else STOP. Called every
        tick it stands, so avoidance stays on in every state as in the authors' controllers."""
        self._yield_since = None
        self._general_on = False
        command = self.general.turn_only(ranges)
        return STOP if command is None else command

    def _general(self, ranges: np.ndarray | Sequence[float]) -> Command | None:
        command = self.general.update(ranges)
        self._general_on = command is not None
        return command


class DdsaState(Enum):
    """Fig. 2 of the paper, folded into the states a robot can be observed in."""

    SEARCHING = "searching"
    """Following the spiral (or steering to a resource seen from it)."""
    RETURNING = "returning"
    """Carrying a resource to the depot centre."""
    RESUMING = "resuming"
    """Driving back to the arc-length position of the last find."""
    DONE = "done"
    """Spiral finished: stopped where it ends (avoidance turns in place only)."""


class DdsaBehaviour:
    """One robot walking its DDSA spiral. See the module docstring for the rules and choices."""

    def __init__(self, scenario: Scenario, robot: RobotId,
                 rng: np.random.Generator | None = None) -> None:
        self.robot = robot
        r = scenario.robots.count
        i = robot_index(robot) + 1
        if not 1 <= i <= r:
            raise ValueError(f"{robot} is not one of the scenario's {r} robots")
        sp = SpiralConfig.of(scenario)
        half = scenario.arena.size / 2.0 - sp.arena_margin
        center = (float(scenario.depot.center[0]), float(scenario.depot.center[1]))
        shared = sp.ddsa_stem == "shared"
        self.path = SpiralPath(ddsa_path(center, r, i, sp.gap, half, include_shared_stem=shared))
        """This robot's spiral [m, world frame]."""
        self._wp = [(float(x), float(y)) for x, y in self.path.waypoints]
        self._cum = [float(c) for c in self.path.cumulative]
        self._drive = drive_for(scenario, rng)
        self._to_point = self._drive.to_point
        self._avoidance = LaneAvoidance(scenario, self._drive)
        tol = min(scenario.controller.arrival_tolerance, sp.gap / 4.0)
        self._wp_tol2 = tol**2
        self._start_tol2 = float(scenario.depot.radius) ** 2 if shared else self._wp_tol2
        """The path's first point counts as reached within this [m^2]: with the shared stem it is the
        depot centre, reached anywhere in the depot disc (``controller.spiral.ddsa_stem``)."""
        self._carrot = sp.gap * sp.waypoint_gaps
        self._arrival2 = scenario.controller.arrival_tolerance**2
        self._center = center

        self._state = DdsaState.SEARCHING
        self._next = 0
        """Index of the waypoint being driven to (len(waypoints) once the path is done)."""
        self._progress = 0.0
        """Arc length reached along the path [m]."""
        self._found_s: float | None = None
        """Arc length of the last find [m], until resumed."""
        self._carrying = False
        self._trips = 0
        self._stamp_ns = 0

    # ------------------------------------------------------------------ read-only views

    @property
    def state(self) -> DdsaState:
        return self._state

    @property
    def progress(self) -> float:
        """Arc length searched so far along the spiral [m]."""
        return self._progress

    @property
    def found_at(self) -> float | None:
        """Arc length of the last find [m], None once resumed (or before any find)."""
        return self._found_s

    @property
    def next_waypoint(self) -> int:
        return self._next

    @property
    def trips(self) -> int:
        return self._trips

    @property
    def obstacle_avoidance_events(self) -> int:
        return self._avoidance.events

    def status(self, stamp_ns: int | None = None) -> BehaviourStatus:
        return BehaviourStatus(
            robot=self.robot,
            stamp_ns=self._stamp_ns if stamp_ns is None else stamp_ns,
            state=self._state.name,
            obstacle_avoidance_events=self._avoidance.events,
            trips=self._trips,
            extra=(("progress", f"{self._progress:.3f}/{self.path.length:.3f}"),),
        )

    # ------------------------------------------------------------------ the tick

    def step(self, obs: Observation) -> Command:
        self._stamp_ns = obs.stamp_ns
        self._drive.begin(obs.stamp_ns)
        carrying = bool(obs.sensed.carrying)
        if carrying != self._carrying:
            self._carrying = carrying
            if carrying:
                if self._state is DdsaState.SEARCHING:
                    self._found_s = self._progress
                elif self._state is DdsaState.DONE:
                    self._found_s = self.path.length  # deliver, then back to the path's end
                self._state = DdsaState.RETURNING
            else:
                self._trips += 1
                if self._state is DdsaState.RETURNING:
                    self._state = DdsaState.RESUMING
        if self._state is DdsaState.RESUMING and self._found_s is None:
            self._state = DdsaState.SEARCHING  # picked up on the way out, nothing to resume
        state = self._state
        if state is DdsaState.DONE:
            return self._avoidance.parked(obs.ranges)
        on_lane = state is DdsaState.SEARCHING or (
            state is DdsaState.RESUMING and self._near_resume_point(obs.pose))
        override = self._avoidance.update(obs.ranges, obs.t, on_lane=on_lane)
        if state is DdsaState.SEARCHING:
            linear, angular = self._searching(obs)
        elif state is DdsaState.RESUMING:
            linear, angular = self._resuming(obs)
        else:
            linear, angular = self._to_depot(obs)
        if self._state is DdsaState.DONE:  # the path ended this tick
            return self._avoidance.parked(obs.ranges)
        return override if override is not None else Command(linear, angular)

    # ------------------------------------------------------------------ states

    def _searching(self, obs: Observation) -> tuple[float, float]:
        pose = obs.pose
        x, y = pose.x, pose.y
        wp, n = self._wp, len(self._wp)
        # Advance past every waypoint already reached (several on a degenerate path).
        while self._next < n:
            tx, ty = wp[self._next]
            if (tx - x) ** 2 + (ty - y) ** 2 >= (self._start_tol2 if self._next == 0 else self._wp_tol2):
                break
            self._progress = max(self._progress, self._cum[self._next])
            self._next += 1
        if self._next >= n:
            self._state = DdsaState.DONE
            return 0.0, 0.0
        self._update_progress(x, y)
        if obs.sensed.resources and not self._carrying:
            rx, ry = obs.sensed.resources[0]
            return self._to_point(x, y, pose.yaw, float(rx), float(ry))
        tx, ty = self._lane_target()
        return self._to_point(x, y, pose.yaw, tx, ty)

    def _lane_target(self) -> tuple[float, float]:
        """The point `_carrot` (one gap by default) ahead of the progress on the current leg (the
        leg's end when nearer): a robot pushed off its lane steers back onto it instead of cutting across
        to the far waypoint."""
        k = self._next
        bx, by = self._wp[k]
        if k == 0:
            return bx, by
        s = self._progress + self._carrot
        c0, c1 = self._cum[k - 1], self._cum[k]
        if s >= c1 or c1 <= c0:
            return bx, by
        ax, ay = self._wp[k - 1]
        t = (s - c0) / (c1 - c0)
        return ax + t * (bx - ax), ay + t * (by - ay)

    def _update_progress(self, x: float, y: float) -> None:
        """Project the robot onto the leg it is walking; progress never goes back."""
        k = self._next
        if k == 0:
            return  # still driving to the path's start
        ax, ay = self._wp[k - 1]
        bx, by = self._wp[k]
        dx, dy = bx - ax, by - ay
        seg2 = dx * dx + dy * dy
        if seg2 <= 0.0:
            return
        t = ((x - ax) * dx + (y - ay) * dy) / seg2
        t = min(max(t, 0.0), 1.0)
        s = self._cum[k - 1] + t * (self._cum[k] - self._cum[k - 1])
        if s > self._progress:
            self._progress = s

    def _near_resume_point(self, pose: Pose2D) -> bool:
        s = self._found_s if self._found_s is not None else self._progress
        tx, ty = self.path.point_at(s)
        return math.hypot(float(tx) - pose.x, float(ty) - pose.y) < self._avoidance.approach_radius

    def _resuming(self, obs: Observation) -> tuple[float, float]:
        pose = obs.pose
        s = self._found_s if self._found_s is not None else self._progress
        tx, ty = (float(v) for v in self.path.point_at(s))
        if (tx - pose.x) ** 2 + (ty - pose.y) ** 2 < (self._start_tol2 if s <= 0.0 else self._wp_tol2):
            self._found_s = None
            self._progress = s
            self._next = max(self.path.next_waypoint_index(s), 0)
            self._state = DdsaState.SEARCHING
            return self._searching(obs)
        return self._to_point(pose.x, pose.y, pose.yaw, tx, ty)

    def _to_depot(self, obs: Observation) -> tuple[float, float]:
        """RETURNING: to the centre (the world drops the resource in the depot disc)."""
        pose = obs.pose
        x, y = pose.x, pose.y
        cx, cy = self._center
        d2 = (cx - x) ** 2 + (cy - y) ** 2
        if d2 < self._arrival2:
            return 0.0, 0.0
        return self._to_point(x, y, pose.yaw, cx, cy)


def planned_paths(scenario: Scenario) -> list[np.ndarray]:
    """Every robot's spiral waypoints [m, world frame] (drawn under recorded trajectories)."""
    rng = np.random.default_rng(0)  # the path does not depend on it
    return [DdsaBehaviour(scenario, r, rng).path.waypoints for r in scenario.robot_names]

"""One robot's controller for collective transport by caging: Algs. 3-6 of the caging paper.

A `Phase` machine; each tick first reads the messages addressed to it, then acts:

- SEARCH (Alg. 3): drive to a random landmark, then to random neighbours eta(lambda) of each
  landmark reached (Fig. 1a), appending each to the trajectory T_i. A robot whose proximity
  sensor reports the object becomes the recruiter r*: it stops and sends type 0 with C_object
  and T_r* to every other robot. A robot that hears a type 0 is recruited (messages are read
  before the sensors, so a robot that detects the object while a type 0 is on its way yields to
  the earlier recruiter; two detections in the same tick: the lower robot index wins and the
  other yields when it hears it).
- APPROACH, WAIT_SUMMON (Alg. 4 lines 1-8): a recruited robot drives toward the object until
  D_object <= Delta and waits there for its type 1.
- TO_CAGE (Alg. 4 lines 9-15, Alg. 5 lines 1-5): to its cage position p_i* of eq. (5) by
  `cage_route` (around the object, not through it), p_i* recomputed every tick from the object's
  sensed centre; a recruited robot then sends type 2 to every other robot.
- SUMMONING (Alg. 5 lines 6-11): the recruiter, placed, summons the robots one by one in its
  order mu_r* with type 1 and waits for each one's type 2. mu_i is (i+1, i+2, ...) modulo rho,
  counter-clockwise around the cage from the recruiter's place (Alg. 2 leaves mu open). Beyond
  the paper: a robot silent for ``call_timeout`` is skipped.
- PLACED (Alg. 6 lines 1-7): a placed robot waits until every other recruited robot has sent
  type 2, or until it hears a type 3 (the recruiter only starts the transport once the cage is
  complete, skipped robots included).
- SPIN, WAIT_ORIENTED, MOVE, WAIT_REACHED (Alg. 6 lines 8-31), for every target of the planned
  path (`swarm_controllers.caging.plan`; by default T_r* reversed, ending at the recruiter's
  start p_r*^0): spin to face p_i+ (Fig. 1b), send type 3
  and wait for everyone's type 3; move to p_i+ (eq. (5) around the landmark) with the seven
  PIDs (`Formation`), send type 4 and wait for everyone's type 4. "Everyone" is the cage: r*
  and the robots that sent type 2. Beyond the paper: robots still silent ``barrier_timeout``
  after a robot started waiting are dropped from its cage.
- DONE once the last landmark is reached.

The transport path's first target is the last landmark the recruiter reached (the paper: "the
first landmark ... holds the position of that where the object has been detected").
"""

from __future__ import annotations

import math
from enum import Enum

import numpy as np

from swarm_controllers.caging import geometry
from swarm_controllers.caging.config import CagingConfig
from swarm_controllers.caging.landmarks import landmarks
from swarm_controllers.caging.motion import Formation, GoTo, Limits, Motion, Neighbour, Spin
from swarm_controllers.caging.plan import planned_path
from swarm_controllers.caging.protocol import Oriented, Positioned, Reached, Recruitment, Summon
from swarm_controllers.caging.task import OBJECT
from swarm_controllers.caging.world_config import TransportConfig
from swarm_msgs_py.types import NS_PER_S, BehaviourStatus, Command, Observation, RobotId, robot_index
from swarm_sim.scenario import Scenario

Point = tuple[float, float]


class Phase(Enum):
    SEARCH = "search"
    APPROACH = "approach"
    WAIT_SUMMON = "wait_summon"
    TO_CAGE = "to_cage"
    SUMMONING = "summoning"
    PLACED = "placed"
    SPIN = "spin"
    WAIT_ORIENTED = "wait_oriented"
    MOVE = "move"
    WAIT_REACHED = "wait_reached"
    DONE = "done"


class CagingBehaviour:
    def __init__(self, scenario: Scenario, robot: RobotId, rng: np.random.Generator) -> None:
        self.robot = robot
        self.index = robot_index(robot)
        self.robots: tuple[RobotId, ...] = tuple(scenario.robot_names)
        self.rho = len(self.robots)
        self._rng = rng
        cfg = self.config = CagingConfig.of(scenario)
        obj, w = TransportConfig.of(scenario).object, scenario.robots.diameter
        self.d = cfg.distance_tolerance
        limits = Limits(scenario.robots.max_linear_speed, scenario.robots.max_angular_speed, scenario.sim.dt,
                        math.radians(cfg.angle_tolerance))
        self.phi = geometry.cage_angle(self.rho)
        self.cage_radius = geometry.cage_radius(obj.radius, w, cfg.clearance)
        self.delta = geometry.approach_distance(obj.radius, w, cfg.approach_margin)
        self.ring = geometry.travel_radius(obj.radius, w, cfg.clearance)
        self.landmarks = landmarks(scenario)
        self._go = GoTo(cfg, limits)
        self._spin = Spin(cfg, limits)
        self._formation = Formation(cfg, limits, self.cage_radius)
        self._call_timeout_ns = round(cfg.call_timeout * NS_PER_S)
        self._barrier_timeout_ns = round(cfg.barrier_timeout * NS_PER_S)

        self.phase = Phase.SEARCH
        self.target = int(rng.integers(len(self.landmarks)))
        """The landmark lambda the search drives to."""
        self.trajectory: list[int] = []
        """T_i: the landmarks reached, in order."""
        self.start: Point | None = None
        """p_i^0, from the first observation."""
        self.recruiter: RobotId | None = None
        self._recruited_at: tuple[int, int] | None = None
        """(stamp, robot index) of the type 0 that made the recruiter known: earlier wins."""
        self.center: Point = (0.0, 0.0)
        """C_object: from the type 0, updated whenever the object is sensed."""
        self.path: list[Point] = []
        """The transport's targets (`swarm_controllers.caging.plan`)."""
        self.leg = 0
        self.cage: set[RobotId] = set()
        """r* and the robots that sent type 2 (minus those dropped after a timeout)."""
        self.positioned: set[RobotId] = set()
        self._summoned = False
        self._queue: list[RobotId] = []
        self._calling: tuple[RobotId, int] | None = None
        self.skipped: list[RobotId] = []
        self._oriented: dict[int, set[RobotId]] = {}
        self._reached: dict[int, set[RobotId]] = {}
        self._route: list[Point] = []
        self._waiting_since = 0
        self.dropped = 0
        self.ignored = 0
        """Messages addressed to this robot that made no sense (unknown origin, landmark)."""
        self._stamp = 0

    # ------------------------------------------------------------------ messages

    def _read(self, messages: tuple[object, ...]) -> Recruitment | None:
        """Take in what is addressed to this robot; returns the earliest type 0 heard."""
        first: Recruitment | None = None
        for m in messages:
            if getattr(m, "destination", None) != self.robot or not hasattr(m, "TYPE"):
                continue
            if m.origin not in self.robots or m.origin == self.robot:
                self.ignored += 1
            elif isinstance(m, Recruitment):
                if any(not 0 <= j < len(self.landmarks) for j in m.trajectory):
                    self.ignored += 1
                elif first is None or (m.stamp_ns, robot_index(m.origin)) < (first.stamp_ns, robot_index(first.origin)):
                    first = m
            elif isinstance(m, Summon):
                self._summoned = self._summoned or m.origin == self.recruiter
            elif isinstance(m, Positioned):
                self.positioned.add(m.origin)
                if self.recruiter is not None:
                    self.cage.add(m.origin)
            elif isinstance(m, Oriented):
                self._oriented.setdefault(m.leg, set()).add(m.origin)
            elif isinstance(m, Reached):
                self._reached.setdefault(m.leg, set()).add(m.origin)
        return first

    def _to_all(self, make) -> list[object]:
        """One message per other robot (the paper's "j = 0, ..., rho - 1 and j != i")."""
        return [make(j) for j in self.robots if j != self.robot]

    # ------------------------------------------------------------------ the tick

    def step(self, obs: Observation) -> Command:
        self._stamp = now = obs.stamp_ns
        pose = obs.pose
        if self.start is None:
            self.start = (pose.x, pose.y)
        bodies = {name: (x, y) for name, x, y in obs.sensed.bodies}
        if OBJECT in bodies:
            self.center = bodies[OBJECT]
        heard = self._read(obs.messages)
        if heard is not None:
            key = (heard.stamp_ns, robot_index(heard.origin))
            if self.phase is Phase.SEARCH or (self.recruiter == self.robot and key < self._recruited_at):
                self._recruited(heard, key)
        out: list[object] = []
        v, w = self._act(obs, pose, bodies, now, out)
        return Command(v, w, tuple(out))

    def _act(self, obs: Observation, pose, bodies: dict[RobotId, Point], now: int, out: list) -> tuple[float, float]:
        phase = self.phase
        if phase is Phase.SEARCH:
            if OBJECT in obs.sensed.proximity and OBJECT in bodies:
                self._become_recruiter(pose, now, out)
                return 0.0, 0.0
            v, w = self._go.step(pose, self.landmarks.position(self.target), self.d)
            if self._go.state is Motion.ARRIVED:
                self.trajectory.append(self.target)
                self.target = int(self._rng.choice(self.landmarks.neighbours[self.target]))
                self._go.reset()
            return v, w
        if phase is Phase.APPROACH:
            v, w = self._go.step(pose, self.center, self.delta)
            if self._go.state is Motion.ARRIVED:
                self.phase = Phase.WAIT_SUMMON
                return self._act(obs, pose, bodies, now, out)
            return v, w
        if phase is Phase.WAIT_SUMMON:
            if self._summoned:
                self._head_for_cage(pose)
                return self._act(obs, pose, bodies, now, out)
            return 0.0, 0.0
        if phase is Phase.TO_CAGE:
            return self._to_cage(pose, now, out)
        if phase is Phase.SUMMONING:
            self._summon(now, out)
            return 0.0, 0.0
        if phase is Phase.PLACED:
            others = set(self.robots) - {self.robot, self.recruiter}
            if others <= self.positioned or self._oriented.get(0):
                self._start_leg(0)
            return 0.0, 0.0
        if phase is Phase.SPIN:
            target = self._place(self.path[self.leg])
            v, w = self._spin.step(pose, target)
            if self._spin.state is Motion.ALIGNED or math.hypot(target[0] - pose.x, target[1] - pose.y) <= self.d:
                out += self._to_all(lambda j: Oriented(now, self.robot, j, self.leg))
                self.phase, self._waiting_since = Phase.WAIT_ORIENTED, now
                return self._act(obs, pose, bodies, now, out)
            return v, w
        if phase is Phase.WAIT_ORIENTED:
            if self._everyone(self._oriented, now):
                self.phase = Phase.MOVE
                self._formation.reset()
                return self._act(obs, pose, bodies, now, out)
            return 0.0, 0.0
        if phase is Phase.MOVE:
            v, w = self._formation.step(pose, self._place(self.path[self.leg]), bodies.get(OBJECT),
                                        self._neighbours(bodies))
            if self._formation.state is Motion.ARRIVED:
                out += self._to_all(lambda j: Reached(now, self.robot, j, self.leg))
                self.phase, self._waiting_since = Phase.WAIT_REACHED, now
                return self._act(obs, pose, bodies, now, out)
            return v, w
        if phase is Phase.WAIT_REACHED:
            if self._everyone(self._reached, now):
                if self.leg + 1 < len(self.path):
                    self._start_leg(self.leg + 1)
                else:
                    self.phase = Phase.DONE
            return 0.0, 0.0
        return 0.0, 0.0

    # ------------------------------------------------------------------ stages

    def _become_recruiter(self, pose, now: int, out: list) -> None:
        """Alg. 3 line 7: found := true; r* := i; type 0 to every other robot."""
        self.recruiter = self.robot
        self._recruited_at = (now, self.index)
        self.cage = {self.robot}
        self._set_path(self.trajectory, self.start)
        sx, sy = self.start
        cx, cy = self.center
        out += self._to_all(lambda j: Recruitment(now, self.robot, j, cx, cy, sx, sy, tuple(self.trajectory)))
        self._queue = [self.robots[(self.index + k) % self.rho] for k in range(1, self.rho)]
        self._head_for_cage(pose)

    def _recruited(self, m: Recruitment, key: tuple[int, int]) -> None:
        """Alg. 3 line 13: r* := msg.origin; C_object := msg.payload."""
        self.recruiter = m.origin
        self._recruited_at = key
        self.center = (m.object_x, m.object_y)
        self.cage = {m.origin}
        self._set_path(list(m.trajectory), (m.start_x, m.start_y))
        self._queue, self._calling, self._route = [], None, []
        self.phase = Phase.APPROACH
        self._go.reset()

    def _set_path(self, trajectory: list[int], start: Point) -> None:
        self.path = planned_path(self.landmarks, trajectory, start, self.config.plan)

    def _place(self, center: Point) -> Point:
        """Eq. (5) around `center`: p_i* around the object, p_i+ around a landmark."""
        a = self.index * self.phi
        return (center[0] + self.cage_radius * math.cos(a), center[1] + self.cage_radius * math.sin(a))

    def _head_for_cage(self, pose) -> None:
        self._route = geometry.cage_route((pose.x, pose.y), self.center, self.index * self.phi, self.ring)
        self._go.reset()
        self.phase = Phase.TO_CAGE

    def _to_cage(self, pose, now: int, out: list) -> tuple[float, float]:
        while True:
            final = not self._route
            target = self._place(self.center) if final else self._route[0]
            v, w = self._go.step(pose, target, self.d)
            if self._go.state is not Motion.ARRIVED:
                return v, w
            self._go.reset()
            if final:
                break
            self._route.pop(0)
        self.positioned.add(self.robot)
        self.cage.add(self.robot)
        if self.recruiter == self.robot:
            self.phase = Phase.SUMMONING
            self._summon(now, out)
        else:
            out += self._to_all(lambda j: Positioned(now, self.robot, j))
            self.phase = Phase.PLACED
        return 0.0, 0.0

    def _summon(self, now: int, out: list) -> None:
        """Alg. 5 lines 6-11: type 1 to mu_r*j, wait for its type 2, next."""
        while True:
            if self._calling is not None:
                robot, since = self._calling
                if robot in self.positioned:
                    self._calling = None
                elif now - since >= self._call_timeout_ns:
                    self.skipped.append(robot)
                    self._calling = None
                else:
                    return
            if not self._queue:
                self._start_leg(0)
                return
            robot = self._queue.pop(0)
            out.append(Summon(now, self.robot, robot))
            self._calling = (robot, now)

    def _start_leg(self, leg: int) -> None:
        self.leg = leg
        self.phase = Phase.SPIN
        self._spin.reset()

    def _everyone(self, heard: dict[int, set[RobotId]], now: int) -> bool:
        """Whether every other robot of the cage has sent this leg's message; after the barrier
        timeout the silent ones are dropped from the cage."""
        missing = self.cage - {self.robot} - heard.get(self.leg, set())
        if not missing:
            return True
        if now - self._waiting_since >= self._barrier_timeout_ns:
            self.cage -= missing
            self.dropped += len(missing)
            return True
        return False

    def _neighbours(self, bodies: dict[RobotId, Point]) -> list[Neighbour]:
        """The cage's left (next counter-clockwise) and right neighbours, if sensed."""
        ring = sorted(self.cage, key=robot_index)
        if len(ring) < 2:
            return []
        k = ring.index(self.robot)
        out = []
        for side, other in ((1, ring[(k + 1) % len(ring)]), (-1, ring[(k - 1) % len(ring)])):
            if other not in bodies:
                continue
            steps = (side * (robot_index(other) - self.index)) % self.rho
            separation = steps * self.phi
            chord = 2.0 * self.cage_radius * math.sin(separation / 2)
            out.append(Neighbour(bodies[other], chord, separation, side))
        return out

    @property
    def finished(self) -> bool:
        """The transport is over for this robot (`swarm_sim.scenario.SimConfig.stop_when_finished`)."""
        return self.phase is Phase.DONE

    # ------------------------------------------------------------------ status

    def status(self, stamp_ns: int | None = None) -> BehaviourStatus:
        extra = (
            ("recruiter", self.recruiter or ""),
            ("leg", f"{self.leg}/{len(self.path)}"),
            ("cage", str(len(self.cage))),
            ("skipped", " ".join(self.skipped)),
            ("dropped", str(self.dropped)),
            ("ignored_messages", str(self.ignored)),
        )
        return BehaviourStatus(self.robot, self._stamp if stamp_ns is None else stamp_ns, self.phase.value, 0, 0, extra,
                               self.finished)

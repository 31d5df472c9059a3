"""The world core: one pybullet client, the whole swarm, stepped one control tick at a time.

Shaped like Crazyswarm2's simulation backend and PettingZoo's parallel API:
``step(commands) -> observations``, both dicts keyed by robot. No ROS here; the world node and
the batch runner both drive this class.

Physics. The arena is a square of side L centred at the origin, closed by four static box
walls just outside it, with optional static box/cylinder obstacles. There is no gravity and no
ground: robots are upright cylinders floating at z = height/2 under kinematic-ish velocity
control. Every physics substep sets each robot's base velocity to (v cos yaw, v sin yaw, vz) and
(0, 0, w) (unless pybullet already holds exactly that: `World._set_velocities`) and lets
pybullet resolve contacts, so robots push each other and stop at walls.
Tipping is prevented by a huge roll/pitch inertia and zero friction/damping (measured: tilt
below 1e-9; a planar robot's, `PLANAR_TILT_INERTIA`, keeps it below 1e-30); contact normals
are horizontal, so yaw changes only by the commanded turn rate, which is why later substeps predict the heading (yaw + w * j * dt_sub) instead of reading it
back. Contact solving leaves a tiny z drift (measured: ~5e-6 m over 100 s of a crowded
16-robot run, ~5e-5 m for 112 robots pushing into each other); the first substep of each tick
adds the vz that returns the body to z = height/2. Robot-robot contact is counted every substep
from pybullet's contact points (distance <= CONTACT_TOLERANCE).

A world task may add bodies of its own after the robots, walls and obstacles (the transport
task's target object, pushed by the robots) and act after every physics substep through an
``after_substep(h)`` hook (e.g. the object's floor friction); it may also choose where the
robots start (`place_robots`, while the world builds tick 0). Robot mass and size come from the
scenario (``robots.mass``, ``robots.diameter``).

Determinism. Everything random comes from ``numpy.random.SeedSequence(seed)``, split into
independent streams (start headings, odometry noise, and two for the world task: for foraging
resources and respawns), so switching odometry noise on does not move the resources. pybullet runs with deterministic overlapping
pairs and a fresh simulation per `reset`, so the same seed and the same command sequence give
bit-identical observations.

Order within a tick: commands are applied (missing robot: previous command; NaN/inf -> 0 and
above-limit -> limit, both counted in ``stats.clamped_commands``), the physics substeps run
(robot-robot contacts counted each substep; before them, the collision time of every robot
whose last observation's proximity ring saw something ahead), the pose is read, odometry is integrated, then
the world task does its bookkeeping (`swarm_sim.world.tasks`; foraging: drops and pick-ups,
robots in index order). Its events are stamped with the new tick's time, which is also the
stamp of the observations `step` returns.
"""

from __future__ import annotations

import math
from collections import deque
from collections.abc import Callable, Collection, Mapping
from itertools import repeat
from operator import attrgetter

import numpy as np

from swarm_msgs_py.geometry import wrap_angle, yaw_to_quaternion
from swarm_msgs_py.types import Command, Observation, Pose2D, RobotId, RobotStats
from swarm_sim.scenario import Scenario
from swarm_sim.world import bullet
from swarm_sim.world.bullet import pybullet as p
from swarm_sim.world.jit import inline, kernel
from swarm_sim.world.observations import observations
from swarm_sim.world.pairs import RobotPairs
from swarm_sim.world.proximity import ProximityRing
from swarm_sim.world.raycast import StaticScene, cast_scan, cast_scan_pybullet
from swarm_sim.world.start import start_positions
from swarm_sim.world.tasks import WorldTask

TaskFactory = Callable[["World", tuple[np.random.SeedSequence, np.random.SeedSequence]], WorldTask]
"""Builds a task for a world being built: (world, the task's two seed sequences); beside `World`
so the tasks' protocol (`swarm_sim.world.tasks`) needs nothing of the world."""
TILT_INERTIA = 1e6
"""Roll and pitch inertia [kg m^2] of a robot that is not planar (``robots.planar``; the generic
robot): large enough that contacts never tip it, though they leave tilts below 1e-9 (and turning
while so tilted adds ~1e-12 rad/s to its angular velocity). A planar robot's is
`PLANAR_TILT_INERTIA`, as no authors' platform tilts robots (ARGoS's dynamics2d is planar)."""
PLANAR_TILT_INERTIA = 1e30
"""Roll and pitch inertia [kg m^2] of a planar robot (``robots.planar``; every platform model): its
tilt stays below 1e-30 rad (measured, 112 robots crowding in Q_MT: 8.5e-31), so it never tilts in
any sense a float can tell from its heading, and a robot that touches nothing keeps the velocity it
was given bit for bit while it turns (measured: 64,234 checks, none off), so its velocity is only
re-set after contacts (`World._velocities_kept`). Not infinite: Bullet's multibody then computes
NaN; not 1e300: its products underflow to subnormal floats, which tripled the physics' time."""
CONTACT_TOLERANCE = 1e-3
"""Two robots whose pybullet contact distance is at most this [m] are in contact (pybullet also
reports points a few mm apart that it merely watches)."""
TILT_RESET = 1e-6
"""If a robot's orientation quaternion x or y component exceeds this it is reset upright."""
ROBOT_COLLISION_MARGIN = 0.04
"""Bullet collision margin of the robot cylinders [m]. A cylinder's margin lies inside its
dimensions (only its top and bottom rims get rounded), so its circle in the plane is unchanged;
the larger margin lets pybullet resolve most robot-robot contacts without its costly
penetration solver (EPA). Measured with 112 robots all pushing into the depot: physics 11.5 ->
3.3 ms per tick (as cheap as sphere-shaped robots), with CONTACT_ERP."""
CONTACT_ERP = 0.8
"""Fraction of a contact's penetration corrected per substep. With pybullet's default 0.2,
robots pushing into a jammed crowd sank ~3 mm (up to 2 cm) into each other; with 0.8 ~1 mm (up
to 3 mm). (Two robots meeting head-on at full speed can still overlap by one substep's travel,
2 x 0.16 m/s x 0.05 s = 1.6 cm, before pybullet sees the contact.)"""
SOLVER_ITERATIONS = 10
"""pybullet constraint solver iterations per substep (its default, 50, buys nothing here)."""

_LINEAR, _ANGULAR = attrgetter("linear"), attrgetter("angular")


_M_TRIM_THRESHOLD, _M_MMAP_THRESHOLD = -1, -3
_malloc_tuned = False


def tune_malloc() -> None:
    """Stop glibc from handing freed heap back to the OS after every tick.

    By default glibc trims the heap top whenever 128 KiB are free and serves blocks above 128 KiB
    with mmap, so the ~100 KB numpy temporaries of the batched scan page-fault afresh on every
    tick; that doubled the scan's cost for a crowded swarm (measured 1.48 -> 0.75 ms for 112
    robots). Keeping up to 64 MiB (and mmap only above 16 MiB) costs at most that much resident
    memory. Process-wide, idempotent; a no-op where glibc is absent.

    So it is called by what owns a simulation process, never by a constructor (a library or a
    test that builds a `World` changes nothing process-wide): the world node's `main`, the batch
    and sweep runs' job (`swarm_sim.batch.run_one`, in the worker process that runs it), the
    caging corners' workers, and the benchmarks that time a world.
    """
    global _malloc_tuned
    if _malloc_tuned:
        return
    _malloc_tuned = True
    try:
        import ctypes

        libc = ctypes.CDLL("libc.so.6")
        libc.mallopt(_M_TRIM_THRESHOLD, 64 << 20)
        libc.mallopt(_M_MMAP_THRESHOLD, 16 << 20)
    except (OSError, AttributeError):
        pass


@kernel
def _stale_rows(
    v: np.ndarray, cos_yaw: np.ndarray, sin_yaw: np.ndarray, vz: np.ndarray, w: np.ndarray,
    held: np.ndarray, kept: np.ndarray, stale: np.ndarray,
) -> int:
    """The substep's base velocity of every robot i, (v cos yaw, v sin yaw, vz, w), compared bit
    for bit with row i of `held`: the robots whose velocity differs, or whom pybullet does not
    keep (`kept` False), get it written into `held` and are listed in `stale`; returns how many.
    Each product is the one IEEE multiply numpy did (`swarm_sim.world.jit`), the cosines and sines
    are numpy's, computed outside; the comparison is bit for bit (`_differ`: 0.0 is not -0.0)."""
    k = 0
    for i in range(v.shape[0]):
        row = (v[i] * cos_yaw[i], v[i] * sin_yaw[i], vz[i], w[i])
        set_it = not kept[i]
        for c in range(4):
            if _differ(row[c], held[i, c]):
                set_it = True
        if set_it:
            for c in range(4):
                held[i, c] = row[c]
            stale[k] = i
            k += 1
    return k


@inline
def _differ(a: float, b: float) -> bool:
    """Whether two velocities differ bit for bit: in value, or 0.0 against -0.0 (a NaN differs from
    everything; no velocity is NaN)."""
    return a != b or (a == 0.0 and math.copysign(1.0, a) != math.copysign(1.0, b))


class World:
    """One object owns the pybullet client (p.DIRECT) and passes its id to every call.

    Crazyswarm2-like backend: ``step(commands) -> observations``; PettingZoo-like dicts keyed by
    robot. The experiment's world logic is the `task` (default: the one the scenario's
    algorithm registers), rebuilt with the world at every reset. `scan_threads` is
    rayTestBatch's numThreads for the pybullet scan backend.
    """

    def __init__(
        self, scenario: Scenario, task: TaskFactory, seed: int | None = None, *, scan_threads: int = 1,
    ) -> None:
        self.scenario = scenario
        self.seed = scenario.seed if seed is None else seed
        self.robots: tuple[RobotId, ...] = tuple(scenario.robot_names)
        self._index = {r: i for i, r in enumerate(self.robots)}
        self._n = len(self.robots)
        self._dt = scenario.sim.dt
        self._dt_ns = scenario.dt_ns
        self._substeps = scenario.sim.physics_substeps
        self._h = self._dt / self._substeps
        rc = scenario.robots
        self._radius = rc.diameter / 2
        self._z0 = rc.height / 2
        self._planar = bool(rc.planar)
        self._vmax = rc.max_linear_speed
        self._wmax = rc.max_angular_speed
        noise = rc.odometry_noise
        self._noisy = noise.linear_std != 0.0 or noise.angular_std != 0.0
        self._scene = StaticScene.from_scenario(scenario)
        self._ring = ProximityRing(scenario)
        self._scan_threads = scan_threads
        self._task_factory = task
        self._client: int | None = bullet.connect(p.DIRECT)
        try:
            self._build()
        except BaseException:
            self.close()  # e.g. a ScenarioError from resource placement: do not leak the client
            raise

    # ------------------------------------------------------------------ building

    def _build(self) -> None:
        """(Re)create the whole simulation for tick 0 from the seed."""
        cid = self._cid
        s = self.scenario
        p.resetSimulation(physicsClientId=cid)
        p.setGravity(0, 0, 0, physicsClientId=cid)
        p.setTimeStep(self._h, physicsClientId=cid)
        p.setPhysicsEngineParameter(
            deterministicOverlappingPairs=1, numSolverIterations=SOLVER_ITERATIONS,
            contactERP=CONTACT_ERP, physicsClientId=cid,
        )
        # Four independent streams of the run's seed: the start headings, the odometry noise and
        # two that belong to the task (for foraging: resource placement and respawns).
        seeds = np.random.SeedSequence(self.seed).spawn(4)
        rng_start, self._rng_odometry = (np.random.default_rng(x) for x in seeds[1:3])
        task_seeds = (seeds[0], seeds[3])

        # Robots first, so their body ids are 0..n-1.
        n = self._n
        yaws = rng_start.uniform(-math.pi, math.pi, size=n)
        if s.robots.start_layout == "groups":
            yaws[:] = 0.0  # ARGoS <orientation method="constant" values="0.0, 0.0, 0.0"/>
        starts = start_positions(s, rng_start).tolist()
        shape = p.createCollisionShape(
            p.GEOM_CYLINDER, radius=self._radius, height=s.robots.height, physicsClientId=cid
        )
        mass = s.robots.mass
        izz = 0.5 * mass * self._radius**2
        tilt = PLANAR_TILT_INERTIA if s.robots.planar else TILT_INERTIA
        self._bodies: list[int] = []
        for i, (x, y) in enumerate(starts):
            body = p.createMultiBody(
                mass, shape, -1, [x, y, self._z0], yaw_to_quaternion(float(yaws[i])),
                physicsClientId=cid,
            )
            p.changeDynamics(
                body, -1, lateralFriction=0.0, spinningFriction=0.0, rollingFriction=0.0,
                restitution=0.0, linearDamping=0.0, angularDamping=0.0,
                localInertiaDiagonal=[tilt, tilt, izz],
                activationState=p.ACTIVATION_STATE_DISABLE_SLEEPING,
                collisionMargin=min(ROBOT_COLLISION_MARGIN, self._radius / 2), physicsClientId=cid,
            )
            self._bodies.append(body)
        if self._bodies != list(range(n)):
            raise RuntimeError(f"pybullet gave robot bodies ids {self._bodies[:3]}..., expected 0..n-1")

        # Walls just outside the arena, long enough to close the corners.
        half, t, height = s.arena.size / 2, s.arena.wall_thickness, s.robots.height
        for (x, y), extents in (
            ((half + t / 2, 0.0), (t / 2, half + t, height / 2)),
            ((-half - t / 2, 0.0), (t / 2, half + t, height / 2)),
            ((0.0, half + t / 2), (half + t, t / 2, height / 2)),
            ((0.0, -half - t / 2), (half + t, t / 2, height / 2)),
        ):
            self._static_box((x, y), extents, 0.0)
        for o in s.obstacles:
            if o.shape == "box":
                self._static_box(o.center, (o.size[0] / 2, o.size[1] / 2, height / 2), o.yaw)
            else:
                col = p.createCollisionShape(
                    p.GEOM_CYLINDER, radius=o.size[0] / 2, height=height, physicsClientId=cid
                )
                p.createMultiBody(0.0, col, -1, [o.center[0], o.center[1], self._z0], physicsClientId=cid)

        self._v = np.zeros(n)
        self._w = np.zeros(n)
        self._contact_substeps = np.zeros(n, dtype=np.int64)
        self._avoidance_ticks = np.zeros(n, dtype=np.int64)
        self._ring_ahead = np.zeros(n, dtype=bool)
        """Whose proximity ring saw something ahead in the last observations."""
        self._held = np.zeros((n, 4))
        """The base velocities last set: vx, vy, vz, w (`_set_velocities`)."""
        self._stale = np.empty(n, dtype=np.intp)
        """`_set_velocities`' scratch: the rows to set."""
        self._kept = np.zeros(n, dtype=bool)
        """Whose velocity pybullet still holds exactly as in `_held`."""
        self._upright = np.zeros(n, dtype=bool)
        """Whose orientation is exactly upright (x = y = 0) since the last read-back."""
        self._pairs = RobotPairs(s.sensors.scan.range_max + self._radius)
        """The analytic scan's robot pairs, kept from tick to tick."""
        self.stats: dict[RobotId, RobotStats] = {r: RobotStats() for r in self.robots}
        self.tick = 0
        self._read_state()
        self._odo = np.column_stack([self._pos, self._yaw])
        self._meas_v = np.zeros(n)
        self._meas_w = np.zeros(n)
        self._obs_cache: dict[RobotId, Observation] | None = None
        self.task: WorldTask = self._task_factory(self, task_seeds)
        self._fresh = True

    def _static_box(
        self, center: tuple[float, float], half_extents: tuple[float, float, float], yaw: float
    ) -> None:
        cid = self._cid
        col = p.createCollisionShape(p.GEOM_BOX, halfExtents=list(half_extents), physicsClientId=cid)
        p.createMultiBody(
            0.0, col, -1, [center[0], center[1], self._z0], yaw_to_quaternion(yaw), physicsClientId=cid
        )

    @property
    def _cid(self) -> int:
        if self._client is None:
            raise RuntimeError("the world is closed")
        return self._client

    @property
    def client(self) -> int:
        """The pybullet client id (for cross-checks and debugging)."""
        return self._cid

    # ------------------------------------------------------------------ state

    def _read_state(self) -> None:
        """Read every robot's true pose from pybullet into `_pos` (n, 2), `_z`, `_yaw`."""
        cid = self._cid
        get = p.getBasePositionAndOrientation
        flat: list[float] = []
        extend = flat.extend
        for body in self._bodies:
            pos, orn = get(body, cid)
            extend(pos)
            extend(orn)
        a = np.array(flat).reshape(self._n, 7)
        qx, qy, qz, qw = a[:, 3], a[:, 4], a[:, 5], a[:, 6]
        self._pos = a[:, :2].copy()
        self._z = a[:, 2].copy()
        self._yaw = np.arctan2(2.0 * (qw * qz + qx * qy), 1.0 - 2.0 * (qy * qy + qz * qz))
        self._upright = (qx == 0.0) & (qy == 0.0)
        tilted = np.nonzero((np.abs(qx) > TILT_RESET) | (np.abs(qy) > TILT_RESET))[0]
        self._kept[tilted] = False  # resetting the pose zeroes the velocity
        for i in tilted.tolist():
            p.resetBasePositionAndOrientation(
                self._bodies[i], [self._pos[i, 0], self._pos[i, 1], self._z0],
                yaw_to_quaternion(float(self._yaw[i])), physicsClientId=cid,
            )
            self._z[i] = self._z0

    @property
    def positions(self) -> np.ndarray:
        """(n, 2) true robot positions [m, world frame] in robot order (read-only view for tasks)."""
        return self._pos

    @property
    def odometry_positions(self) -> np.ndarray:
        """(n, 2) the odometry positions of the current tick's observations [m, world frame],
        in robot order (read-only view: ``Observation.pose`` x and y, without building them)."""
        return self._odo[:, :2]

    @property
    def headings(self) -> np.ndarray:
        """(n,) true robot yaws [rad, world frame] in robot order (read-only view for tasks)."""
        return self._yaw

    @property
    def scan_ranges(self) -> np.ndarray:
        """(n, rays) the current tick's scan ranges [m, float32, from the robots' centres], in
        robot order (read-only: the rows the observations hold)."""
        if self._obs_cache is None:
            self.observe()
        return self._ranges

    @property
    def ring(self) -> ProximityRing:
        """The proximity ring the world counts collision time with (`swarm_sim.world.proximity`)."""
        return self._ring

    @property
    def dt_ns(self) -> int:
        """The control tick [ns]."""
        return self._dt_ns

    def drain_events(self) -> list:
        """The task's events since the last drain (pick-ups, drops, ...), in order."""
        return self.task.drain_events()

    @property
    def t_ns(self) -> int:
        """Sim time of the current tick [ns]."""
        return self.tick * self._dt_ns

    # ------------------------------------------------------------------ API

    def reset(self) -> dict[RobotId, Observation]:
        """Back to tick 0 (same seed, fresh pybullet simulation); its observations."""
        if not self._fresh:
            self._build()
        return self.observe()

    def step(self, commands: Mapping[RobotId, Command]) -> dict[RobotId, Observation]:
        """Apply `commands`, advance one tick, return the new tick's observations (see `observe`)."""
        try:
            idx = np.fromiter(map(self._index.__getitem__, commands), np.intp, len(commands))
        except KeyError as exc:
            raise ValueError(
                f"unknown robot id {exc.args[0]!r} (this world has robot_0..robot_{self._n - 1})"
            ) from None
        if len(idx):
            self._apply_commands(idx, commands.values())
        self._fresh = False
        if self._obs_cache is None:
            self.observe()  # the observations these commands answer (tick 0 without a reset)
        self._count_avoidance()
        self._obs_cache = None
        pos0, yaw0 = self._pos, self._yaw
        self._physics()
        self._read_state()
        self._odometry(pos0, yaw0)
        self.task.post_step((self.tick + 1) * self._dt_ns)
        self.tick += 1
        return self.observe()

    def _apply_commands(self, idx: np.ndarray, commands: Collection[Command]) -> None:
        """Store the commanded (v, w) of robots `idx`, NaN/inf -> 0 and clamped to the limits."""
        n = len(idx)
        vw = np.empty((n, 2))
        vw[:, 0] = np.fromiter(map(_LINEAR, commands), float, n)  # C-level loops: 1000 robots, 110 -> 50 us
        vw[:, 1] = np.fromiter(map(_ANGULAR, commands), float, n)
        limits = (self._vmax, self._wmax)
        bad = ~(np.abs(vw) <= limits)  # NaN compares False: bad too
        if bad.any():
            vw[~np.isfinite(vw)] = 0.0
            np.clip(vw, np.negative(limits), limits, out=vw)
            for i in idx[bad.any(axis=1)].tolist():
                self.stats[self.robots[i]].clamped_commands += 1
        self._v[idx] = vw[:, 0]
        self._w[idx] = vw[:, 1]

    def _count_avoidance(self) -> None:
        """One more tick of collision time for every robot that acted on a ring reading ahead
        (`swarm_sim.world.proximity`)."""
        if self._ring_ahead.any():
            self._avoidance_ticks += self._ring_ahead
            dt, stats, names = self._dt, self.stats, self.robots
            ahead = np.flatnonzero(self._ring_ahead)
            for i, ticks in zip(ahead.tolist(), self._avoidance_ticks[ahead].tolist()):
                stats[names[i]].avoidance_time_s = ticks * dt  # a Python int: the same float as numpy's

    def _physics(self) -> None:
        """Run the substeps; count robot-robot contact per substep."""
        cid = self._cid
        n, h = self._n, self._h
        step = p.stepSimulation
        contacts = p.getContactPoints
        touched_any: set[int] = set()
        after_substep = getattr(self.task, "after_substep", None)
        turning = self._w != 0.0
        no_climb = np.zeros(n)
        for j in range(self._substeps):
            yaw = self._yaw + self._w * (j * h) if j else self._yaw
            self._set_velocities(np.cos(yaw), np.sin(yaw), (self._z0 - self._z) / h if j == 0 else no_climb)
            step(physicsClientId=cid)
            if after_substep is not None:
                after_substep(h)
            touching = np.zeros(n, dtype=bool)  # any contact point, with anything
            touched: set[int] = set()
            for cp in contacts(physicsClientId=cid):
                a_body, b_body = cp[1], cp[2]
                if a_body < n:
                    touching[a_body] = True
                if b_body < n:
                    touching[b_body] = True
                if a_body < n and b_body < n and cp[8] <= CONTACT_TOLERANCE:
                    touched.add(a_body)
                    touched.add(b_body)
            for i in touched:
                self._contact_substeps[i] += 1
            touched_any |= touched
            self._upright &= ~touching
            self._kept = self._velocities_kept(turning, touching) if after_substep is None else np.zeros(n, dtype=bool)
        for i in touched_any:
            self.stats[self.robots[i]].collision_time_s = float(self._contact_substeps[i]) * h

    def _set_velocities(self, cos_yaw: np.ndarray, sin_yaw: np.ndarray, vz: np.ndarray) -> None:
        """Set robot i's base velocity to (v cos yaw, v sin yaw, vz), (0, 0, w), unless pybullet
        already holds exactly that (`_velocities_kept`); `_held` keeps what was last set.

        A robot that stands still, turns in place or drives straight is given the same velocity
        substep after substep, and each call costs ~0.7 us. Replaying 1000-robot runs' commands
        (ticks 600-799, CPU time): CPFA 3.6 -> 2.8 ms a tick for the physics, pybullet's
        stepSimulation included (it now updates the bounding boxes the skipped calls used to);
        Q_MT 4.2 -> 3.7 ms. The body ids are the robot indices. Which rows to set is one compiled
        loop (`_stale_rows`), in place of the ten numpy calls a substep that built the velocities
        and compared them (measured without the pybullet calls, two substeps: 112 robots 30 -> 20
        us a tick, 1000 robots 171 -> 135 us)."""
        stale = self._stale
        k = _stale_rows(self._v, cos_yaw, sin_yaw, vz, self._w, self._held, self._kept, stale)
        rows = stale[:k]
        vx, vy, vz, w = self._held[rows].T.tolist()
        zero = repeat(0.0)
        deque(map(p.resetBaseVelocity, rows.tolist(), zip(vx, vy, vz), zip(zero, zero, w), repeat(self._cid)),
              maxlen=0)  # one C-level loop of positional calls (1000 robots: ~0.15 ms a tick less than a for loop)

    def _velocities_kept(self, turning: np.ndarray, touching: np.ndarray) -> np.ndarray:
        """Whose velocity pybullet has left exactly as `_set_velocities` last set it, after a
        substep in which robots `touching` had contact points (`turning`: w != 0).

        With no gravity and no damping, a body that touches nothing moves on with the velocity it
        was given, bit for bit, unless it turns while tilted: a robot that an earlier contact left
        tilted (by less than TILT_RESET) and that turns gets gyroscopic terms of ~1e-12 rad/s in
        its angular velocity. Measured in CPFA (1000 and 112 robots), Q_MT, Q_SE, DDSA, DRTM and
        ARTM runs: every robot this selects (42-100 % of them) read back bit for bit the velocity
        set. Skipping a call also moves the update of the body's bounding box from the call into
        stepSimulation, which can leave pybullet's broadphase with other far-apart pairs (that
        carry no contact points) for a while; the runs stay bit for bit the same (test_world).
        A planar robot (`PLANAR_TILT_INERTIA`) keeps its velocity while it turns, tilted or not."""
        if self._planar:
            return ~touching
        return (~turning | self._upright) & ~touching

    def _odometry(self, pos0: np.ndarray, yaw0: np.ndarray) -> None:
        """Odometry estimate and measured velocities for the tick just simulated.

        The true motion is expressed in the body frame at the tick's start (forward, lateral,
        turn). With noise, distance and turn are scaled by (1 + N(0, linear_std)) and
        (1 + N(0, angular_std)) per robot and tick - an error proportional to what was travelled -
        and dead-reckoned from the previous estimate. Without noise the estimate is the truth.
        """
        d = self._pos - pos0
        c, s = np.cos(yaw0), np.sin(yaw0)
        forward = d[:, 0] * c + d[:, 1] * s
        turn = np.remainder(self._yaw - yaw0 + math.pi, 2 * math.pi) - math.pi
        if not self._noisy:
            self._odo = np.column_stack([self._pos, self._yaw])
        else:
            lateral = -d[:, 0] * s + d[:, 1] * c  # only the noisy estimate moves sideways
            noise = self.scenario.robots.odometry_noise
            scale = 1.0 + self._rng_odometry.normal(0.0, noise.linear_std, self._n)
            turn = turn * (1.0 + self._rng_odometry.normal(0.0, noise.angular_std, self._n))
            forward = forward * scale
            lateral = lateral * scale
            yaw = self._odo[:, 2]
            ce, se = np.cos(yaw), np.sin(yaw)
            self._odo[:, 0] += forward * ce - lateral * se
            self._odo[:, 1] += forward * se + lateral * ce
            self._odo[:, 2] = np.remainder(yaw + turn + math.pi, 2 * math.pi) - math.pi
        self._meas_v = forward / self._dt
        self._meas_w = turn / self._dt

    def observe(self) -> dict[RobotId, Observation]:
        """Observations for the current tick (wire-rounded), with no messages: the world neither
        sends nor carries any (the batch runner hands each behaviour its inbox, as a controller
        node does)."""
        if self._obs_cache is not None:
            return dict(self._obs_cache)
        sc = self.scenario.sensors.scan
        if sc.backend == "pybullet":
            ranges = cast_scan_pybullet(
                self._cid, self._pos, self._yaw, self._z0, self._radius, sc, self._scan_threads
            )
        else:
            ranges = cast_scan(
                self._pos, self._yaw, self._radius, self._scene, sc.rays, sc.fov, sc.range_max, sc.range_min,
                self._pairs,
            )
        ranges.flags.writeable = False
        self._ranges = ranges
        self._ring_ahead = self._ring.ahead(ranges)
        sensed = self.task.sense()
        obs = observations(self.robots, self.t_ns, self._odo, self._meas_v, self._meas_w, ranges, sensed)
        self._obs_cache = obs
        return dict(obs)

    def true_poses(self) -> dict[RobotId, Pose2D]:
        """Ground-truth poses [m, rad; world frame] (the observed odometry may be noisy)."""
        xs, ys, yaws = self._pos[:, 0].tolist(), self._pos[:, 1].tolist(), self._yaw.tolist()
        return {r: Pose2D(xs[i], ys[i], wrap_angle(yaws[i])) for i, r in enumerate(self.robots)}

    def odometry_poses(self) -> dict[RobotId, Pose2D]:
        """The odometry estimates before the wire rounding [m, rad; world frame].

        Observation.pose.yaw is wire_yaw(this yaw). A publisher should encode these: a second
        quaternion round trip of the already rounded yaw is not the identity (about 3% of yaws
        move by an ulp), so re-encoding Observation.pose would hand graph controllers a yaw one
        ulp away from the batch runner's.
        """
        xs, ys, yaws = self._odo[:, 0].tolist(), self._odo[:, 1].tolist(), self._odo[:, 2].tolist()
        return {r: Pose2D(xs[i], ys[i], yaws[i]) for i, r in enumerate(self.robots)}

    def teleport(self, poses: Mapping[RobotId, Pose2D]) -> None:
        """Put robots at `poses` (at rest), for tests and scripted set-ups; odometry follows."""
        self.place_robots(poses)
        self._fresh = False
        self.task.moved()

    def place_robots(self, poses: Mapping[RobotId, Pose2D]) -> None:
        """Put robots at `poses` (at rest) with their odometry; what a task calls while the
        world builds tick 0 to choose where robots start (`teleport` does it later)."""
        cid = self._cid
        for robot, pose in poses.items():
            i = self._index[robot]
            p.resetBasePositionAndOrientation(
                self._bodies[i], [pose.x, pose.y, self._z0], yaw_to_quaternion(pose.yaw),
                physicsClientId=cid,
            )
            p.resetBaseVelocity(self._bodies[i], (0.0, 0.0, 0.0), (0.0, 0.0, 0.0), physicsClientId=cid)
            self._kept[i] = False
        self._read_state()
        for robot in poses:
            i = self._index[robot]
            self._odo[i] = (self._pos[i, 0], self._pos[i, 1], self._yaw[i])
        self._obs_cache = None

    def close(self) -> None:
        """Disconnect from pybullet (idempotent)."""
        if self._client is not None:
            try:
                p.disconnect(physicsClientId=self._client)
            finally:
                self._client = None

    def __enter__(self) -> World:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    def __del__(self) -> None:
        try:
            self.close()
        except Exception:  # interpreter shutdown: pybullet may already be gone
            pass

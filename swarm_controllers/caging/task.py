"""The transport task: landmarks and a cylindrical target object moved only by contact (the
caging paper's arena, Alg. 2; in the manner of ARGoS loop functions).

What it places (Alg. 2), from its first seed stream: the object's centre C_object uniformly in
the rectangle the landmarks span, then every robot's start p_i^0 uniformly in the same
rectangle with a random heading, at least a robot width apart and out of reach of the
object's sensors (a robot never starts next to the object), and at least ``transport.swarm_distance``
from the object's centre (0 by default: no further bound). The paper only says "randomly";
the landmark rectangle keeps the object, and the transport's end at p_r*^0, a cage's width
from the walls.

The object is a dynamic pybullet cylinder of radius r and mass M at the robots' height. The
world has no gravity, so floor friction is a planar Coulomb model applied after every physics
substep of h seconds (`after_substep`): the object's planar speed drops by mu g h (to zero if
smaller) and its spin by (4/3) mu g h / r, the deceleration of a disc pressed uniformly on the
floor; its height and tilt are held like the robots'. An untouched object therefore never moves,
and robots, which are velocity-driven bodies, push it through pybullet's contacts. Robot-object
and object-wall contacts are frictionless (as robot-robot contacts are).

What robots additionally sense (`CagingSense`), from the true state:

- ``proximity``: the paper's ``sensors<detect, id>``, one entry per proximity sensor
  (``sensors.proximity``: the Khepera III's nine infra-red sensors by default): the id of the
  body its ray meets within range (``object``, ``robot_3``, ``wall``), "" when it detects
  nothing. One pybullet ray per sensor from the robot's rim.
- ``bodies``: (id, x, y) of the object and of the other robots whose centres are within
  ``sensors.position_range`` [m, world frame], object first, then robots in index order.

Its state, published every tick on ``/caging/object`` and ``/caging/robots`` (`state`): the
object's and every robot's true position, which analysis reads back as the ``object`` and
``robots`` series (transport error, deviation, whether the cage held).
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from typing import TYPE_CHECKING, NamedTuple

import numpy as np

from swarm_controllers.caging.landmarks import landmarks
from swarm_controllers.caging.world_config import TransportConfig
from swarm_msgs_py.geometry import yaw_to_quaternion
from swarm_msgs_py.types import Pose2D
from swarm_sim.scenario import ScenarioError
from swarm_sim.world.bullet import pybullet as p

if TYPE_CHECKING:
    from swarm_sim.world.core import World

OBJECT = "object"
"""The target object's id in sensor readings (the paper's id_object)."""
WALL = "wall"
"""What a sensor reports for the arena walls and static obstacles."""
GRAVITY = 9.81
"""[m/s^2], for the floor friction."""
TILT_INERTIA = 1e6
"""Roll and pitch inertia of the object [kg m^2] (as the robots': contacts never tip it)."""
RAY_START_OFFSET = 1e-4
"""Proximity rays start this far outside the robot's rim [m] so they never hit it."""
PLACEMENT_TRIES = 10_000
START_GAP = 0.02
"""Robots start at least a robot width plus this apart [m]."""


def starts(rng: np.random.Generator, half: np.ndarray, center: np.ndarray, robots: Sequence[str], width: float,
           clear: float, distance: float) -> dict[str, Pose2D]:
    """p_i^0 (Alg. 2): uniform in the landmark rectangle of half-sides `half` [m] with a uniform
    heading, at least `width` + START_GAP apart, farther than `clear` (the object's sensor reach)
    and at least `distance` (``transport.swarm_distance``) from the object's centre `center`."""
    placed: list[np.ndarray] = []
    poses = {}
    for robot in robots:
        for _ in range(PLACEMENT_TRIES):
            xy = rng.uniform(-half, half)
            away = np.hypot(*(xy - center))
            if away > clear and away >= distance and all(np.hypot(*(xy - q)) >= width + START_GAP for q in placed):
                break
        else:
            where = f"{2 * half[0]:g} x {2 * half[1]:g} m landmark rectangle"
            if distance > clear:
                raise ScenarioError(
                    f"transport.swarm_distance: {len(robots)} robots do not fit apart in the {where} at least "
                    f"{distance:g} m from the object at ({center[0]:.2f}, {center[1]:.2f})")
            raise ScenarioError(f"robots.count: {len(robots)} robots do not fit apart in the {where} "
                                "(transport.landmarks.extent)")
        placed.append(xy)
        poses[robot] = Pose2D(float(xy[0]), float(xy[1]), float(rng.uniform(-math.pi, math.pi)))
    return poses


class CagingSense(NamedTuple):
    """What a robot of the transport task senses besides odometry and scan."""

    proximity: tuple[str, ...]
    """Per proximity sensor, the id of what it detects ("" = detect is false)."""
    bodies: tuple[tuple[str, float, float], ...]
    """(id, x, y) of the object and the robots within the position range [m, world frame]."""


class TransportTask:
    """The object, the landmarks and the robots' sensors for one world; rebuilt at every reset."""

    def __init__(self, world: World, seeds: tuple[np.random.SeedSequence, np.random.SeedSequence]) -> None:
        s = world.scenario
        self._world = world
        self._cid = world.client
        self.landmarks = landmarks(s)
        obj = TransportConfig.of(s).object
        self.radius, self.mass, self._mu = obj.radius, obj.mass, obj.floor_friction
        self._w = s.robots.diameter
        self._z0 = s.robots.height / 2
        self._proximity = s.sensors.proximity
        self._position_range = s.sensors.position_range
        rng = np.random.default_rng(seeds[0])
        half = np.array(TransportConfig.of(s).landmarks.extent, dtype=float) / 2
        center = rng.uniform(-half, half)
        clear = self.radius + self._w / 2 + self._proximity.range + RAY_START_OFFSET
        world.place_robots(starts(rng, half, center, world.robots, self._w, clear,
                                  TransportConfig.of(s).swarm_distance))
        shape = p.createCollisionShape(p.GEOM_CYLINDER, radius=self.radius, height=s.robots.height,
                                       physicsClientId=self._cid)
        self.body = p.createMultiBody(self.mass, shape, -1, [center[0], center[1], self._z0],
                                      physicsClientId=self._cid)
        p.changeDynamics(
            self.body, -1, lateralFriction=0.0, spinningFriction=0.0, rollingFriction=0.0,
            restitution=0.0, linearDamping=0.0, angularDamping=0.0,
            localInertiaDiagonal=[TILT_INERTIA, TILT_INERTIA, 0.5 * self.mass * self.radius**2],
            activationState=p.ACTIVATION_STATE_DISABLE_SLEEPING, physicsClientId=self._cid,
        )
        self._ids = {i: r for i, r in enumerate(world.robots)} | {self.body: OBJECT}
        angles = np.radians(np.asarray(self._proximity.angles, dtype=float))
        self._sensor_angles = angles
        self._read_object()

    # ------------------------------------------------------------------ physics

    def after_substep(self, h: float) -> None:
        """Planar Coulomb friction on the object; hold it upright at the robots' height."""
        cid = self._cid
        (vx, vy, _), (_, _, wz) = p.getBaseVelocity(self.body, cid)
        (x, y, z), (qx, qy, qz, qw) = p.getBasePositionAndOrientation(self.body, cid)
        speed = math.hypot(vx, vy)
        dv = self._mu * GRAVITY * h
        if speed <= dv:
            vx = vy = 0.0
        else:
            vx, vy = vx * (1.0 - dv / speed), vy * (1.0 - dv / speed)
        dw = 4.0 / 3.0 * self._mu * GRAVITY * h / self.radius
        wz = 0.0 if abs(wz) <= dw else wz - math.copysign(dw, wz)
        if abs(qx) > 1e-6 or abs(qy) > 1e-6:
            yaw = math.atan2(2.0 * (qw * qz + qx * qy), 1.0 - 2.0 * (qy * qy + qz * qz))
            p.resetBasePositionAndOrientation(self.body, [x, y, z], yaw_to_quaternion(yaw), cid)
        p.resetBaseVelocity(self.body, (vx, vy, (self._z0 - z) / h), (0.0, 0.0, wz), cid)

    def _read_object(self) -> None:
        (x, y, _), (qx, qy, qz, qw) = p.getBasePositionAndOrientation(self.body, self._cid)
        self.object_pose = Pose2D(x, y, math.atan2(2.0 * (qw * qz + qx * qy), 1.0 - 2.0 * (qy * qy + qz * qz)))
        """The object's true pose [m, rad; world frame] at the current tick."""

    # ------------------------------------------------------------------ WorldTask

    def post_step(self, stamp_ns: int) -> None:
        self._read_object()

    def moved(self) -> None:
        pass

    def sense(self) -> list[CagingSense]:
        world = self._world
        pos, yaw = world.positions, world.headings
        n = len(pos)
        start = self._w / 2 + RAY_START_OFFSET
        end = self._w / 2 + self._proximity.range
        angles = (yaw[:, None] + self._sensor_angles[None, :]).reshape(-1)
        u = np.column_stack([np.cos(angles), np.sin(angles)])
        o = np.repeat(pos, len(self._sensor_angles), axis=0)
        z = np.full((len(u), 1), self._z0)
        hits = p.rayTestBatch(np.hstack([o + start * u, z]).tolist(), np.hstack([o + end * u, z]).tolist(),
                              physicsClientId=self._cid)
        ids = self._ids
        seen = [("" if h[0] < 0 else ids.get(h[0], WALL)) for h in hits]
        k = len(self._sensor_angles)
        obj = np.array([self.object_pose.x, self.object_pose.y])
        near_object = (np.hypot(*(pos - obj).T) <= self._position_range).tolist()
        d = pos[:, None, :] - pos[None, :, :]
        near = (np.hypot(d[..., 0], d[..., 1]) <= self._position_range).tolist()
        xy = pos.tolist()
        names = world.robots
        ox, oy = float(obj[0]), float(obj[1])
        out = []
        for i in range(n):
            bodies = [(OBJECT, ox, oy)] if near_object[i] else []
            bodies += [(names[j], xy[j][0], xy[j][1]) for j in range(n) if j != i and near[i][j]]
            out.append(CagingSense(tuple(seen[i * k:(i + 1) * k]), tuple(bodies)))
        return out

    def state(self) -> dict[str, object]:
        """``object``: its true (x, y); ``robots``: every robot's true (x, y), in robot order."""
        o = self.object_pose
        return {"object": (o.x, o.y), "robots": tuple(map(tuple, self._world.positions.tolist()))}

    def drain_events(self) -> list:
        return []

    def placed(self) -> Mapping[str, np.ndarray]:
        return {"landmarks": np.array(self.landmarks.points),
                "object": np.array([[self.object_pose.x, self.object_pose.y]])}

    def progress(self) -> str:
        return f"object=({self.object_pose.x:.2f}, {self.object_pose.y:.2f})"

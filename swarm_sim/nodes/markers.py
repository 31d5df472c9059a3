"""visualization_msgs/msg/MarkerArray for RViz/Foxglove: the scenario's world, drawn.

Rarely published (static parts latched once, dynamic parts at a low rate), so this one codec
builds rclpy message objects and serializes them. Everything is in the ``world`` frame.

Namespaces and ids: ``walls`` (one LINE_STRIP), ``drop_zones`` (one flat CYLINDER per zone,
the depot first), ``obstacles`` (CUBE or CYLINDER each), one SPHERE_LIST per point set the world task placed
(``resources`` for foraging),
``robots`` (one CYLINDER per robot, id = robot index, orange while carrying).
"""

from __future__ import annotations

import math
from collections.abc import Mapping

import numpy as np
from builtin_interfaces.msg import Time
from geometry_msgs.msg import Point, Pose, Quaternion, Vector3
from rclpy.serialization import serialize_message
from std_msgs.msg import ColorRGBA, Header
from visualization_msgs.msg import Marker, MarkerArray

from swarm_msgs_py.cdr import split_stamp
from swarm_msgs_py.geometry import yaw_to_quaternion
from swarm_msgs_py.types import Pose2D, RobotId, robot_index
from swarm_sim.scenario import Scenario
from swarm_sim.sites import drop_zones

WORLD_FRAME = "world"
RESOURCE_DIAMETER = 0.05
"""Drawn size of a resource [m] (resources are points to the simulation)."""
OBSTACLE_HEIGHT = 0.3
"""Drawn height of obstacles [m]."""

_WALL = ColorRGBA(r=0.3, g=0.3, b=0.3, a=1.0)
_DEPOT = ColorRGBA(r=0.2, g=0.7, b=0.2, a=0.5)
_ZONE = ColorRGBA(r=0.2, g=0.4, b=0.9, a=0.5)
_OBSTACLE = ColorRGBA(r=0.5, g=0.35, b=0.2, a=1.0)
_PLACED = (ColorRGBA(r=0.95, g=0.85, b=0.1, a=1.0), ColorRGBA(r=0.6, g=0.3, b=0.9, a=1.0),
           ColorRGBA(r=0.1, g=0.7, b=0.7, a=1.0))
"""Colours of the task's point sets, in order (resources: yellow)."""
_ROBOT = ColorRGBA(r=0.1, g=0.3, b=0.8, a=1.0)
_ROBOT_CARRYING = ColorRGBA(r=1.0, g=0.5, b=0.0, a=1.0)


def _marker(stamp_ns: int, ns: str, id_: int, type_: int, color: ColorRGBA) -> Marker:
    sec, nanosec = split_stamp(stamp_ns)
    m = Marker()
    m.header = Header(stamp=Time(sec=sec, nanosec=nanosec), frame_id=WORLD_FRAME)
    m.ns, m.id, m.type, m.action, m.color = ns, id_, type_, Marker.ADD, color
    m.pose.orientation.w = 1.0
    return m


def _pose(x: float, y: float, z: float, yaw: float = 0.0) -> Pose:
    qx, qy, qz, qw = yaw_to_quaternion(yaw)
    return Pose(
        position=Point(x=float(x), y=float(y), z=float(z)),
        orientation=Quaternion(x=qx, y=qy, z=qz, w=qw),
    )


def static_markers(scenario: Scenario, stamp_ns: int = 0) -> list[Marker]:
    """Walls, drop zones and obstacles: they never move, publish them latched."""
    markers = []
    half = scenario.arena.size / 2 + scenario.arena.wall_thickness / 2
    walls = _marker(stamp_ns, "walls", 0, Marker.LINE_STRIP, _WALL)
    corners = [(-half, -half), (half, -half), (half, half), (-half, half), (-half, -half)]
    walls.points = [Point(x=x, y=y, z=0.0) for x, y in corners]
    walls.scale.x = scenario.arena.wall_thickness
    markers.append(walls)
    for i, zone in enumerate(drop_zones(scenario)):
        m = _marker(stamp_ns, "drop_zones", i, Marker.CYLINDER, _DEPOT if i == 0 else _ZONE)
        m.pose = _pose(zone.center[0], zone.center[1], 0.005)
        m.scale = Vector3(x=2 * zone.radius, y=2 * zone.radius, z=0.01)
        markers.append(m)
    for i, ob in enumerate(scenario.obstacles):
        kind = Marker.CUBE if ob.shape == "box" else Marker.CYLINDER
        m = _marker(stamp_ns, "obstacles", i, kind, _OBSTACLE)
        m.pose = _pose(ob.center[0], ob.center[1], OBSTACLE_HEIGHT / 2, ob.yaw)
        m.scale = Vector3(x=float(ob.size[0]), y=float(ob.size[1]), z=OBSTACLE_HEIGHT)
        markers.append(m)
    return markers


def placed_markers(placed: Mapping[str, np.ndarray], stamp_ns: int = 0) -> list[Marker]:
    """One SPHERE_LIST per point set the world task has placed (`WorldTask.placed`, e.g. the
    resources lying on the ground), namespace = its name; (n, 2) [m, world] each."""
    out = []
    for k, (name, positions) in enumerate(placed.items()):
        m = _marker(stamp_ns, name, 0, Marker.SPHERE_LIST, _PLACED[k % len(_PLACED)])
        d = RESOURCE_DIAMETER
        m.scale = Vector3(x=d, y=d, z=d)
        pts = np.asarray(positions, dtype=float).reshape(-1, 2)
        m.points = [Point(x=x, y=y, z=d / 2) for x, y in pts.tolist()]
        out.append(m)
    return out


def robot_markers(
    scenario: Scenario,
    poses: Mapping[RobotId, Pose2D] | np.ndarray,
    carrying: np.ndarray | None = None,
    stamp_ns: int = 0,
) -> list[Marker]:
    """One CYLINDER per robot, orange while carrying.

    `poses`: ``{robot: Pose2D}`` (marker id = robot index) or an (n, 3) array of rows
    x, y [m, world], yaw [rad] (marker id = row); `carrying`: (n,) bool in the same order.
    """
    if isinstance(poses, Mapping):
        rows = [(robot_index(r), p.x, p.y, p.yaw) for r, p in poses.items()]
    else:
        arr = np.asarray(poses, dtype=float).reshape(-1, 3)
        rows = [(i, x, y, yaw) for i, (x, y, yaw) in enumerate(arr.tolist())]
    held = np.zeros(len(rows), bool) if carrying is None else np.asarray(carrying, bool)
    if held.shape != (len(rows),):
        raise ValueError(f"carrying of shape {held.shape} for {len(rows)} robots")
    d, h = scenario.robots.diameter, scenario.robots.height
    markers = []
    for (i, x, y, yaw), c in zip(rows, held.tolist()):
        m = _marker(stamp_ns, "robots", i, Marker.CYLINDER, _ROBOT_CARRYING if c else _ROBOT)
        m.pose = _pose(x, y, h / 2, yaw if math.isfinite(yaw) else 0.0)
        m.scale = Vector3(x=d, y=d, z=h)
        markers.append(m)
    return markers


def serialize_markers(markers: list[Marker]) -> bytes:
    return bytes(serialize_message(MarkerArray(markers=markers)))


def encode_static_markers(scenario: Scenario, stamp_ns: int = 0) -> bytes:
    return serialize_markers(static_markers(scenario, stamp_ns))


def encode_placed_markers(placed: Mapping[str, np.ndarray], stamp_ns: int = 0) -> bytes:
    return serialize_markers(placed_markers(placed, stamp_ns))


def encode_robot_markers(
    scenario: Scenario,
    poses: Mapping[RobotId, Pose2D] | np.ndarray,
    carrying: np.ndarray | None = None,
    stamp_ns: int = 0,
) -> bytes:
    return serialize_markers(robot_markers(scenario, poses, carrying, stamp_ns))


def encode_markers(
    scenario: Scenario,
    stamp_ns: int,
    placed: Mapping[str, np.ndarray],
    robot_poses: Mapping[RobotId, Pose2D] | np.ndarray,
    carrying: np.ndarray | None = None,
) -> bytes:
    """Everything in one array: static parts, what the task placed, robots."""
    return serialize_markers(
        static_markers(scenario, stamp_ns)
        + placed_markers(placed, stamp_ns)
        + robot_markers(scenario, robot_poses, carrying, stamp_ns)
    )


# --------------------------------------------------------------------------- servers' drawings


def line_markers(
    ns: str, lines: list[np.ndarray], color: tuple[float, float, float, float],
    width: float = 0.02, stamp_ns: int = 0,
) -> list[Marker]:
    """One LINE_STRIP per polyline ((n, 2) [m, world]), id = position in `lines`."""
    out = []
    for i, pts in enumerate(lines):
        m = _marker(stamp_ns, ns, i, Marker.LINE_STRIP, ColorRGBA(r=color[0], g=color[1], b=color[2], a=color[3]))
        m.scale.x = width
        m.points = [Point(x=x, y=y, z=0.01) for x, y in np.asarray(pts, float).reshape(-1, 2).tolist()]
        out.append(m)
    return out


def point_markers(
    ns: str, id_: int, points: np.ndarray, color: tuple[float, float, float, float],
    size: float, stamp_ns: int = 0, cubes: bool = False,
) -> list[Marker]:
    """One SPHERE_LIST (or CUBE_LIST) of `points` ((n, 2) [m, world])."""
    kind = Marker.CUBE_LIST if cubes else Marker.SPHERE_LIST
    m = _marker(stamp_ns, ns, id_, kind, ColorRGBA(r=color[0], g=color[1], b=color[2], a=color[3]))
    m.scale = Vector3(x=size, y=size, z=size)
    m.points = [Point(x=x, y=y, z=size / 2) for x, y in np.asarray(points, float).reshape(-1, 2).tolist()]
    return [m]

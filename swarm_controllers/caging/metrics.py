"""The caging paper's measures of a run (sec. 5, Tables 1 and 2), from its trace alone.

Everything comes from the recorded protocol (`RunTrace.messages`: types 0-4) and the transport
task's state series (``object``: the object's true position, ``robots``: the robots', every
tick), so a batch run and the bag of a graph run give the same numbers.

- search time: from the start to the recruiter's type 0 (the first detection);
- recruitment time: from there until the cage is complete: the last robot's type 2 (or, when
  the recruiter gave up on a summoned robot, the end of that robot's ``call_timeout``);
- transport time: from there until the last type 4 of the final landmark;
- planned path: the object's centre when the cage is complete, then the transport's targets
  (`swarm_controllers.caging.plan`; by default the landmarks of T_r* reversed, then p_r*^0), as
  a polyline (the paper's "path minimum length"; its Table 2 lengths, sums of 0.5 m and
  0.5 sqrt 2 m steps, have no piece off the grid: ours keeps the object's centre to the first
  landmark and, by default, the last landmark to p_r*^0, since the object travels them too);
- object path: the length of the polyline of the object's centre over the transport;
- trajectory error: |object path - planned path| (sec. 5), and as a percentage of the planned
  path (the paper's "normalised error", about 3.8 %);
- max path deviation: the object centre's largest distance from the planned polyline;
- cage held: at every tick of the transport the object's centre lay inside the polygon of the
  cage's robots (in cage order), and no robot lost contact with its cage for more than
  CONTACT_BOUND seconds in a row, where losing contact means opening a gap to a cage neighbour
  (edge to edge) as wide as the object (2 r): a gap the object could slip through.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from swarm_controllers.caging.config import CagingConfig
from swarm_controllers.caging.landmarks import landmarks
from swarm_controllers.caging.plan import planned_path
from swarm_controllers.caging.protocol import Oriented, Positioned, Reached, Recruitment, Summon
from swarm_controllers.caging.world_config import TransportConfig
from swarm_msgs_py.types import NS_PER_S, robot_index

CONTACT_BOUND = 5.0
"""[s]: the longest a gap the object could pass through may stay open while the cage still counts
as held."""


@dataclass(frozen=True)
class CagingReport:
    search_time_s: float | None = None
    recruitment_time_s: float | None = None
    transport_time_s: float | None = None
    total_time_s: float | None = None
    planned_path_m: float | None = None
    object_path_m: float | None = None
    trajectory_error_m: float | None = None
    trajectory_error_pct: float | None = None
    cage_held: bool | None = None
    max_path_deviation_m: float | None = None
    landmarks: int | None = None
    cage_size: int | None = None
    """Robots in the cage: the recruiter and every robot that sent type 2."""


def polyline_length(points: np.ndarray) -> float:
    return float(np.hypot(*np.diff(points, axis=0).T).sum()) if len(points) > 1 else 0.0


def distance_to_polyline(points: np.ndarray, polyline: np.ndarray) -> np.ndarray:
    """Each point's distance to the nearest segment of `polyline` [m]."""
    if len(polyline) == 1:
        return np.hypot(*(points - polyline[0]).T)
    a, b = polyline[:-1], polyline[1:]
    ab = b - a
    length2 = np.maximum((ab**2).sum(axis=1), 1e-18)
    ap = points[:, None, :] - a[None, :, :]
    t = np.clip((ap * ab[None]).sum(axis=2) / length2[None], 0.0, 1.0)
    nearest = a[None] + t[..., None] * ab[None]
    return np.hypot(*(points[:, None, :] - nearest).transpose(2, 0, 1)).min(axis=1)


def inside_polygon(point: np.ndarray, polygon: np.ndarray) -> bool:
    """Even-odd ray casting: whether `point` lies strictly inside `polygon` (any simple polygon)."""
    x, y = point
    inside = False
    n = len(polygon)
    for k in range(n):
        (x1, y1), (x2, y2) = polygon[k], polygon[(k + 1) % n]
        if (y1 > y) != (y2 > y) and x < x1 + (y - y1) * (x2 - x1) / (y2 - y1):
            inside = not inside
    return inside


@dataclass(frozen=True, eq=False)
class Transport:
    """What the figures need besides the report: the transport stage of a run."""

    start_s: float
    """When the cage was complete [s]."""
    end_s: float
    """When the last type 4 of the final landmark was sent (or the run's end) [s]."""
    planned: np.ndarray
    """(N, 2) the planned path [m, world frame]."""
    cage: tuple[str, ...]
    """The cage's robots in cage order."""


def series_of(trace, name: str) -> tuple[np.ndarray, list]:
    """(times [s], values) of one of the run's series."""
    points = trace.series.get(name, [])
    return np.array([t for t, _ in points]), [v for _, v in points]


_cache: tuple[object, CagingReport, Transport | None] | None = None


def caging_report(trace) -> CagingReport:
    """The run's measures (None where the run did not get that far); computed once per trace."""
    return _analysis(trace)[0]


def transport_stage(trace) -> Transport | None:
    """The transport stage (None if the cage was never complete)."""
    return _analysis(trace)[1]


def _analysis(trace) -> tuple[CagingReport, Transport | None]:
    global _cache
    if _cache is None or _cache[0] is not trace:
        _cache = (trace, *_report(trace))
    return _cache[1], _cache[2]


def _report(trace) -> tuple[CagingReport, Transport | None]:
    scenario = trace.config
    marks = landmarks(scenario)
    recruitments = [m for m in trace.messages if isinstance(m, Recruitment)]
    if not recruitments:
        return CagingReport(landmarks=len(marks)), None
    first = min(recruitments, key=lambda m: (m.stamp_ns, robot_index(m.origin)))
    recruiter = first.origin
    s = 1.0 / NS_PER_S
    t_detect = first.stamp_ns * s
    positioned = {m.origin: m.stamp_ns for m in trace.messages if isinstance(m, Positioned)}
    cage = sorted({recruiter, *positioned}, key=robot_index)
    result = {"search_time_s": t_detect, "landmarks": len(marks), "cage_size": len(cage)}
    if not any(isinstance(m, Oriented) for m in trace.messages):
        return CagingReport(**result), None
    cfg = CagingConfig.of(scenario)
    unanswered = [m.stamp_ns * s + cfg.call_timeout for m in trace.messages
                  if isinstance(m, Summon) and m.origin == recruiter and m.destination not in positioned]
    t_caged = max([t * s for t in positioned.values()] + unanswered + [t_detect])
    result["recruitment_time_s"] = t_caged - t_detect

    targets = planned_path(marks, first.trajectory, (first.start_x, first.start_y), cfg.plan)
    final = len(targets) - 1
    oriented = {m.origin for m in trace.messages if isinstance(m, Oriented) and m.leg == final}
    reached = {m.origin: m.stamp_ns for m in trace.messages if isinstance(m, Reached) and m.leg == final}
    done = bool(oriented) and oriented <= set(reached)
    t_done = max(reached.values()) * s if done else trace.sim_seconds
    if done:
        result |= {"transport_time_s": t_done - t_caged, "total_time_s": t_done}

    times, positions = series_of(trace, "object")
    window = (times >= t_caged - 1e-9) & (times <= t_done + 1e-9)
    if not window.any():
        return CagingReport(**result), None
    obj = np.array(positions)[window]
    planned = np.array([obj[0], *targets])
    result["max_path_deviation_m"] = float(distance_to_polyline(obj, planned).max())
    result["cage_held"] = _cage_held(trace, scenario, cage, times[window], obj)
    if done:
        planned_m, travelled_m = polyline_length(planned), polyline_length(obj)
        error = abs(travelled_m - planned_m)
        result |= {"planned_path_m": planned_m, "object_path_m": travelled_m, "trajectory_error_m": error,
                   "trajectory_error_pct": 100.0 * error / planned_m if planned_m > 0 else None}
    return CagingReport(**result), Transport(t_caged, t_done, planned, tuple(cage))


def _cage_held(trace, scenario, cage: list[str], times: np.ndarray, obj: np.ndarray) -> bool:
    robot_times, robot_positions = series_of(trace, "robots")
    at = {round(t, 6): p for t, p in zip(robot_times, robot_positions)}
    members = [robot_index(r) for r in cage]
    widest = 2.0 * TransportConfig.of(scenario).object.radius + scenario.robots.diameter
    """Adjacent robots' centres this far apart leave a gap the object passes through."""
    open_since: float | None = None
    for t, center in zip(times, obj):
        positions = at.get(round(t, 6))
        if positions is None or len(cage) < 3:
            return False
        polygon = np.array([positions[i] for i in members])
        if not inside_polygon(center, polygon):
            return False
        if np.hypot(*(polygon - np.roll(polygon, -1, axis=0)).T).max() >= widest:
            open_since = t if open_since is None else open_since
            if t - open_since > CONTACT_BOUND:
                return False
        else:
            open_since = None
    return True


def _field(name: str):
    def metric(trace):
        value = getattr(caging_report(trace), name)
        return round(value, 6) if isinstance(value, float) else value
    metric.__name__ = name
    metric.__doc__ = f"``{name}`` of `caging_report`."
    return metric


search_time_s = _field("search_time_s")
recruitment_time_s = _field("recruitment_time_s")
transport_time_s = _field("transport_time_s")
total_time_s = _field("total_time_s")
planned_path_m = _field("planned_path_m")
object_path_m = _field("object_path_m")
trajectory_error_m = _field("trajectory_error_m")
trajectory_error_pct = _field("trajectory_error_pct")
cage_held = _field("cage_held")
max_path_deviation_m = _field("max_path_deviation_m")
landmark_count = _field("landmarks")
cage_size = _field("cage_size")


def object_delivered(trace) -> bool:
    """Whether the transport ended: every cage robot sent its type 4 for the final landmark (the
    object is at p_r*^0; ``transport_time_s`` is then known)."""
    return caging_report(trace).transport_time_s is not None

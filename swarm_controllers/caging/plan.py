"""The transport's planned path from the recruiter's trajectory T_r* (Alg. 6), in three readings
(``controller.caging.plan``); the robots follow it (`swarm_controllers.caging.behaviour`) and the
measures read it back from the type-0 message (`swarm_controllers.caging.metrics`).

- ``search_to_start`` (the default): T_r* reversed, then the recruiter's start p_r*^0. Sec. 4:
  "the last position has the initial position of robot r* when it started the search for the
  target object".
- ``search``: T_r* reversed and nothing after it, Alg. 6's loop as printed ("for j := n - 1 -> 0
  do lambda := T_ij"): the transport ends at the first landmark the recruiter reached.
- ``shortest``: the same two ends (T_r*'s last landmark, its first), joined by a shortest path
  of the 8-connected landmark grid instead of the recruiter's walk: sec. 5's "path minimum
  length" read as the grid's shortest path, the "path optimization" sec. 6 leaves for future
  work. Table 2's lengths are each such a path of 7 steps: 5 + 2, 3 + 4 and 1 + 6 straight and
  diagonal 0.5 m steps (`grid_path_length`).

When the recruiter detects the object before reaching any landmark (T_r* empty), the two
landmark-only readings use the landmark nearest p_r*^0, where its search began.
"""

from __future__ import annotations

import math

import numpy as np

from swarm_controllers.caging.landmarks import Landmarks

Point = tuple[float, float]
PLANS: tuple[str, ...] = ("search_to_start", "search", "shortest")


def grid_path_length(step: float, dx: int, dy: int) -> float:
    """The length of a shortest 8-connected grid path over a displacement of (dx, dy) cells:
    min(|dx|, |dy|) diagonal steps and the rest straight."""
    m = min(abs(dx), abs(dy))
    return (max(abs(dx), abs(dy)) - m) * step + m * step * math.sqrt(2.0)


def shortest_grid_path(marks: Landmarks, a: int, b: int) -> list[int]:
    """Landmark indices from a to b, both included, a shortest 8-connected path: the diagonal
    steps first, then the straight ones (of the many shortest paths, one with a single corner)."""
    (ax, ay), (bx, by) = marks.cell(a), marks.cell(b)
    sx, sy = int(np.sign(bx - ax)), int(np.sign(by - ay))
    out, x, y = [a], ax, ay
    while (x, y) != (bx, by):
        x += sx if x != bx else 0
        y += sy if y != by else 0
        out.append(marks.index(x, y))
    return out


def nearest(marks: Landmarks, point: Point) -> int:
    return int(np.argmin(np.hypot(*(marks.points - np.asarray(point, dtype=float)).T)))


def planned_path(marks: Landmarks, trajectory: list[int] | tuple[int, ...], start: Point, plan: str) -> list[Point]:
    """The transport's targets, in order, under `plan` (one of `PLANS`)."""
    if plan not in PLANS:
        raise ValueError(f"controller.caging.plan: {plan!r} is not one of {', '.join(PLANS)}")
    if plan == "search_to_start":
        return [marks.position(j) for j in reversed(trajectory)] + [start]
    if not trajectory:
        return [marks.position(nearest(marks, start))]
    indices = list(reversed(trajectory)) if plan == "search" else shortest_grid_path(marks, trajectory[-1], trajectory[0])
    return [marks.position(j) for j in indices]

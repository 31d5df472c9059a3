"""The foraging task: resources on the ground, grippers, drop zones (ARGoS foraging loop functions).

What it places: the scenario's resources (`swarm_sim.world.resources`), kept clear of the drop
zones (`swarm_sim.sites.zones_clear_of_resources`). What robots additionally sense (`ForagingSense`): the
resources within the detection radius, nearest first, and whether the gripper holds one. Its
bookkeeping after each tick, robots in index order: a carrying robot that has stayed inside a
drop zone for the zone's dwell time drops its resource there (a `DropEvent`; respawn if the
scenario asks); an empty robot within the pick-up radius of a resource picks up the nearest one
(a `PickupEvent`). Events are stamped with the new tick's time.
"""

from __future__ import annotations

import functools
import math
from collections.abc import Iterator, Mapping
from typing import TYPE_CHECKING, NamedTuple

import numpy as np

from swarm_msgs_py.types import DropEvent, PickupEvent, RobotId
from swarm_sim.sites import drop_zones, zones_clear_of_resources
from swarm_sim.world.jit import kernel
from swarm_sim.world.resources import place_one, place_resources

if TYPE_CHECKING:
    from swarm_sim.world.core import World


class ForagingSense(NamedTuple):
    """What a foraging robot senses besides odometry and scan (a NamedTuple: built for every
    robot on every tick, it must be cheap)."""

    resources: tuple[tuple[float, float], ...]
    """Positions of resources within the detection radius [m, world frame], nearest first."""
    carrying: bool
    """True while the gripper holds a resource."""


_new_sense = functools.partial(tuple.__new__, ForagingSense)
"""ForagingSense from a (resources, carrying) pair without the Python-level NamedTuple
``__new__``: built for every robot on every tick (measured: 112 robots, +8 % per tick)."""
_DETECTING_NOTHING = (_new_sense(((), False)), _new_sense(((), True)))
"""The reading of a robot that detects no resource, by whether it carries one."""


_ALL_PAIRS = 4096
"""Up to this many (robot, resource) pairs every pair is tested at once; more (the queue paper's
112 robots and 320 resources) go through the grid of cells (`ForagingTask._ground_changed`)."""


class ForagingTask:
    """Resources, pick-up and delivery for one world; rebuilt with it at every reset."""

    def __init__(self, world: World, seeds: tuple[np.random.SeedSequence, np.random.SeedSequence]) -> None:
        s = world.scenario
        self._world = world
        self._scenario = s
        rng_resources, self._rng_respawn = (np.random.default_rng(x) for x in seeds)
        n = len(world.robots)
        self._zones = zones = drop_zones(s)
        self._keep_clear = zones_clear_of_resources(s)
        self._zone_xy = np.array([z.center for z in zones], dtype=float).reshape(-1, 2)
        self._zone_r2 = np.array([z.radius**2 for z in zones])
        self._zone_dwell_ns = np.array([round(z.dwell * 1e9) for z in zones], dtype=np.int64)
        self._detect_r = s.sensors.resource_detection_radius
        self._pickup_r = s.sensors.pickup_radius
        self._near_r = max(self._detect_r, self._pickup_r)
        # The grid of square cells over the arena, an empty ring of cells around it. A cell is a
        # little wider than the radius, so rounding never puts a resource in reach two cells away.
        self._cell = self._near_r * (1 + 1e-6)
        self._grid = math.ceil(s.arena.size / self._cell) + 3
        self._grid_corner = -s.arena.size / 2 - self._cell  # the lower left corner of cell (0, 0)
        self._ground_version = 0
        # Every resource ever placed keeps its index; `_on_ground` says where it is.
        self._res_xy = place_resources(s.resources, s.arena, s.depot, rng_resources, self._keep_clear)
        self._on_ground = np.ones(len(self._res_xy), dtype=bool)
        self._carrying = np.full(n, -1, dtype=np.int64)
        self._inside_ticks = np.zeros((n, len(zones)), dtype=np.int64)
        self._events: list[PickupEvent | DropEvent] = []
        self.resources_delivered = 0
        self._near_cache: tuple[int, np.ndarray, np.ndarray, np.ndarray] | None = None
        self._ground_changed()

    # ------------------------------------------------------------------ the ground index

    def _ground_changed(self) -> None:
        """Refresh the ground index after a pick-up or a respawn: the resources on the ground,
        sorted by the square cell of the grid they lie in, and where each cell's run starts."""
        self._ground_ids = np.nonzero(self._on_ground)[0]
        self._ground_xy = self._res_xy[self._ground_ids]
        cells = self._cells(self._ground_xy)
        self._ground_by_cell = np.argsort(cells, kind="stable")
        self._cell_start = np.zeros(self._grid * self._grid + 1, dtype=np.intp)
        np.cumsum(np.bincount(cells, minlength=self._grid * self._grid), out=self._cell_start[1:])
        self._ground_version += 1
        self._near_cache = None

    def _cells(self, xy: np.ndarray) -> np.ndarray:
        """Cell i * grid + j of points (x, y), (i, j) clipped to the grid's inner cells (the outer
        ring stays empty, so the 3 x 3 cells around any point's cell are 9 distinct cells)."""
        ij = np.floor((xy - self._grid_corner) / self._cell).astype(np.intp)
        np.clip(ij, 1, self._grid - 2, out=ij)
        return ij[:, 0] * self._grid + ij[:, 1]

    def _near_resources(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(robot index, ground index, squared distance) of ground resources within the sensing
        radius (the larger of detection and pick-up) of a robot centre, sorted by robot, then
        distance, then resource index.

        Beyond _ALL_PAIRS pairs, each robot looks into the 3 x 3 cells around its own
        (`_near_in_cells`). (1000 robots and 3,200 resources: 0.45 -> 0.18 ms a tick; the strip
        x +- r searched before held ~300 times the resources within reach.) A resource counts if
        it is within the radius and inside that strip as rounded, as before, so the result is the
        same bit for bit (one ulp outside the strip can be within the radius)."""
        radius = self._near_r
        empty = np.zeros(0, dtype=np.int64)
        if len(self._ground_ids) == 0:
            return empty, empty, np.zeros(0)
        pos = self._world.positions
        rx, ry = pos[:, 0], pos[:, 1]
        if len(rx) * len(self._ground_ids) <= _ALL_PAIRS:
            dx = self._ground_xy[None, :, 0] - rx[:, None]
            dy = self._ground_xy[None, :, 1] - ry[:, None]
            d2 = dx * dx + dy * dy
            robot, g = np.nonzero(d2 <= radius * radius)
            d2 = d2[robot, g]
            order = np.lexsort((g, d2, robot))
            return robot[order], g[order], d2[order]
        return _near_in_cells(rx, ry, self._cells(pos), self._ground_xy, self._ground_by_cell,
                              self._cell_start, self._grid, radius)

    def _near_cached(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """`_near_resources` for the larger of the detection and pick-up radii, once per state."""
        key = self._ground_version
        if self._near_cache is None or self._near_cache[0] != key:
            self._near_cache = (key, *self._near_resources())
        return self._near_cache[1:]

    # ------------------------------------------------------------------ WorldTask

    def moved(self) -> None:
        self._near_cache = None

    def post_step(self, stamp_ns: int) -> None:
        """Drops and pick-ups for the tick that ends at `stamp_ns`, robots in index order."""
        self._near_cache = None  # the robots moved
        pos = self._world.positions
        carrying = self._carrying >= 0
        # Dwell: consecutive ticks a carrying robot has been seen inside each zone (the rows of
        # robots that carry nothing stay zero).
        droppers = np.zeros(0, dtype=np.int64)
        ready = np.zeros((0, len(self._zones)), dtype=bool)
        if carrying.any():
            holders = np.flatnonzero(carrying)
            dz = pos[holders, None, :] - self._zone_xy[None, :, :]
            inside = dz[..., 0] ** 2 + dz[..., 1] ** 2 <= self._zone_r2[None, :]
            ticks = np.where(inside, self._inside_ticks[holders] + 1, 0)
            self._inside_ticks[holders] = ticks
            ready_rows = (ticks > 0) & ((ticks - 1) * self._world.dt_ns >= self._zone_dwell_ns)
            some = ready_rows.any(axis=1)
            droppers, ready = holders[some], ready_rows[some]

        robot, g, d2 = self._near_cached()
        candidate = (d2 <= self._pickup_r ** 2) & ~carrying[robot]
        pickers = robot[candidate]
        if len(droppers) == 0 and len(pickers) == 0:
            return
        zone_of = {int(i): self._zones[int(np.argmax(row))] for i, row in zip(droppers, ready)}
        names, stats = self._world.robots, self._world.stats
        s = self._scenario

        taken: set[int] = set()
        changed = False
        for i in sorted(set(droppers.tolist()) | set(pickers.tolist())):
            name = names[i]
            x, y = float(pos[i, 0]), float(pos[i, 1])
            if carrying[i]:
                zone = zone_of[i]
                resource = int(self._carrying[i])
                self._carrying[i] = -1
                self._inside_ticks[i] = 0
                self._events.append(DropEvent(name, stamp_ns, resource, zone.name, x, y))
                self.resources_delivered += 1
                stats[name].deliveries += 1
                if s.resources.respawn:
                    new = place_one(s.resources, s.arena, s.depot, self._rng_respawn, self._ground_xy, self._keep_clear)
                    self._res_xy = np.vstack([self._res_xy, new[None, :]])
                    self._on_ground = np.append(self._on_ground, True)
                    changed = True
            else:
                mine = np.nonzero((robot == i) & candidate)[0]
                for k in mine.tolist():
                    resource = int(self._ground_ids[g[k]])
                    if resource in taken:
                        continue
                    taken.add(resource)
                    self._carrying[i] = resource
                    self._on_ground[resource] = False
                    rx, ry = self._res_xy[resource]
                    self._events.append(PickupEvent(name, stamp_ns, resource, float(rx), float(ry)))
                    stats[name].pickups += 1
                    changed = True
                    break
        if changed:
            self._ground_changed()

    def sense(self) -> list[ForagingSense]:
        carrying = (self._carrying >= 0).tolist()
        # Most robots detect nothing: they share one reading per gripper state (1000 robots: the
        # readings built in a third of the time).
        senses = list(map(_DETECTING_NOTHING.__getitem__, carrying))
        for i, resources in self._detections():
            senses[i] = _new_sense((resources, carrying[i]))
        return senses

    def sense_fields(self) -> tuple[list[tuple[tuple[float, float], ...]], list[bool]]:
        """Per robot, the resources it detects (nearest first) and whether it carries one: the
        fields of `ForagingSense`, for tasks whose sense extends it."""
        detected: list[tuple[tuple[float, float], ...]] = [()] * len(self._world.robots)
        for i, resources in self._detections():
            detected[i] = resources
        return detected, (self._carrying >= 0).tolist()

    def _detections(self) -> Iterator[tuple[int, tuple[tuple[float, float], ...]]]:
        """(robot, the resources it detects, nearest first) for every robot that detects any."""
        robot, g, d2 = self._near_cached()
        if len(robot):
            keep = d2 <= self._detect_r ** 2
            robot, g = robot[keep].tolist(), self._ground_xy[g[keep]].tolist()
            start = 0
            for k in range(1, len(robot) + 1):
                if k == len(robot) or robot[k] != robot[start]:
                    yield robot[start], tuple(tuple(xy) for xy in g[start:k])
                    start = k

    def drain_events(self) -> list[PickupEvent | DropEvent]:
        events, self._events = self._events, []
        return events

    def placed(self) -> Mapping[str, np.ndarray]:
        return {"resources": self.resource_positions()}

    def progress(self) -> str:
        return f"delivered={self.resources_delivered}"

    # ------------------------------------------------------------------ queries

    def resource_positions(self) -> np.ndarray:
        """(M, 2) positions of the resources lying on the ground [m, world frame]."""
        return self._ground_xy.copy()

    def carried_resource(self, robot: RobotId) -> int | None:
        """Index of the resource `robot` holds, or None."""
        k = int(self._carrying[self._world.robots.index(robot)])
        return None if k < 0 else k


@kernel
def _near_in_cells(
    rx: np.ndarray, ry: np.ndarray, cells: np.ndarray, ground_xy: np.ndarray, ground_by_cell: np.ndarray,
    cell_start: np.ndarray, grid: int, radius: float,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """`ForagingTask._near_resources` by the grid (compiled, `swarm_sim.world.jit`): for robot i
    at (rx[i], ry[i]) in cell cells[i], the ground resources of the 3 x 3 cells around it, one run
    of `ground_by_cell` per column of cells (cell_start[c]: where cell c's run starts), within
    `radius` and inside the strip [x - radius, x + radius] as rounded. Sorted by robot, then
    squared distance, then ground index, as ``np.lexsort((g, d2, robot))`` sorts them."""
    r2 = radius * radius
    capacity = 0  # every resource in the cells looked into
    for i in range(len(rx)):
        for bottom in (cells[i] - grid - 1, cells[i] - 1, cells[i] + grid - 1):  # cells j - 1 .. j + 1
            capacity += cell_start[bottom + 3] - cell_start[bottom]
    robot = np.empty(capacity, np.int64)
    ground = np.empty(capacity, np.int64)
    dist2 = np.empty(capacity)
    count = 0
    for i in range(len(rx)):
        x, y = rx[i], ry[i]
        first = count  # robot i's resources are [first, count), kept sorted
        for bottom in (cells[i] - grid - 1, cells[i] - 1, cells[i] + grid - 1):
            for run in range(cell_start[bottom], cell_start[bottom + 3]):
                g = ground_by_cell[run]
                gx = ground_xy[g, 0]
                dx = gx - x
                dy = ground_xy[g, 1] - y
                d2 = dx * dx + dy * dy
                if d2 <= r2 and gx >= x - radius and gx <= x + radius:
                    # insert (d2, g) into the sorted run (a robot has only a few in reach)
                    k = count
                    while k > first and (dist2[k - 1] > d2 or (dist2[k - 1] == d2 and ground[k - 1] > g)):
                        dist2[k], ground[k] = dist2[k - 1], ground[k - 1]
                        k -= 1
                    robot[count], dist2[k], ground[k] = i, d2, g
                    count += 1
    return robot[:count], ground[:count], dist2[:count]

"""Where the resources lie at the start of a run, and where a respawned one reappears.

Every placement draws only from the `numpy.random.Generator` it is given, so the same seed gives
the same layout. All positions are [m, world frame]. A position is *valid* when it keeps
``resources.margin`` from the walls (``|x|, |y| <= L/2 - margin``) and lies at least
``resources.min_depot_clearance`` outside the depot disc, and at least one ``spacing`` outside
every drop zone it is given to keep clear: a resource inside a zone would count as delivered the
moment it is picked up. Which zones those are is the caller's (`swarm_sim.sites.zones_clear_of_resources`:
a delivery kind may let resources lie inside its zones).

Distributions:

- ``clustered``: ``clusters`` square grids of ``cluster_side x cluster_side`` resources (pitch
  ``spacing``), e.g. the queue paper's five 8 x 8 clusters; cluster squares never touch (at least one
  pitch between them) and every resource of a cluster is valid.
- ``uniform``: every resource independently uniform over the valid region.
- ``powerlaw``: Hecker & Moses (2015): piles of 4^j resources (a 2^j x 2^j grid) for
  ``j < powerlaw_levels``, with 4^(levels-1-j) piles of each size (so each size holds the same
  number of resources); piles of one resource are scattered uniformly, and so is whatever
  ``count`` holds beyond the piles.
- ``powerlaw_tiers``: the power law of the DDSA/MDBSA authors' loop functions
  (`powerlaw_tiers`): as many tiers as ``count`` needs, ``count`` split evenly over them, each
  tier's piles filled in turn and the last one cut short; every pile, singles included, is
  placed like a cluster.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

from swarm_sim.scenario.schema import ArenaConfig, DepotConfig, DropZoneConfig, ResourceConfig, ScenarioError

MAX_ATTEMPTS = 4096
"""Random candidate positions per cluster/pile (drawn in batches) before a layout restarts."""
BATCH = 256
"""Candidates drawn and tested at once."""
MAX_RESTARTS = 10
"""Fresh starts before a placement gives up with a ScenarioError."""


def _half_extent(cfg: ResourceConfig, arena: ArenaConfig) -> float:
    """Resource coordinates must satisfy |x|, |y| <= this [m]."""
    return arena.size / 2 - cfg.margin


Disc = tuple[float, float, float]
"""(x, y, radius) [m, world frame]: an area resources keep out of."""


def _keep_out(cfg: ResourceConfig, depot: DepotConfig, zones: Sequence[DropZoneConfig]) -> list[Disc]:
    """The depot disc widened by min_depot_clearance, and every zone of `zones` widened by
    spacing, except the depot's own drop zone: it keeps min_depot_clearance, as the key says
    (with a clearance below one spacing the zone's disc would otherwise decide)."""
    disc = (float(depot.center[0]), float(depot.center[1]), depot.radius)
    discs = [(disc[0], disc[1], depot.radius + cfg.min_depot_clearance)]
    for z in zones:
        own = (float(z.center[0]), float(z.center[1]), z.radius)
        if z.kind == "depot" and own == disc:
            continue
        discs.append((own[0], own[1], z.radius + cfg.spacing))
    return discs


def _clear(x: np.ndarray, y: np.ndarray, discs: list[Disc]) -> np.ndarray:
    """Which points (x, y) lie outside every disc."""
    ok = np.ones(np.shape(x), dtype=bool)
    for cx, cy, r in discs:
        ok &= np.hypot(x - cx, y - cy) >= r
    return ok


def _grid(side: int, spacing: float) -> np.ndarray:
    """(side^2, 2) offsets of a side x side grid centred on the origin, row by row."""
    ticks = (np.arange(side) - (side - 1) / 2) * spacing
    gx, gy = np.meshgrid(ticks, ticks)
    return np.column_stack([gx.ravel(), gy.ravel()])


def _grid_rows(side: int, n: int, spacing: float) -> np.ndarray:
    """(n, 2) the first n points of a side x side grid of pitch `spacing`, row by row from
    the origin along +x, rows stacked along +y (a power-law pile cut short)."""
    k = np.arange(n)
    return np.column_stack([(k % side) * spacing, (k // side) * spacing]).astype(float)


def _place_squares(
    half_spans: Sequence[float] | Sequence[tuple[float, float]],
    cfg: ResourceConfig,
    arena: ArenaConfig,
    depot: DepotConfig,
    rng: np.random.Generator,
    key: str,
    zones: Sequence[DropZoneConfig] = (),
) -> np.ndarray:
    """Centres (K, 2) for squares (half span h) or rectangles (half spans (hx, hy)) [m]:
    valid, and any two at least one pitch apart along x or y.

    Rejection sampling, largest first, BATCH candidates at a time; after MAX_ATTEMPTS
    candidates for one square the whole layout restarts; after MAX_RESTARTS it raises
    ScenarioError naming `key`.
    """
    half = _half_extent(cfg, arena)
    discs = _keep_out(cfg, depot, zones)
    spans = np.asarray(half_spans, dtype=float)
    if spans.ndim == 1:
        spans = np.column_stack([spans, spans])
    order = np.argsort(-spans.max(axis=1), kind="stable")
    for _ in range(MAX_RESTARTS):
        centres = np.zeros((len(spans), 2))
        placed: list[int] = []
        for i in order.tolist():
            hs = spans[i]
            room = half - hs
            if room.min() < 0:
                raise ScenarioError(
                    f"{key}: a group of {2 * hs[0]:.2f} x {2 * hs[1]:.2f} m does not fit in the arena "
                    f"(arena.size {arena.size} m, resources.margin {cfg.margin} m)"
                )
            for _ in range(MAX_ATTEMPTS // BATCH):
                c = rng.uniform(-room, room, size=(BATCH, 2))
                # the point of each candidate square nearest to each keep-out centre
                ok = np.ones(len(c), dtype=bool)
                for cx, cy, r in discs:
                    nx = np.clip(cx, c[:, 0] - hs[0], c[:, 0] + hs[0])
                    ny = np.clip(cy, c[:, 1] - hs[1], c[:, 1] + hs[1])
                    ok &= np.hypot(nx - cx, ny - cy) >= r
                if placed:
                    gap = np.abs(c[:, None, :] - centres[None, placed, :]) - spans[placed][None, :, :] - hs
                    ok &= (gap.max(axis=2) >= cfg.spacing).all(axis=1)
                hits = np.flatnonzero(ok)
                if len(hits):
                    centres[i] = c[hits[0]]
                    placed.append(i)
                    break
            else:
                break  # this square found no room: restart the whole layout
        else:
            return centres
    raise ScenarioError(
        f"{key}: cannot place {len(spans)} non-overlapping groups of resources in the "
        f"{arena.size} m arena (margin {cfg.margin} m, {cfg.min_depot_clearance} m clear of the "
        f"depot) after {MAX_RESTARTS} attempts"
    )


def _uniform(
    n: int, cfg: ResourceConfig, arena: ArenaConfig, depot: DepotConfig, rng: np.random.Generator,
    zones: Sequence[DropZoneConfig] = (),
) -> np.ndarray:
    """(n, 2) independent uniform valid positions (vectorised rejection sampling)."""
    half = _half_extent(cfg, arena)
    discs = _keep_out(cfg, depot, zones)
    if half < 0:
        raise ScenarioError(f"resources.margin: {cfg.margin} m leaves no room in the {arena.size} m arena")
    out = np.empty((n, 2))
    filled = 0
    for _ in range(MAX_ATTEMPTS):
        if filled == n:
            return out
        batch = rng.uniform(-half, half, size=(max(2 * (n - filled), 16), 2))
        ok = _clear(batch[:, 0], batch[:, 1], discs)
        take = batch[ok][: n - filled]
        out[filled : filled + len(take)] = take
        filled += len(take)
    if filled == n:
        return out
    raise ScenarioError(
        f"resources.min_depot_clearance: no room for resources {cfg.min_depot_clearance} m clear of "
        f"the depot inside the {arena.size} m arena (margin {cfg.margin} m)"
    )


def powerlaw_tiers(count: int) -> list[list[int]]:
    """Resources per pile, tier by tier (largest piles first), of the DDSA/MDBSA authors'
    power law; a pile of n holds the first n points of its side x side grid, row by row.

    ``DSA_loop_functions::PowerLawFoodDistribution`` (MARSLab-UTRGV/DDSA-Distributed-
    Deterministic-Spiral-Search-Algorithm, branch luki-dev, and MARSLab-UTRGV/Adaptive-
    Multiple-Distributed-Spiral-Search-Algorithm, branch luki-dev, source/DSA/
    DSA_loop_functions.cpp; the same function in both): the rank R = p + 1 for the least p >= 1
    with 4^p (1 + p) >= count; tier h < R has 4^h piles of side 2^(R-1-h); every tier but the
    first takes ceil(count / R) resources and the first the rest; piles are filled in turn and a tier stops at its share (160 resources: 40 in one 8 x 8 pile cut to 5
    rows, 40 in 4 x 4 piles (16, 16, 8), 40 in ten 2 x 2, 40 singles).
    """
    if count <= 0:
        return []
    p = 1  # the authors' loop raises p at least once
    while 4**p * (1 + p) < count:
        p += 1
    rank = p + 1
    if count % rank == 0:
        first = other = count // rank
    else:
        other = count // rank + 1
        first = other - (4**p * rank - count) % rank
    tiers = []
    for h in range(rank):
        quota, side = (first if h == 0 else other), 2 ** (rank - 1 - h)
        piles = []
        for _ in range(4**h):
            if quota <= 0:
                break
            piles.append(min(side * side, quota))
            quota -= piles[-1]
        tiers.append(piles)
    return tiers


def powerlaw_pile_sizes(levels: int) -> list[int]:
    """Pile sizes of the power-law distribution, largest first, piles of one included."""
    return [4**j for j in reversed(range(levels)) for _ in range(4 ** (levels - 1 - j))]


def place_resources(
    cfg: ResourceConfig, arena: ArenaConfig, depot: DepotConfig, rng: np.random.Generator,
    zones: Sequence[DropZoneConfig] = (),
) -> np.ndarray:
    """Initial resource positions, (cfg.count, 2) [m, world frame], deterministic per `rng`;
    `zones`: the drop zones to keep clear (`swarm_sim.sites.zones_clear_of_resources`).

    Raises ScenarioError naming the key when the layout cannot be placed.
    """
    if cfg.count == 0:
        return np.zeros((0, 2))
    if cfg.distribution == "uniform":
        return _uniform(cfg.count, cfg, arena, depot, rng, zones)
    if cfg.distribution == "clustered":
        if cfg.count != cfg.clusters * cfg.cluster_side**2:
            raise ScenarioError(
                f"resources.count: {cfg.count} != clusters * cluster_side^2 = "
                f"{cfg.clusters * cfg.cluster_side ** 2}"
            )
        half_span = (cfg.cluster_side - 1) * cfg.spacing / 2
        centres = _place_squares([half_span] * cfg.clusters, cfg, arena, depot, rng, "resources.clusters", zones)
        grid = _grid(cfg.cluster_side, cfg.spacing)
        return (centres[:, None, :] + grid[None, :, :]).reshape(-1, 2)
    if cfg.distribution == "powerlaw":
        sizes = powerlaw_pile_sizes(cfg.powerlaw_levels)
        if sum(sizes) > cfg.count:
            raise ScenarioError(
                f"resources.count: the power law with powerlaw_levels={cfg.powerlaw_levels} needs at "
                f"least {sum(sizes)} resources, got {cfg.count}"
            )
        piles = [s for s in sizes if s > 1]
        sides = [math.isqrt(s) for s in piles]
        centres = _place_squares(
            [(side - 1) * cfg.spacing / 2 for side in sides], cfg, arena, depot, rng,
            "resources.powerlaw_levels", zones,
        )
        parts = [c[None, :] + _grid(side, cfg.spacing) for c, side in zip(centres, sides)]
        parts.append(_uniform(cfg.count - sum(piles), cfg, arena, depot, rng, zones))
        return np.concatenate(parts, axis=0)
    if cfg.distribution == "powerlaw_tiers":
        tiers = powerlaw_tiers(cfg.count)
        grids = [_grid_rows(2 ** (len(tiers) - 1 - h), n, cfg.spacing)
                 for h, tier in enumerate(tiers) for n in tier]
        spans = [tuple((g.max(axis=0) - g.min(axis=0)) / 2) for g in grids]
        centres = _place_squares(spans, cfg, arena, depot, rng, "resources.count", zones)
        return np.concatenate([c - (g.max(axis=0) + g.min(axis=0)) / 2 + g
                               for c, g in zip(centres, grids)], axis=0)
    raise ScenarioError(f"resources.distribution: unknown distribution {cfg.distribution!r}")


def place_one(
    cfg: ResourceConfig,
    arena: ArenaConfig,
    depot: DepotConfig,
    rng: np.random.Generator,
    avoid: np.ndarray | None = None,
    zones: Sequence[DropZoneConfig] = (),
) -> np.ndarray:
    """One replacement resource (2,) [m, world frame] for respawn.

    A single resource drawn "by the distribution" is a 1 x 1 cluster or a pile of one, i.e. a
    uniform valid position for every distribution. It keeps at least one `spacing` from the
    positions in `avoid` (the resources on the ground) if one of BATCH candidates does.
    """
    candidates = _uniform(BATCH, cfg, arena, depot, rng, zones)
    if avoid is None or len(avoid) == 0:
        return candidates[0]
    d2 = ((candidates[:, None, :] - np.asarray(avoid)[None, :, :]) ** 2).sum(axis=2).min(axis=1)
    clear = np.flatnonzero(d2 >= cfg.spacing**2)
    return candidates[clear[0] if len(clear) else 0]

"""Queue geometry of queue_depot_traffic.md sec. IV/VII: containment, spacing, refusal."""

from __future__ import annotations

import itertools
import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.spatial import cKDTree

from depot_manager.draw import draw_layout, main
from depot_manager.geometry import (
    DepotGeometryConfig,
    Polyline,
    QueueLayout,
    multi_queue_layout,
    segment_intersections,
    single_queue_layout,
)

TOL = 1e-6
LANE_TOL = 1e-3
"""Lane distances hold up to the chord sagitta of the arc discretisation (geometry.ARC_STEP)."""
STEP = 0.04


def _radii(layout: QueueLayout, pts: np.ndarray) -> np.ndarray:
    return np.linalg.norm(pts - layout.config.center, axis=1)


def _self_clearance(line: Polyline, lane: float) -> float:
    """Min distance between points of one line more than 3 lanes of arc apart."""
    s, p = line.sample(STEP)
    pairs = cKDTree(p).query_pairs(2 * lane, output_type="ndarray")
    far = np.abs(s[pairs[:, 0]] - s[pairs[:, 1]]) > 3 * lane
    if not far.any():
        return math.inf
    return float(np.linalg.norm(p[pairs[far, 0]] - p[pairs[far, 1]], axis=1).min())


def _clearance(a: np.ndarray, b: np.ndarray) -> float:
    return float(cKDTree(b).query(a)[0].min())


def _trim(line: Polyline, head: float = 0.0, tail: float = 0.0) -> np.ndarray:
    s, p = line.sample(STEP)
    return p[(s >= head) & (s <= line.length - tail)]


def check_layout(layout: QueueLayout) -> None:
    cfg = layout.config
    lane, rp, rd = cfg.lane_spacing, cfg.perimeter_radius, cfg.depot_radius
    for ln in layout.lines():
        _, p = ln.sample(STEP)
        r = _radii(layout, p)
        assert r.max() <= rp + TOL, ln.name
        if layout.kind == "multi" or ln in layout.entry_lines:
            # Outside the depot disc, by at least a robot radius (robots touch it only at
            # docks). The single queue's inner legs and exit line cross the depot floor to
            # its centre, as the authors' exit paths do.
            assert r.min() >= cfg.dock_stop_radius - LANE_TOL, ln.name
        # Consecutive slots exactly one pitch apart, in order along the line, and no two
        # robots in slots of the same line overlap.
        sl, s = ln.slots(cfg.pitch), ln.slot_arclengths(cfg.pitch)
        assert np.all(np.diff(s) >= cfg.pitch - TOL)
        s_all, p_all = ln.sample(STEP)
        tail = p_all[s_all > s[-1]]  # no room for one more slot after the last
        assert len(tail) == 0 or np.linalg.norm(tail - sl[-1], axis=1).max() < cfg.pitch + TOL
        chord = np.linalg.norm(np.diff(sl, axis=0), axis=1)
        assert np.allclose(chord, cfg.pitch, atol=1e-6), ln.name
        dd = np.linalg.norm(sl[:, None] - sl[None], axis=2) + np.eye(len(sl)) * 1e9
        assert dd.min() >= cfg.robot_diameter - LANE_TOL, ln.name
    for ln in layout.entry_lines + layout.exit_lines:
        assert _self_clearance(ln, lane) >= lane - LANE_TOL, ln.name
    # Entry points start on the perimeter; exit points end on it.
    assert np.allclose(_radii(layout, layout.entry_points), rp)
    assert np.allclose(_radii(layout, layout.exit_points), rp)
    assert rd < layout.inner_radius < rp


def check_single(layout: QueueLayout) -> None:
    check_layout(layout)
    cfg = layout.config
    lane = cfg.lane_spacing
    (entry,), (exit_line,) = layout.entry_lines, layout.exit_lines
    assert len(layout.inner_queues) == cfg.docks
    for q, d in zip(layout.inner_queues, layout.docks):
        assert np.allclose(q.start, layout.inner_entry_point)
        assert np.allclose(q.end, layout.inner_exit_point)
        assert _clearance(q.points, d.stop[None]) < 1e-9  # passes through its dock
        assert np.all(_radii(layout, q.points[1:]) <= layout.inner_radius + TOL)  # after the head
        # The entry line stays a lane away from the inner queues except at the entry point,
        # and the exit line from them except at the inner exit point.
        assert _clearance(_trim(entry, tail=lane), _trim(q, lane)) >= lane - LANE_TOL
        # The exit line keeps a lane from the ring, the V and the dock; the inner queues' last
        # legs merge with it only at the inner exit point, inside the dock stops' circle.
        s_q, p_q = q.sample(STEP)
        to_dock = p_q[s_q <= q.cumulative[int(np.argmin(np.linalg.norm(q.points - d.stop, axis=1)))] + 1e-9]
        _, p_x = exit_line.sample(STEP)
        outer = p_x[_radii(layout, p_x) >= cfg.dock_stop_radius - TOL]
        assert _clearance(outer, to_dock) >= lane - LANE_TOL
    assert np.allclose(entry.end, layout.inner_entry_point)
    assert np.allclose(exit_line.start, layout.inner_exit_point)
    assert _radii(layout, entry.points[1:-1]).min() >= layout.inner_radius - TOL
    # The exit line leaves through the arcs' gap: it crosses no line and keeps a lane from the
    # entry line (the authors' exit paths, SetNestsPredefinedExitPathCoordinates).
    assert layout.crossings == ()
    assert _clearance(exit_line.sample(STEP)[1], entry.sample(STEP)[1]) >= lane - LANE_TOL
    assert np.linalg.norm(layout.entry_points[0] - layout.exit_points[0]) >= lane


def check_multi(layout: QueueLayout) -> None:
    check_layout(layout)
    cfg = layout.config
    lane, K = cfg.lane_spacing, cfg.docks
    assert len(layout.entry_lines) == len(layout.exit_lines) == len(layout.sectors) == K
    # Sectors tile the circle without overlap.
    for k, (a, b) in enumerate(layout.sectors):
        assert b - a == pytest.approx(2 * math.pi / K)
        nb = layout.sectors[(k + 1) % K][0]
        assert (nb - b) % (2 * math.pi) == pytest.approx(0.0, abs=1e-9) or math.isclose(
            (nb - b) % (2 * math.pi), 2 * math.pi
        )
    for k, (e, x) in enumerate(zip(layout.entry_lines, layout.exit_lines)):
        d = layout.docks[k]
        assert np.allclose(e.end, d.stop) and np.allclose(x.start, d.stop)
        meet = segment_intersections(e.points, x.points)  # only where they join: the dock
        assert np.allclose(meet, d.stop[None]), meet
        assert _clearance(_trim(e, tail=lane), _trim(x, head=lane)) >= lane - LANE_TOL
        # Every point of the sector's lines lies inside its own sector.
        a, _ = layout.sectors[k]
        for ln in (e, x):
            _, p = ln.sample(STEP)
            ang = (np.arctan2(*(p - cfg.center)[:, ::-1].T) - a) % (2 * math.pi)
            assert ang.max() <= 2 * math.pi / K + 1e-9, ln.name
    lines = layout.entry_lines + layout.exit_lines
    for i, j in itertools.combinations(range(len(lines)), 2):
        if lines[i].name[-1] == lines[j].name[-1]:
            continue  # same sector, checked above
        pi, pj = lines[i].sample(STEP)[1], lines[j].sample(STEP)[1]
        assert _clearance(pi, pj) >= lane - LANE_TOL, (lines[i].name, lines[j].name)
        assert len(segment_intersections(lines[i].points, lines[j].points)) == 0


def test_default_single_layout() -> None:
    layout = single_queue_layout()
    check_single(layout)
    assert 200 <= layout.capacity <= 240
    assert layout.exit_lines[0].length < 2.0  # from near the depot centre to the perimeter
    assert layout.crossings == ()


def test_default_multi_layout() -> None:
    layout = multi_queue_layout()
    check_multi(layout)
    assert 190 <= layout.capacity <= 240
    for x in layout.exit_lines:
        assert x.length < 2.0


def test_slots_along_known_line() -> None:
    line = Polyline("l", np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 0.5]]))
    sl = line.slots(0.2)
    assert np.allclose(sl[:6], [[0.2 * i, 0.0] for i in range(6)], atol=1e-6)
    # Across the corner the next slot is 0.2 m in a straight line: (1, y) with 0.2^2 = 0^2 + y^2.
    assert np.allclose(sl[6:], [[1.0, 0.2], [1.0, 0.4]], atol=1e-6)
    assert len(sl) == 8
    bent = Polyline("b", np.array([[0.0, 0.0], [0.9, 0.0], [0.9, 0.5]]))
    sb = bent.slots(0.2)
    assert np.allclose(sb[4], [0.8, 0.0], atol=1e-6)
    assert np.allclose(sb[5], [0.9, math.sqrt(0.2**2 - 0.1**2)], atol=1e-6)
    with pytest.raises(ValueError):
        line.slots(0.0)


def test_segment_intersections() -> None:
    a = np.array([[0.0, 0.0], [2.0, 0.0]])
    b = np.array([[1.0, -1.0], [1.0, 1.0], [1.5, -1.0]])
    assert np.allclose(segment_intersections(a, b), [[1.0, 0.0], [1.25, 0.0]])
    assert len(segment_intersections(a, a + [0, 0.1])) == 0


@pytest.mark.parametrize(
    ("kwargs", "name"),
    [
        ({"perimeter_radius": 0.85}, "perimeter_radius"),
        ({"perimeter_radius": 0.4}, "perimeter_radius"),
        ({"lane_spacing": 0.1}, "lane_spacing"),
        ({"docks": 0}, "docks"),
        ({"docks": 12}, "docks"),
        ({"slot_pitch": 0.1}, "slot_pitch"),
        ({"depot_radius": 0.0}, "depot_radius"),
    ],
)
@pytest.mark.parametrize("build", [single_queue_layout, multi_queue_layout])
def test_refuses_impossible(kwargs: dict, name: str, build) -> None:
    with pytest.raises(ValueError, match=name):
        build(DepotGeometryConfig(**kwargs))


def test_multi_fits_where_single_does_not() -> None:
    # Multi needs one lane above the dock lane; single needs ring + spiral: 0.9 m is between.
    cfg = DepotGeometryConfig(perimeter_radius=1.0)
    with pytest.raises(ValueError, match="perimeter_radius"):
        single_queue_layout(cfg)
    check_multi(multi_queue_layout(cfg))


configs = st.builds(
    DepotGeometryConfig,
    depot_center=st.tuples(st.floats(-3, 3), st.floats(-3, 3)),
    depot_radius=st.floats(0.3, 1.0),
    perimeter_radius=st.floats(1.0, 2.6),
    docks=st.integers(1, 8),
    lane_spacing=st.floats(0.17, 0.3),
    slot_pitch=st.one_of(st.none(), st.floats(0.17, 0.3)),
)


def _build_or_refuse(build, cfg: DepotGeometryConfig) -> QueueLayout | None:
    try:
        return build(cfg)
    except ValueError as e:
        msg = str(e)
        assert any(n in msg for n in ("perimeter_radius", "docks", "lane_spacing", "slot_pitch"))
        return None


@settings(max_examples=40, deadline=None)
@given(configs)
def test_single_property(cfg: DepotGeometryConfig) -> None:
    layout = _build_or_refuse(single_queue_layout, cfg)
    if layout is not None:
        check_single(layout)


@settings(max_examples=40, deadline=None)
@given(configs)
def test_multi_property(cfg: DepotGeometryConfig) -> None:
    layout = _build_or_refuse(multi_queue_layout, cfg)
    if layout is not None:
        check_multi(layout)


def test_default_params_fit_both() -> None:
    # The refusal path must not swallow ordinary configurations.
    for k in (1, 2, 3, 4):
        cfg = DepotGeometryConfig(docks=k)
        check_single(single_queue_layout(cfg))
        check_multi(multi_queue_layout(cfg))


def test_draw(tmp_path) -> None:
    out = draw_layout(single_queue_layout(), tmp_path / "s.png")
    assert out.stat().st_size > 10_000
    assert main(["--layout", "multi", "--out", str(tmp_path / "m.png")]) == 0
    assert (tmp_path / "m.png").stat().st_size > 10_000

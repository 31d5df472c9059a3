"""Scan-based obstacle avoidance: turns away toward free space, counts episodes, not ticks."""

from __future__ import annotations

import math

import numpy as np
import pytest

from swarm_controllers.avoidance import ObstacleAvoidance, ray_angles
from swarm_sim.scenario import AvoidanceConfig, ScanConfig

SCAN = ScanConfig()  # 24 rays over the full circle, range_max 3.5 m
AVOID = AvoidanceConfig()  # 0.3 m, front sector 2 rad, 1.5 rad/s


def clear() -> np.ndarray:
    return np.full(SCAN.rays, np.inf, dtype=np.float32)


def wall_scan(distance: float, normal: float, scan: ScanConfig = SCAN) -> np.ndarray:
    """Ranges to an infinite straight wall whose closest point is `distance` m away in
    direction `normal` [rad, robot frame]; inf for rays that never meet it or meet it beyond
    range_max."""
    out = []
    for a in ray_angles(scan):
        c = math.cos(a - normal)
        r = distance / c if c > 1e-9 else math.inf
        out.append(r if r <= scan.range_max else math.inf)
    return np.asarray(out, dtype=np.float32)


def test_ray_angles_follow_the_scan_convention():
    angles = ray_angles(SCAN)
    assert len(angles) == 24
    assert angles[12] == pytest.approx(0.0, abs=1e-12)  # straight ahead in the middle
    assert angles[0] == pytest.approx(math.pi)  # -pi wraps to +pi: straight behind
    assert angles[13] - angles[12] == pytest.approx(2 * math.pi / 24)
    partial = ray_angles(ScanConfig(rays=5, fov=math.pi))
    assert partial == pytest.approx([-math.pi / 2, -math.pi / 4, 0.0, math.pi / 4, math.pi / 2])


def test_front_sector_is_the_rays_within_half_front_fov():
    avoid = ObstacleAvoidance(AVOID, SCAN)
    # inc = 0.2618 rad: rays 9..15 are within +-1 rad of the heading, 8 and 16 are not.
    assert avoid.front_rays == tuple(range(9, 16))
    narrow = ObstacleAvoidance(AvoidanceConfig(front_fov=0.1), SCAN)
    assert narrow.front_rays == (12,)


def test_clear_scan_gives_none():
    avoid = ObstacleAvoidance(AVOID, SCAN)
    assert avoid.update(clear()) is None
    assert avoid.update(np.full(24, 3.0, dtype=np.float32)) is None
    assert avoid.events == 0 and not avoid.active


@pytest.mark.parametrize("ray", [0, 3, 6, 8, 16, 18, 21])
def test_obstacles_outside_the_front_sector_are_ignored(ray):
    ranges = clear()
    ranges[ray] = 0.1
    assert ObstacleAvoidance(AVOID, SCAN).update(ranges) is None


@pytest.mark.parametrize("ray", [9, 12, 15])
def test_anything_close_in_front_triggers(ray):
    ranges = clear()
    ranges[ray] = 0.29  # a robot, a wall or an obstacle: the scan does not care
    cmd = ObstacleAvoidance(AVOID, SCAN).update(ranges)
    assert cmd is not None and cmd.linear == 0.0 and abs(cmd.angular) == AVOID.turn_speed


def test_wall_ahead_turns_toward_the_free_side():
    # Wall 0.2 m away, its normal 0.5 rad to the right of the heading: the left is open.
    left = ObstacleAvoidance(AVOID, SCAN).update(wall_scan(0.2, -0.5))
    assert left is not None and left.linear == 0.0 and left.angular > 0.0
    # Mirror image: the wall is to the front-left, so turn right.
    right = ObstacleAvoidance(AVOID, SCAN).update(wall_scan(0.2, +0.5))
    assert right is not None and right.linear == 0.0 and right.angular < 0.0


def test_corner_turns_away_from_the_nearer_wall():
    # Corner: a wall ahead and one close on the right; much more room on the left.
    ranges = np.minimum(wall_scan(0.25, 0.0), wall_scan(0.15, -math.pi / 2))
    cmd = ObstacleAvoidance(AVOID, SCAN).update(ranges)
    assert cmd is not None and cmd.angular > 0.0


def test_one_event_per_episode_not_per_tick():
    avoid = ObstacleAvoidance(AVOID, SCAN)
    blocked = wall_scan(0.2, 0.0)
    for _ in range(5):
        assert avoid.update(blocked) is not None
    assert avoid.events == 1 and avoid.active
    assert avoid.update(clear()) is None
    assert not avoid.active
    for _ in range(3):
        avoid.update(blocked)
    assert avoid.events == 2
    avoid.update(clear())
    avoid.update(clear())
    avoid.update(blocked)
    assert avoid.events == 3


def test_turn_direction_is_kept_for_the_whole_episode():
    avoid = ObstacleAvoidance(AVOID, SCAN)
    first = avoid.update(wall_scan(0.2, -0.5))  # free side left
    assert first is not None and first.angular > 0
    # Mid-episode the free side flips; the robot keeps turning the same way (no dithering).
    again = avoid.update(wall_scan(0.2, +0.5))
    assert again is not None and again.angular == first.angular
    assert avoid.events == 1
    # A new episode chooses afresh.
    avoid.update(clear())
    new = avoid.update(wall_scan(0.2, +0.5))
    assert new is not None and new.angular < 0 and avoid.events == 2


def test_turn_rate_respects_the_robot_limit():
    cmd = ObstacleAvoidance(AvoidanceConfig(turn_speed=5.0), SCAN, max_angular=2.0).update(
        wall_scan(0.1, 0.0)
    )
    assert cmd is not None and abs(cmd.angular) == 2.0


def test_partial_field_of_view():
    scan = ScanConfig(rays=9, fov=math.pi)  # rays every pi/8 from -pi/2 to +pi/2
    avoid = ObstacleAvoidance(AvoidanceConfig(front_fov=1.0), scan)
    assert avoid.front_rays == (3, 4, 5)  # -pi/8, 0, +pi/8
    cmd = avoid.update(wall_scan(0.2, -0.6, scan))
    assert cmd is not None and cmd.angular > 0


def test_nan_rays_are_ignored_and_lists_work():
    avoid = ObstacleAvoidance(AVOID, SCAN)
    ranges = [math.inf] * 24
    ranges[12] = math.nan
    assert avoid.update(ranges) is None
    ranges[11] = 0.1
    assert avoid.update(ranges) is not None


def test_wrong_ray_count_is_refused():
    with pytest.raises(ValueError, match="sensors.scan.rays=24"):
        ObstacleAvoidance(AVOID, SCAN).update(np.full(10, np.inf, dtype=np.float32))

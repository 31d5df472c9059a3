"""The state machines of Fig. 1 and the PIDs of Table 1 (swarm_controllers.caging.motion)."""

from __future__ import annotations

import math

import pytest
from hypothesis import given
from hypothesis import strategies as st

from swarm_controllers.caging.config import CagingConfig, PidGains
from swarm_controllers.caging.motion import Formation, GoTo, Limits, Motion, Neighbour, Pid, Spin, deadband
from swarm_msgs_py.types import Pose2D

CFG = CagingConfig()
LIMITS = Limits(linear=0.5, angular=11.3, dt=0.1, sigma=math.radians(3.0))


def test_pid_by_hand():
    pid = Pid(PidGains(1.0, 0.01, 0.1), dt=0.1)
    assert pid(2.0) == pytest.approx(2.0 + 0.01 * 0.2)  # no derivative on the first step
    assert pid(1.0) == pytest.approx(1.0 + 0.01 * 0.3 + 0.1 * (1.0 - 2.0) / 0.1)
    pid.reset()
    assert pid(1.0) == pytest.approx(1.0 + 0.01 * 0.1)


@given(st.floats(-5, 5), st.floats(0, 1))
def test_deadband_keeps_only_what_exceeds_the_tolerance(error, tolerance):
    out = deadband(error, tolerance)
    assert abs(out) == pytest.approx(max(0.0, abs(error) - tolerance))
    assert out == 0.0 or math.copysign(1, out) == math.copysign(1, error)


def test_fig1a_rotates_first_then_moves_then_arrives():
    go = GoTo(CFG, LIMITS)
    pose = Pose2D(0.0, 0.0, 0.0)
    v, w = go.step(pose, (0.0, 1.0), 0.05)  # 90 deg to the left: rotate in place
    assert go.state is Motion.ROTATE and v == 0.0 and w > 0
    go = GoTo(CFG, LIMITS)
    v, w = go.step(Pose2D(0.0, 0.0, math.pi / 2 - math.radians(2)), (0.0, 1.0), 0.05)  # within sigma
    assert go.state is Motion.MOVE and v == pytest.approx(0.5) and w > 0  # kp D = 1 m/s, clamped
    v, w = go.step(Pose2D(0.0, 0.96, math.pi / 2), (0.0, 1.0), 0.05)
    assert go.state is Motion.ARRIVED and (v, w) == (0.0, 0.0)


def test_fig1a_drives_a_robot_to_a_point():
    go = GoTo(CFG, LIMITS)
    x, y, yaw = 0.0, 0.0, 2.5
    for _ in range(300):
        v, w = go.step(Pose2D(x, y, yaw), (1.2, -0.7), CFG.distance_tolerance)
        if go.state is Motion.ARRIVED:
            break
        yaw += w * LIMITS.dt
        x, y = x + v * math.cos(yaw) * LIMITS.dt, y + v * math.sin(yaw) * LIMITS.dt
    assert go.state is Motion.ARRIVED and math.hypot(x - 1.2, y + 0.7) <= CFG.distance_tolerance


def test_fig1b_spins_until_within_sigma():
    spin = Spin(CFG, LIMITS)
    yaw = -2.0
    for _ in range(100):
        v, w = spin.step(Pose2D(0.0, 0.0, yaw), (1.0, 1.0))
        assert v == 0.0
        if spin.state is Motion.ALIGNED:
            break
        yaw += w * LIMITS.dt
    assert spin.state is Motion.ALIGNED and abs(yaw - math.pi / 4) <= math.radians(3.0)


def _formation() -> Formation:
    return Formation(CFG, LIMITS, cage_radius=0.44)


def test_formation_arrives_within_d_of_its_place():
    f = _formation()
    assert f.step(Pose2D(1.0, 0.0, 0.0), (1.03, 0.02), None, []) == (0.0, 0.0)
    assert f.state is Motion.ARRIVED


def test_formation_holds_back_a_robot_that_ran_ahead_of_the_object():
    """A front robot 0.2 m too far from the object (beyond +-d) is pulled back toward it."""
    pose = Pose2D(0.64, 0.0, 0.0)
    ahead = _formation().velocity(pose, (1.44, 0.0), (0.0, 0.0), [])
    centred = _formation().velocity(Pose2D(0.44, 0.0, 0.0), (1.24, 0.0), (0.0, 0.0), [])
    # D_lambda: 0.8 m -> 0.5 m/s (capped); D_object: 0.15 m beyond d -> 0.15 + 0.01 x 0.015 back
    assert ahead == pytest.approx((0.5 - 0.15 - 0.01 * 0.15 * 0.1, 0.0))
    assert centred == pytest.approx((0.5, 0.0))


def test_formation_ignores_errors_within_the_tolerances():
    """D_object, D_ell, D_r within +-d and theta within +-sigma ask for nothing."""
    f = _formation()
    R = 0.44
    chord = 2 * R * math.sin(math.pi / 8)
    left = Neighbour((R * math.cos(math.pi / 4), R * math.sin(math.pi / 4)), chord, math.pi / 4, 1)
    right = Neighbour((R * math.cos(-math.pi / 4), R * math.sin(-math.pi / 4)), chord, math.pi / 4, -1)
    with_cage = f.velocity(Pose2D(R + 0.03, 0.0, 0.0), (R + 1.0, 0.0), (0.0, 0.0), [left, right])
    alone = _formation().velocity(Pose2D(R + 0.03, 0.0, 0.0), (R + 1.0, 0.0), None, [])
    assert with_cage == pytest.approx(alone)


def test_formation_closes_up_on_a_neighbour_along_the_cage():
    """A left neighbour 90 deg away instead of 45 draws the robot counter-clockwise (+y here)."""
    R = 0.44
    chord = 2 * R * math.sin(math.pi / 8)
    left = Neighbour((0.0, R), chord, math.pi / 4, 1)
    vx, vy = _formation().velocity(Pose2D(R, 0.0, 0.0), (R, 0.0001), (0.0, 0.0), [left])
    assert vy > 0 and vx < 0  # toward the neighbour, along the cage and along the chord


def test_formation_backs_up_when_the_sum_points_behind():
    f = _formation()
    v, w = f.step(Pose2D(1.0, 0.0, 0.0), (0.5, 0.0), None, [])
    assert v < 0 and f.state is Motion.MOVE

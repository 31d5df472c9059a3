"""The world core: observations, gripper, contacts, command clamping, determinism."""

from __future__ import annotations

import dataclasses
import math
import subprocess
import sys

import numpy as np
import pytest
from generic_robot import generic_scenario
from hypothesis import given, settings
from hypothesis import strategies as st

from swarm_controllers.cpfa.messages import PheromoneMessage
from swarm_msgs_py.geometry import wire_yaw, wrap_angle
from swarm_msgs_py.types import Command, DropEvent, Observation, PickupEvent, Pose2D
from swarm_sim.registry import task_factory
from swarm_sim.scenario import (
    DropZoneConfig,
    NoiseConfig,
    ObstacleConfig,
    Scenario,
    ScenarioError,
)
from swarm_sim.world import World
from swarm_sim.world.bullet import pybullet as p
from swarm_sim.world.observations import with_messages


def scenario(robots: int = 4, **fields) -> Scenario:
    return generic_scenario("cpfa", robots__count=robots, **fields)


@pytest.fixture
def make_world():
    worlds: list[World] = []

    def make(s: Scenario, seed: int | None = None) -> World:
        worlds.append(World(s, task_factory(s), seed))
        return worlds[-1]

    yield make
    for w in worlds:
        w.close()


def go_to(obs: Observation, target: tuple[float, float], speed: float = 0.16) -> Command:
    """Turn towards `target`, drive when roughly facing it (a test controller, not a behaviour)."""
    dx, dy = target[0] - obs.pose.x, target[1] - obs.pose.y
    error = wrap_angle(math.atan2(dy, dx) - obs.pose.yaw)
    return Command(speed if abs(error) < 0.3 else 0.0, max(-2.0, min(2.0, 4.0 * error)))


# --------------------------------------------------------------------------- observations


def test_reset_observations_at_tick_zero(make_world):
    w = make_world(scenario(5))
    obs = w.reset()
    assert w.robots == ("robot_0", "robot_1", "robot_2", "robot_3", "robot_4")
    assert list(obs) == list(w.robots) and w.tick == 0 and w.t_ns == 0
    truth = w.true_poses()
    for r, o in obs.items():
        assert o.robot == r and o.stamp_ns == 0 and o.messages == () and not o.sensed.carrying
        assert type(o.pose.x) is float and type(o.pose.yaw) is float and type(o.linear_velocity) is float
        assert o.pose.x == truth[r].x and o.pose.y == truth[r].y
        assert o.pose.yaw == wire_yaw(truth[r].yaw)
        assert o.ranges.dtype == np.float32 and o.ranges.shape == (24,)
        assert o.linear_velocity == 0.0 and o.angular_velocity == 0.0
    assert len({o.pose.yaw for o in obs.values()}) == 5  # random headings


def test_inlined_wire_yaw_is_bit_identical():
    from swarm_sim.world.observations import _wire_yaw

    rng = np.random.default_rng(0)
    values = [0.0, -0.0, math.pi, -math.pi, math.pi / 2, 1e-17, 7.0, -20.0, *rng.uniform(-10, 10, 2000)]
    assert all(_wire_yaw(float(y)) == wire_yaw(float(y)) for y in values)



@pytest.mark.parametrize("low, high", [(-math.pi, math.pi), (-10.0, 10.0)])
def test_compiled_wire_yaws_are_bit_identical(low, high):
    """The swarm's wire yaws in one compiled loop (`_wire_yaws`): bit for bit `_wire_yaw`'s, on
    world yaws (the compiled route) and on any yaws (partly the Python route)."""
    from swarm_sim.world.observations import _wire_yaw, _wire_yaws

    rng = np.random.default_rng(2)
    edges = [0.0, -0.0, math.pi, -math.pi, math.pi / 2, -math.pi / 2, 1e-17, -1e-300, 5e-324,
             math.nextafter(math.pi, 0.0), math.nextafter(-math.pi, 0.0)]
    yaws = np.array([*edges, *rng.uniform(low, high, 200_000)])
    want = np.array([_wire_yaw(y) for y in yaws.tolist()])
    got = np.array(_wire_yaws(yaws))
    assert got.view(np.int64).tolist() == want.view(np.int64).tolist()
    strided = np.column_stack([yaws, yaws, yaws])[:, 2]  # the odometry's yaw column
    assert np.array(_wire_yaws(strided)).view(np.int64).tolist() == want.view(np.int64).tolist()


def test_stale_rows_kernel_equals_the_numpy_comparison():
    """`_stale_rows` against the straightforward numpy version: the velocities, which rows differ
    bit for bit (0.0 against -0.0 too) or are not kept, and `held` afterwards."""
    from swarm_sim.world.core import _stale_rows

    rng = np.random.default_rng(5)
    n = 500
    for _ in range(20):
        v = rng.choice([0.0, -0.0, 0.16, 0.05], n)
        w = rng.choice([0.0, -0.0, 1.5, -0.3], n)
        yaw = rng.choice([0.0, math.pi / 2, 1.0, -2.0], n)
        vz = rng.choice([0.0, -0.0, 1e-6], n)
        kept = rng.random(n) < 0.7
        held = np.column_stack([v * np.cos(yaw), v * np.sin(yaw), vz, w])
        flip = rng.random((n, 4)) < 0.05
        held[flip] = rng.choice([0.0, -0.0, 0.1], int(flip.sum()))
        velocity = np.empty((n, 4))
        np.multiply(v, np.cos(yaw), out=velocity[:, 0])
        np.multiply(v, np.sin(yaw), out=velocity[:, 1])
        velocity[:, 2], velocity[:, 3] = vz, w
        same = (velocity.view(np.int64) == held.view(np.int64)).all(axis=1)
        want = np.flatnonzero(~(same & kept))
        stale = np.empty(n, dtype=np.intp)
        k = _stale_rows(v, np.cos(yaw), np.sin(yaw), vz, w, held, kept, stale)
        assert stale[:k].tolist() == want.tolist() and 0 < k < n
        assert held.view(np.int64).tolist() == velocity.view(np.int64).tolist()

def test_fast_observation_constructor_equals_the_dataclass_one():
    from swarm_sim.world.observations import _new_observation

    args = ("robot_1", 5, Pose2D(1.0, 2.0, 0.5), 0.1, -0.2, np.ones(3, np.float32), ("sensed",), ())
    fast, slow = _new_observation(*args), Observation(*args)
    assert type(fast) is Observation and fast == slow
    for f in dataclasses.fields(Observation):
        assert getattr(fast, f.name) is getattr(slow, f.name)
    with pytest.raises(dataclasses.FrozenInstanceError):
        fast.sensed = None


@pytest.mark.parametrize("slots", ["filled", "constructor"])
def test_swarm_observations_equal_the_dataclass_ones(slots):
    """Built field by field for the whole swarm (or, should the dataclasses change, by their
    constructors): the same objects as Observation(...) and Pose2D(...) give, field for field."""
    import swarm_sim.world.observations as observations

    rng = np.random.default_rng(1)
    n = 7
    robots = tuple(f"robot_{i}" for i in range(n))
    odometry = np.column_stack([rng.normal(size=(n, 2)), rng.uniform(-4.0, 4.0, n)])
    speeds, turns = rng.normal(size=n), rng.normal(size=n)
    ranges = rng.uniform(0.0, 3.0, (n, 24)).astype(np.float32)
    sensed = [("sensed", i) for i in range(n)]
    with pytest.MonkeyPatch.context() as m:
        if slots == "constructor":
            m.setattr(observations, "_OBSERVATION_SETTERS", None)
            m.setattr(observations, "_POSE_SETTERS", None)
        got = observations.observations(robots, 42, odometry, speeds, turns, ranges, sensed)
    assert list(got) == list(robots)
    for i, r in enumerate(robots):
        x, y, yaw = odometry[i].tolist()
        want = Observation(r, 42, Pose2D(x, y, wire_yaw(yaw)), float(speeds[i]), float(turns[i]), ranges[i],
                           sensed[i], ())
        o = got[r]
        assert type(o) is Observation and type(o.pose) is Pose2D and o == want
        assert type(o.pose.x) is float and type(o.linear_velocity) is float and o.sensed is sensed[i]
        assert o.ranges.base is ranges and np.array_equal(o.ranges, ranges[i])
        with pytest.raises(dataclasses.FrozenInstanceError):
            o.pose.x = 0.0


def test_reset_after_teleport_restores_the_start(make_world):
    w = make_world(scenario(3))
    start = w.reset()
    w.teleport({"robot_0": Pose2D(3.0, 3.0, 1.0)})
    assert w.reset() == start


def test_odometry_poses_are_the_unrounded_observation_poses(make_world):
    from swarm_msgs_py.odometry import decode_odometry, encode_odometry

    w = make_world(scenario(8))
    rng = np.random.default_rng(3)
    for _ in range(30):
        obs = w.step(random_commands(w.robots, rng))
        for r, raw in w.odometry_poses().items():
            o = obs[r]
            assert (o.pose.x, o.pose.y, o.pose.yaw) == (raw.x, raw.y, wire_yaw(raw.yaw))
            # what a graph controller decodes when the publisher encodes the raw pose
            wire = decode_odometry(encode_odometry(r, o.stamp_ns, raw, o.linear_velocity, o.angular_velocity))
            assert wire.pose == o.pose


def test_robots_start_on_a_grid_around_the_depot(make_world):
    s = generic_scenario("cpfa", robots__count=9, robots__start_spacing=0.4, depot__center=[1.0, -2.0])
    w = make_world(s)
    xy = sorted((round(q.x, 6), round(q.y, 6)) for q in w.true_poses().values())
    want = sorted((1.0 + 0.4 * a, -2.0 + 0.4 * b) for a in (-1, 0, 1) for b in (-1, 0, 1))
    np.testing.assert_allclose(xy, want, atol=1e-9)


def test_time_advances_one_tick_per_step(make_world):
    w = make_world(scenario(2))
    w.reset()
    obs = w.step({})
    assert w.tick == 1 and w.t_ns == 100_000_000
    assert all(o.stamp_ns == 100_000_000 for o in obs.values())
    assert w.observe() == obs



def test_observations_carry_no_messages_and_the_batch_runner_adds_its_inbox(make_world):
    """The world sends and carries no messages; the batch runner hands every behaviour the
    tick's inbox in a copy of its observation (`with_messages`): the same observation with the
    very same inbox tuple put in, as ``dataclasses.replace`` would give."""
    inbox = (PheromoneMessage(0, 1.0, 2.0), PheromoneMessage(0, -1.0, 0.5))
    w = make_world(scenario(3))
    w.reset()
    plain = w.step({})
    assert all(o.messages == () for o in plain.values()) and w.observe() == plain
    for o in plain.values():
        carrying = with_messages(o, inbox)
        assert carrying.messages is inbox and carrying == dataclasses.replace(o, messages=inbox)
        assert o.messages == ()  # the world's own observation is left as it was


def test_a_robot_drives_forward_at_the_commanded_speed(make_world):
    w = make_world(scenario(1))
    w.reset()
    w.teleport({"robot_0": Pose2D(2.0, 2.0, 0.5)})
    for _ in range(10):
        obs = w.step({"robot_0": Command(0.1, 0.0)})
    o = obs["robot_0"]
    assert o.pose.x == pytest.approx(2.0 + 0.1 * math.cos(0.5), abs=1e-6)
    assert o.pose.y == pytest.approx(2.0 + 0.1 * math.sin(0.5), abs=1e-6)
    assert o.linear_velocity == pytest.approx(0.1, abs=1e-6)
    for _ in range(10):
        obs = w.step({"robot_0": Command(0.0, 1.0)})
    assert obs["robot_0"].pose.yaw == pytest.approx(1.5, abs=1e-6)
    assert obs["robot_0"].angular_velocity == pytest.approx(1.0, abs=1e-6)


def test_walls_stop_robots(make_world):
    w = make_world(scenario(1))
    w.teleport({"robot_0": Pose2D(5.5, 0.0, 0.0)})
    for _ in range(40):
        w.step({"robot_0": Command(0.16, 0.0)})
    x = w.true_poses()["robot_0"].x
    assert 6.0 - 0.085 - 0.01 < x <= 6.0 - 0.085 + 0.002


def test_robots_stay_upright_at_fixed_height(make_world):
    """Crowd the swarm: contacts must not tip robots or let them drift in z."""
    w = make_world(scenario(16))
    rng = np.random.default_rng(0)
    for _ in range(150):
        w.step({r: Command(0.16, float(rng.uniform(-2, 2))) for r in w.robots})
    for body in range(16):
        pos, orn = p.getBasePositionAndOrientation(body, physicsClientId=w.client)
        assert abs(pos[2] - 0.05) < 1e-4
        assert abs(orn[0]) < 1e-6 and abs(orn[1]) < 1e-6


def test_detected_resources_are_nearest_first(make_world):
    w = make_world(scenario(1))
    xy = w.task.resource_positions()
    corner = xy[np.lexsort((xy[:, 1], xy[:, 0]))[0]]  # the lower-left corner of a cluster
    at = (float(corner[0]) + 0.07, float(corner[1]) + 0.06)
    w.teleport({"robot_0": Pose2D(*at, 0.0)})
    found = w.observe()["robot_0"].sensed.resources
    # the grid points at offsets (0.1, 0.1), (0.1, 0), (0, 0.1), (0, 0) are 0.05, 0.067, 0.081 and
    # 0.092 m away: nearest first is not the order of the resource indices
    want = [(corner[0] + dx, corner[1] + dy) for dx, dy in ((0.1, 0.1), (0.1, 0.0), (0.0, 0.1), (0.0, 0.0))]
    np.testing.assert_allclose(found, want, atol=1e-9)
    assert found[-1] == (float(corner[0]), float(corner[1]))
    assert all(type(v) is float for xy in found for v in xy)


def test_the_shared_readings_of_robots_detecting_nothing_equal_their_own(make_world):
    """`sense` hands robots that detect nothing one shared reading per gripper state: equal to
    the reading built from `sense_fields`, robot by robot, carrying or not, detecting or not."""
    from swarm_sim.world.tasks.foraging import ForagingSense

    w = make_world(scenario(6))
    xy = w.task.resource_positions()
    spots = [xy[0] + 0.02, xy[5] + 0.02, (0.0, 0.0), (0.0, 0.6), (0.6, 0.0), (-0.6, 0.0)]
    w.teleport({r: Pose2D(float(x), float(y), 0.0) for r, (x, y) in zip(w.robots, spots)})
    w.task._carrying[[1, 3]] = 7, 8  # two robots hold something (one of them detects resources)
    senses = w.task.sense()
    detected, carrying = w.task.sense_fields()
    assert [type(s) for s in senses] == [ForagingSense] * 6
    assert senses == [ForagingSense(d, c) for d, c in zip(detected, carrying)]
    assert [bool(d) for d in detected] == [True, True, False, False, False, False]
    assert carrying == [False, True, False, True, False, False]


@settings(max_examples=15, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), robots=st.integers(1, 40), resources=st.integers(1, 400))
def test_resources_in_reach_by_cells_are_those_of_testing_every_pair(seed, robots, resources):
    """The grid search finds exactly the (robot, resource) pairs testing every pair finds: within
    the radius and inside the strip [x - r, x + r] as rounded, also for resources placed one ulp
    either side of a robot's strip or circle, and for robots and resources off the grid."""
    import swarm_sim.world.tasks.foraging as foraging

    rng = np.random.default_rng(seed)
    s = generic_scenario("cpfa", robots__count=robots, arena__size=6.0, depot__radius=0.3,
                      resources__distribution="uniform", resources__count=5, resources__min_depot_clearance=0.1)
    with World(s, task_factory(s)) as w:
        w.teleport({r: Pose2D(*rng.uniform(-3.5, 3.5, 2), 0.0) for r in w.robots})  # the arena: +-3 m
        task = w.task
        pos, r = w.positions, task._near_r
        near = pos[rng.integers(0, robots, resources)]
        xy = near + rng.uniform(-1.5 * r, 1.5 * r, near.shape)
        edge = rng.uniform(size=resources) < 0.3  # on the strip's or circle's edge
        side = np.where(rng.uniform(size=resources) < 0.5, -1.0, 1.0)
        xy[edge, 0] = np.nextafter(near[edge, 0] + side[edge] * r, rng.choice([-np.inf, np.inf], edge.sum()))
        xy[edge, 1] = near[edge, 1]
        task._res_xy, task._on_ground = xy, np.ones(resources, dtype=bool)
        task._ground_changed()
        def d2(a, b):
            return (a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1])

        want = sorted(
            (i, d2(g_xy, xy_i), g)
            for i, xy_i in enumerate(pos.tolist()) for g, g_xy in enumerate(xy.tolist())
            if d2(g_xy, xy_i) <= r * r and xy_i[0] - r <= g_xy[0] <= xy_i[0] + r
        )
        with pytest.MonkeyPatch.context() as m:
            m.setattr(foraging, "_ALL_PAIRS", 0)  # always the cells
            robot, g, dist2 = task._near_resources()
    assert list(zip(robot.tolist(), dist2.tolist(), g.tolist())) == want
    i, j = np.divmod(task._cells(np.array([[-3.0, -3.0], [3.0, 3.0]])), task._grid)  # the arena's corners
    assert i.tolist() == j.tolist() == [1, math.floor(6.0 / task._cell) + 1] and i[1] <= task._grid - 2


# --------------------------------------------------------------------------- gripper


def test_pick_up_and_drop_at_the_depot(make_world):
    w = make_world(scenario(1))
    obs = w.reset()
    xy = w.task.resource_positions()
    n_ground = len(xy)
    target = xy[np.argmin(np.hypot(xy[:, 0], xy[:, 1]))]
    start = target * (1 - 0.4 / np.hypot(*target))  # 0.4 m short of it, towards the depot
    w.teleport({"robot_0": Pose2D(float(start[0]), float(start[1]), 0.0)})
    obs = w.observe()
    events = []
    for _ in range(300):
        obs = w.step({"robot_0": go_to(obs["robot_0"], (float(target[0]), float(target[1])))})
        events += w.drain_events()
        if obs["robot_0"].sensed.carrying:
            break
    assert obs["robot_0"].sensed.carrying
    (pick,) = events
    assert isinstance(pick, PickupEvent) and pick.robot == "robot_0" and pick.stamp_ns == w.t_ns
    assert math.hypot(pick.x - obs["robot_0"].pose.x, pick.y - obs["robot_0"].pose.y) <= 0.05 + 1e-9
    assert len(w.task.resource_positions()) == n_ground - 1
    assert w.task.carried_resource("robot_0") == pick.resource
    assert w.stats["robot_0"].pickups == 1

    for _ in range(1000):
        obs = w.step({"robot_0": go_to(obs["robot_0"], (0.0, 0.0))})
        if not obs["robot_0"].sensed.carrying:
            break
    assert not obs["robot_0"].sensed.carrying
    (drop,) = w.drain_events()
    assert isinstance(drop, DropEvent) and drop.zone == "depot" and drop.resource == pick.resource
    assert math.hypot(drop.x, drop.y) <= 0.5
    assert w.task.resources_delivered == 1 and w.stats["robot_0"].deliveries == 1
    assert len(w.task.resource_positions()) == n_ground - 1  # no respawn by default
    assert w.drain_events() == []


def test_an_empty_robot_in_the_depot_drops_nothing(make_world):
    w = make_world(scenario(4))
    for _ in range(20):
        w.step({})
    assert w.drain_events() == [] and w.task.resources_delivered == 0


def test_dwell_time_and_respawn(make_world):
    dock = DropZoneConfig("dock_0", (3.0, 3.0), 0.3, dwell=1.0, kind="dock")
    s = dataclasses.replace(
        scenario(1), drop_zones=(dock,), resources=dataclasses.replace(scenario(1).resources, respawn=True)
    )
    w = make_world(s)
    n_ground = len(w.task.resource_positions())
    r = w.task.resource_positions()[5]
    w.teleport({"robot_0": Pose2D(float(r[0]), float(r[1]), 0.0)})
    w.step({})
    assert w.observe()["robot_0"].sensed.carrying
    w.teleport({"robot_0": Pose2D(3.1, 3.0, 0.0)})
    first_inside = w.tick + 1
    ticks = 0
    while w.observe()["robot_0"].sensed.carrying:
        w.step({})
        ticks += 1
        assert ticks < 50
    events = w.drain_events()
    assert [type(e) for e in events] == [PickupEvent, DropEvent]
    assert events[1].zone == "dock_0"
    assert events[1].stamp_ns == (first_inside + 10) * s.dt_ns  # inside for 1.0 s = 10 ticks
    assert len(w.task.resource_positions()) == n_ground  # one new resource replaced the delivered one
    assert w.task.resources_delivered == 1


def test_leaving_the_zone_restarts_the_dwell(make_world):
    dock = DropZoneConfig("dock_0", (3.0, 3.0), 0.3, dwell=1.0, kind="dock")
    w = make_world(dataclasses.replace(scenario(1), drop_zones=(dock,)))
    r = w.task.resource_positions()[0]
    w.teleport({"robot_0": Pose2D(float(r[0]), float(r[1]), 0.0)})
    w.step({})
    for _ in range(3):
        w.teleport({"robot_0": Pose2D(3.0, 3.0, 0.0)})
        for _ in range(8):  # 0.8 s inside
            w.step({})
        w.teleport({"robot_0": Pose2D(4.0, 4.0, 0.0)})
        w.step({})
    assert w.observe()["robot_0"].sensed.carrying and w.task.resources_delivered == 0


# --------------------------------------------------------------------------- contacts


def head_on(make_world, towards: bool) -> World:
    w = make_world(scenario(2))
    w.teleport({"robot_0": Pose2D(-0.5, 0.0, 0.0), "robot_1": Pose2D(0.5, 0.0, math.pi)})
    speed = 0.16 if towards else -0.16
    for _ in range(60):
        w.step({"robot_0": Command(speed, 0.0), "robot_1": Command(speed, 0.0)})
    return w


def test_collision_time_accrues_when_robots_push_each_other(make_world):
    w = head_on(make_world, towards=True)
    # they touch after (1 - 0.17) / 0.32 = 2.6 s and push for the remaining ~3.4 s
    for r in w.robots:
        t = w.stats[r].collision_time_s
        assert 3.0 < t < 3.6
        assert t / 0.05 == pytest.approx(round(t / 0.05))  # whole substeps of dt / 2
    assert w.stats["robot_0"].collision_time_s == w.stats["robot_1"].collision_time_s
    gap = w.true_poses()["robot_1"].x - w.true_poses()["robot_0"].x
    assert gap > 0.17 - 0.01  # they pushed but did not pass through each other


def test_no_collision_time_when_apart(make_world):
    w = head_on(make_world, towards=False)
    assert all(s.collision_time_s == 0.0 for s in w.stats.values())


def test_driving_side_by_side_5_mm_apart_is_not_a_collision(make_world):
    w = make_world(scenario(2))
    w.teleport({"robot_0": Pose2D(-1.0, 0.0, 0.0), "robot_1": Pose2D(-1.0, 0.175, 0.0)})
    for _ in range(20):
        w.step({r: Command(0.16, 0.0) for r in w.robots})
    assert all(s.collision_time_s == 0.0 for s in w.stats.values())
    assert w.true_poses()["robot_1"].y - w.true_poses()["robot_0"].y == pytest.approx(0.175)


def test_touching_a_wall_is_not_a_robot_collision(make_world):
    w = make_world(scenario(1))
    w.teleport({"robot_0": Pose2D(5.8, 0.0, 0.0)})
    for _ in range(20):
        w.step({"robot_0": Command(0.16, 0.0)})
    assert w.stats["robot_0"].collision_time_s == 0.0


# --------------------------------------------------------------------------- commands


def test_nan_and_too_fast_commands_are_clamped_and_counted(make_world):
    w = make_world(scenario(3))
    w.teleport({
        "robot_0": Pose2D(-3.0, 3.0, 0.0),
        "robot_1": Pose2D(3.0, 3.0, 0.0),
        "robot_2": Pose2D(0.0, -3.0, 0.0),
    })
    before = w.true_poses()
    w.step({
        "robot_0": Command(math.nan, 0.0),
        "robot_1": Command(5.0, math.inf),
        "robot_2": Command(0.1, -1.0),
    })
    after = w.true_poses()
    assert after["robot_0"] == pytest.approx(before["robot_0"])  # NaN -> 0, no motion
    assert after["robot_1"].yaw == pytest.approx(0.0)  # inf turn rate -> 0
    assert after["robot_1"].x - before["robot_1"].x == pytest.approx(0.016, abs=1e-6)  # 0.16 m/s
    assert [w.stats[r].clamped_commands for r in w.robots] == [1, 1, 0]
    w.step({"robot_2": Command(-1.0, 9.0)})
    assert w.stats["robot_2"].clamped_commands == 1
    assert after["robot_2"].x + 0.01 > w.true_poses()["robot_2"].x  # moved backwards


def test_a_missing_robot_keeps_its_previous_command(make_world):
    w = make_world(scenario(1))
    w.teleport({"robot_0": Pose2D(0.0, 3.0, 0.0)})
    w.step({"robot_0": Command(0.1, 0.0)})
    x1 = w.true_poses()["robot_0"].x
    w.step({})
    assert w.true_poses()["robot_0"].x - x1 == pytest.approx(0.01, abs=1e-6)
    assert w.stats["robot_0"].clamped_commands == 0


def test_an_impossible_layout_raises_naming_the_key():
    s = generic_scenario("cpfa", robots__count=1, arena__size=3.0)  # five 8 x 8 clusters do not fit
    with pytest.raises(ScenarioError, match="resources.clusters"):
        World(s, task_factory(s))


def test_unknown_robot_id_raises_naming_it(make_world):
    w = make_world(scenario(2))
    with pytest.raises(ValueError, match="robot_7"):
        w.step({"robot_0": Command(0.1, 0.0), "robot_7": Command(0.1, 0.0)})
    with pytest.raises(ValueError, match="'bob'"):
        w.step({"bob": Command()})
    assert w.tick == 0


# --------------------------------------------------------------------------- odometry


def test_noisy_odometry_drifts_from_the_truth_deterministically(make_world):
    s = generic_scenario("cpfa", robots__count=2)
    s = dataclasses.replace(s, robots=dataclasses.replace(s.robots, odometry_noise=NoiseConfig(0.1, 0.1)))
    runs = []
    for _ in range(2):
        w = make_world(s)
        w.reset()
        for _ in range(100):
            obs = w.step({r: Command(0.16, 0.5) for r in w.robots})
        runs.append(obs)
        truth = w.true_poses()
        errors = [math.hypot(obs[r].pose.x - truth[r].x, obs[r].pose.y - truth[r].y) for r in w.robots]
        assert 1e-4 < max(errors) < 1.0
    assert runs[0] == runs[1]
    # noise does not change where the resources are
    assert np.array_equal(make_world(s).task.resource_positions(), make_world(scenario(2)).task.resource_positions())


# --------------------------------------------------------------------------- determinism


def random_commands(robots, rng: np.random.Generator) -> dict:
    return {r: Command(float(rng.uniform(-0.05, 0.2)), float(rng.uniform(-2.5, 2.5))) for r in robots}


def run(w: World, ticks: int, seed: int):
    rng = np.random.default_rng(seed)
    trace = [w.reset()]
    for _ in range(ticks):
        trace.append(w.step(random_commands(w.robots, rng)))
    return trace, w.drain_events(), {r: dataclasses.replace(s) for r, s in w.stats.items()}


def test_same_seed_same_commands_identical_observations(make_world):
    s = generic_scenario("cpfa", robots__count=12)
    noise = NoiseConfig(linear_std=0.05, angular_std=0.05)
    s = dataclasses.replace(
        s,
        robots=dataclasses.replace(s.robots, odometry_noise=noise),
        obstacles=(ObstacleConfig("box", (1.2, 0.0), (0.3, 1.0), 0.4),),
    )
    a = run(make_world(s), 200, seed=1)
    b = run(make_world(s), 200, seed=1)
    assert a[0] == b[0]
    assert a[1] == b[1] and a[2] == b[2]
    assert sum(st.collision_time_s for st in a[2].values()) > 0  # a run where robots interact
    c = run(make_world(s, seed=5), 200, seed=1)
    assert c[0][0] != a[0][0]


@settings(max_examples=10, deadline=None, derandomize=True)
@given(seed=st.integers(0, 2**31), robots=st.integers(1, 9))
def test_robots_stay_in_the_arena_and_apart(seed, robots):
    """Random driving in a small arena. A body moves up to one substep's travel into another
    before pybullet sees the contact and pushes it back: 0.16 m/s x 0.05 s = 8 mm into a wall,
    twice that between two robots closing head-on (or a robot pushed into a wall)."""
    s = generic_scenario(
        "cpfa", robots__count=robots, arena__size=2.0, depot__radius=0.3,
        resources__distribution="uniform", resources__count=10, resources__min_depot_clearance=0.1,
    )
    overlap = 2 * 0.16 * 0.05 + 1e-3
    with World(s, task_factory(s), seed) as w:
        rng = np.random.default_rng(seed)
        for _ in range(100):
            w.step(random_commands(w.robots, rng))
            xy = np.array([[q.x, q.y] for q in w.true_poses().values()])
            assert np.all(np.abs(xy) <= 1.0 - 0.085 + overlap)
            d = np.hypot(*(xy[:, None, :] - xy[None, :, :]).transpose(2, 0, 1))
            np.fill_diagonal(d, np.inf)
            assert np.all(d >= 0.17 - overlap)


def test_reset_replays_the_run(make_world):
    w = make_world(generic_scenario("cpfa", robots__count=6))
    first = run(w, 50, seed=2)
    second = run(w, 50, seed=2)
    assert first == second


# --------------------------------------------------------------------------- velocities pybullet keeps


def sticky_commands(robots, rng: np.random.Generator, last: dict) -> dict:
    """Commands as behaviours give them: most robots keep theirs, many stand still, turn in place
    or drive straight (what lets the world skip setting velocities pybullet already holds)."""
    out = {}
    for r in robots:
        u = rng.uniform()
        if r in last and u < 0.6:
            out[r] = last[r]
        elif u < 0.7:
            out[r] = Command(0.0, 0.0)
        elif u < 0.8:
            out[r] = Command(0.0, float(rng.choice([-1.5, 1.5])))
        elif u < 0.9:
            out[r] = Command(0.16, 0.0)
        else:
            out[r] = Command(float(rng.uniform(-0.05, 0.2)), float(rng.uniform(-2.5, 2.5)))
    return out


def trajectory(s: Scenario, seed: int, ticks: int, always_set: bool) -> list:
    """True poses, observations and stats of a run of sticky commands (a teleport half-way)."""
    rng = np.random.default_rng(seed)
    out, last = [], {}
    with World(s, task_factory(s)) as w, pytest.MonkeyPatch.context() as m:
        if always_set:  # the reference: every velocity set on every substep
            m.setattr(w, "_velocities_kept", lambda turning, touching: np.zeros(len(touching), dtype=bool))
        obs = w.reset()
        for k in range(ticks):
            if k == ticks // 2:
                w.teleport({w.robots[0]: Pose2D(0.3, 0.4, 1.0)})
            last = sticky_commands(w.robots, rng, last)
            obs = w.step(last)
            out.append((w.positions.tobytes(), w.headings.tobytes(), obs))
        out.append({r: dataclasses.replace(st) for r, st in w.stats.items()})
    return out


@settings(max_examples=6, deadline=None, derandomize=True)
@given(seed=st.integers(0, 2**31), robots=st.integers(8, 25), arena=st.sampled_from([2.5, 3.0]))
def test_skipping_velocities_pybullet_keeps_changes_nothing(seed, robots, arena):
    """A crowded swarm pushing, turning and stopping: bit for bit the run that sets every velocity."""
    s = generic_scenario("cpfa", robots__count=robots, arena__size=arena, depot__radius=0.3,
                      resources__distribution="uniform", resources__count=5, resources__min_depot_clearance=0.1)
    skipping = trajectory(s, seed, 120, always_set=False)
    assert skipping == trajectory(s, seed, 120, always_set=True)
    assert sum(st.collision_time_s for st in skipping[-1].values()) > 0  # robots did touch


def _holds_what_was_set(w: World, i: int) -> bool:
    (vx, vy, vz), (ax, ay, az) = p.getBaseVelocity(i, physicsClientId=w.client)
    return (vx, vy, vz, az) == tuple(w._held[i]) and ax == ay == 0.0


def test_pybullet_holds_exactly_the_velocities_taken_as_kept(make_world):
    """What `_velocities_kept` rests on: a robot it selects reads back, bit for bit, the velocity
    last set (and some robots it does not select do not)."""
    s = generic_scenario("cpfa", robots__count=25, arena__size=3.0, depot__radius=0.3,
                      resources__distribution="uniform", resources__count=5, resources__min_depot_clearance=0.1)
    w = make_world(s)
    rng = np.random.default_rng(0)
    w.reset()
    kept = changed = 0
    last: dict = {}
    for _ in range(100):
        last = sticky_commands(w.robots, rng, last)
        w.step(last)
        for i in range(w._n):
            exact = _holds_what_was_set(w, i)
            if w._kept[i]:
                assert exact, i
                kept += 1
            changed += not exact
    assert kept > 1000 and changed > 100


@pytest.mark.parametrize("how", ["teleported", "set upright"])
def test_a_robot_whose_pose_was_reset_gets_its_velocity_set_again(make_world, how):
    """Resetting a pose zeroes the velocity pybullet holds: the next substep must set it again,
    although the command did not change."""
    w = make_world(scenario(1))
    w.reset()
    w.teleport({w.robots[0]: Pose2D(-1.0, 0.5, 0.0)})  # heading 0: the same velocity bits after the reset
    go = {w.robots[0]: Command(0.16, 0.0)}
    for _ in range(3):
        w.step(go)
    assert w._kept[0] and _holds_what_was_set(w, 0)  # driving straight, touching nothing
    if how == "teleported":
        w.teleport({w.robots[0]: Pose2D(0.5, 0.5, 0.0)})
        start = w.positions[0].copy()
        w.step(go)
        assert w.positions[0, 0] - start[0] == pytest.approx(0.016, abs=1e-6)
    else:  # tilted behind the world's back: its read-back sets it upright, zeroing the velocity
        (x, y, z), _ = p.getBasePositionAndOrientation(0, physicsClientId=w.client)
        tilt = (math.sin(5e-4), 0.0, 0.0, math.cos(5e-4))
        p.resetBasePositionAndOrientation(0, (x, y, z), tilt, physicsClientId=w.client)
        p.resetBaseVelocity(0, tuple(w._held[0, :3]), (0.0, 0.0, 0.0), physicsClientId=w.client)
        w._read_state()
        assert p.getBasePositionAndOrientation(0, physicsClientId=w.client)[1][0] == 0.0  # upright again
    assert not w._kept[0] or _holds_what_was_set(w, 0)


def test_no_pybullet_banner_in_our_output():
    out = subprocess.run([sys.executable, "-m", "swarm_sim.batch", "--robots", "2", "--duration", "1"],
                         capture_output=True, text=True, timeout=120)
    assert out.returncode == 0, out.stderr
    assert "pybullet build time" not in out.stdout + out.stderr and "delivered" in out.stdout


def test_a_world_leaves_the_process_alone_and_the_batch_job_tunes_it():
    """`tune_malloc` changes glibc for the whole process, so building a World must not call it (a
    library, a test); the batch job (`swarm_sim.batch.run_one`: what swarm-batch and the sweeps'
    workers run) does. In a fresh process: this one may have been tuned by another test."""
    code = """
from swarm_sim.batch import run_one
from swarm_sim.registry import task_factory
from swarm_sim.scenario import load_scenario
from swarm_sim.world import core
s = load_scenario("cpfa", ["robots.count=2", "sim.duration=1"])
with core.World(s, task_factory(s)) as world:
    world.step({})
print(core._malloc_tuned)
run_one(("cpfa", ("robots.count=2", "sim.duration=1"), {}, 0))
print(core._malloc_tuned)
"""
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=300)
    assert out.returncode == 0, out.stderr[-2000:]
    assert out.stdout.split() == ["False", "True"]

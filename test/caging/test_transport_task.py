"""The transport world task: the object moves only by contact (planar floor friction), the
robots' sensors report detect and id, the state topics round-trip, and a cage of caging
behaviours holds the object on a straight and on a turning path."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

from swarm_controllers.caging.behaviour import Phase
from swarm_controllers.caging.metrics import inside_polygon, polyline_length
from swarm_controllers.caging.sensing import SENSING, STATE
from swarm_controllers.caging.task import OBJECT, WALL
from swarm_msgs_py.types import Command, Pose2D
from swarm_sim.behaviour import behaviour_rng
from swarm_sim.messaging import Router
from swarm_sim.protocol import ROBOTS
from swarm_sim.registry import make_behaviour, task_factory
from swarm_sim.scenario import load_scenario
from swarm_sim.world import World
from swarm_sim.world.bullet import pybullet as p

OBJECT_AT = (-1.5, -1.0)


def _world(*overrides: str, seed: int = 1) -> World:
    scenario = load_scenario("caging", ["sim.duration=120", *overrides], seed=seed)
    world = World(scenario, task_factory(scenario))
    p.resetBasePositionAndOrientation(world.task.body, [*OBJECT_AT, world.scenario.robots.height / 2],
                                      [0, 0, 0, 1], physicsClientId=world.client)
    world.task.post_step(0)
    return world


def _park(world: World) -> None:
    """Every robot in a row along the top wall, far from the object."""
    world.teleport({r: Pose2D(-3.0 + 0.3 * i, 4.0, 0.0) for i, r in enumerate(world.robots)})


def test_the_object_does_not_move_when_nothing_touches_it():
    with _world() as world:
        _park(world)
        commands = {r: Command(0.5, 1.0) for r in world.robots}  # robots spin in place far away
        for _ in range(300):
            world.step(commands)
        pose = world.task.object_pose
        assert (pose.x, pose.y, pose.yaw) == (*OBJECT_AT, 0.0)


def _push(*overrides: str) -> tuple[World, float]:
    """robot_0 drives into the object at 0.3 m/s for 3 s (0.9 m, the first 0.235 m to reach it)."""
    world = _world(*overrides)
    _park(world)
    world.teleport({"robot_0": Pose2D(OBJECT_AT[0] - 0.6, OBJECT_AT[1], 0.0)})
    for _ in range(30):
        world.step({"robot_0": Command(0.3, 0.0)})
    return world, world.task.object_pose.x - OBJECT_AT[0]


def test_a_robot_pushes_the_object_and_friction_stops_it():
    world, moved = _push()
    with world:
        # pushed straight ahead, a little less far than the robot went: each physics substep the
        # contact shares momentum between robot (0.69 kg) and object, and friction takes mu g dt
        assert 0.3 < moved < 0.665
        assert abs(world.task.object_pose.y - OBJECT_AT[1]) < 0.005  # Bullet cylinders: off by ~1 mm
        world.step({"robot_0": Command(-0.3, 0.0)})  # back off: the object stops at once
        stopped = world.task.object_pose
        for _ in range(20):
            world.step({"robot_0": Command(0.0, 0.0)})
        assert (world.task.object_pose.x, world.task.object_pose.y) == (stopped.x, stopped.y)


def test_a_heavier_object_moves_less_for_the_same_push():
    distances = []
    for mass in (0.3, 1.0, 3.0):
        world, moved = _push(f"transport.object.mass={mass}")
        world.close()
        distances.append(moved)
    assert distances[0] > distances[1] > distances[2] > 0


def test_sensors_report_detect_and_id():
    with _world() as world:
        _park(world)
        # robot_0 faces the object 0.1 m from its surface; robot_1 sits just left of robot_0;
        # robot_2 faces the east wall from 0.1 m
        x0 = OBJECT_AT[0] - 0.3 - 0.1 - 0.065
        world.teleport({"robot_0": Pose2D(x0, OBJECT_AT[1], 0.0),
                        "robot_1": Pose2D(x0, OBJECT_AT[1] + 0.2, 0.0),
                        "robot_2": Pose2D(5.0 - 0.165, 0.0, 0.0)})
        sense = world.observe()
        front = sense["robot_0"].sensed.proximity
        assert front[3] == front[4] == OBJECT  # the sensors at +-13 deg
        assert front[1] == "robot_1"  # 75 deg to the left
        assert front[8] == ""  # nothing behind
        assert sense["robot_2"].sensed.proximity[3] == WALL
        bodies = dict((name, (x, y)) for name, x, y in sense["robot_0"].sensed.bodies)
        assert bodies[OBJECT] == pytest.approx(OBJECT_AT)
        assert bodies["robot_1"] == pytest.approx((x0, OBJECT_AT[1] + 0.2))
        assert "robot_2" not in bodies  # beyond the position range
        assert SENSING.decode(SENSING.encode(5, sense["robot_0"].sensed)) == (5, sense["robot_0"].sensed)
        state = world.task.state()
        for st in STATE:
            stamp, value = st.decode(st.encode(7, state[st.field]))
            assert stamp == 7 and np.allclose(np.array(value, dtype=float), np.array(state[st.field], dtype=float))


def test_robots_and_object_start_in_the_landmark_rectangle_apart_and_out_of_sight():
    for seed in range(5):
        scenario = load_scenario("caging", seed=seed)
        with World(scenario, task_factory(scenario)) as world:
            obj = np.array([world.task.object_pose.x, world.task.object_pose.y])
            pos = world.positions
            assert (np.abs(obj) <= (4.0, 3.5)).all() and (np.abs(pos) <= (4.0, 3.5)).all()
            assert (np.hypot(*(pos - obj).T) > 0.3 + 0.065 + 0.2).all()
            gaps = np.hypot(*(pos[:, None] - pos[None]).transpose(2, 0, 1))[np.triu_indices(len(pos), 1)]
            assert gaps.min() >= 0.13
            assert all(OBJECT not in o.sensed.proximity for o in world.observe().values())


def _transport(path: list[tuple[float, float]], seconds: float = 120.0) -> dict:
    """Eight caging behaviours teleported into a complete cage around the object, then the
    transport stage of Alg. 6 along `path` (offsets from the object [m]); per tick, the cage
    polygon, the object and the phases."""
    with _world(f"sim.duration={seconds}") as world:
        s = world.scenario
        behaviours = {r: make_behaviour(s, r, behaviour_rng(s.seed, r)) for r in world.robots}
        center = OBJECT_AT
        world.teleport({r: Pose2D(*b._place(center), 0.0) for r, b in behaviours.items()})
        targets = [(center[0] + dx, center[1] + dy) for dx, dy in path]
        for b in behaviours.values():  # the state at the end of Alg. 5: the cage is complete
            b.recruiter, b.cage, b.path, b.center = "robot_0", set(world.robots), list(targets), center
            b._start_leg(0)
        router, obs, ticks = Router(), world.observe(), []
        for _ in range(s.ticks):
            inbox = router.take_before(ROBOTS, world.t_ns)
            commands = {}
            for r, b in behaviours.items():
                commands[r] = b.step(obs[r] if not inbox else dataclasses.replace(obs[r], messages=inbox))
                for m in commands[r].messages:
                    router.post(m)
            o = world.task.object_pose
            ticks.append(((o.x, o.y), world.positions.copy()))
            if all(b.phase is Phase.DONE for b in behaviours.values()):
                break
            obs = world.step(commands)
        return {"ticks": ticks, "done": all(b.phase is Phase.DONE for b in behaviours.values()),
                "planned": np.array([center, *targets])}


@pytest.mark.parametrize("path", [
    [(0.5, 0.0), (1.0, 0.0), (1.5, 0.0), (2.0, 0.0)],  # straight
    [(0.5, 0.0), (1.0, 0.0), (1.5, 0.5), (1.5, 1.0), (1.0, 1.5)],  # turning left twice
], ids=["straight", "turning"])
def test_the_cage_holds_the_object_along_a_path(path):
    run = _transport(path)
    assert run["done"]
    widest = 2 * 0.3 + 0.13  # adjacent robots' centres this far apart would let the object out
    for center, robots in run["ticks"]:
        assert inside_polygon(np.array(center), robots)
        assert np.hypot(*(robots - np.roll(robots, -1, axis=0)).T).max() < widest
    objects = np.array([c for c, _ in run["ticks"]])
    end = run["planned"][-1]
    assert math.dist(objects[-1], end) < 0.15  # the object lags its cage by the clearance and d
    planned = polyline_length(run["planned"])
    assert abs(polyline_length(objects) - planned) / planned < 0.15

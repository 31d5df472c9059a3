"""The robot models (`swarm_sim.robots`, `swarm_controllers.robots`) against hand-worked cases.

A stop-turn-go leg (the CPFA lineage's ``BaseController``): turns first, each lasting
0.105 x angle [deg] / ``RobotRotationSpeed`` [cm/s], so that the time spent turning is the angle
turned over the turn rate, then one straight drive of the whole distance at 16 cm/s. The foraging
example's three turning regimes (hard, soft, none, with hysteresis) and its diffusion. The Khepera
III's speed limit. Scenario keys: the model chosen by name, its values written in, refused with a
line naming the key.
"""

from __future__ import annotations

import functools
import math

import numpy as np
import pytest

from swarm_controllers.motion import ContinuousDrive, drive_for
from swarm_controllers.robots.stop_turn_go import PLAN_TIME, StopTurnGo
from swarm_controllers.robots.wheel_turning import WheelTurning
from swarm_msgs_py.types import Command, Pose2D
from swarm_sim import registry
from swarm_sim.registry import task_factory
from swarm_sim.robots import footbot
from swarm_sim.scenario import ScenarioError, load_scenario, scenario_from_dict, scenario_to_dict
from swarm_sim.world import World

DT = 0.1
DT_NS = 100_000_000


def _scenario(model: str, *more: str, name: str = "cpfa"):
    return load_scenario(name, [f"robots.model={model}", "robots.count=1", *more])


def _ranges(scenario, hits: dict[float, float]) -> np.ndarray:
    """A scan of `scenario`'s layout, inf but for rays at the given angles [deg] reading `hits`
    [m beyond the body]."""
    from swarm_controllers.avoidance import ray_angles

    angles = [math.degrees(a) for a in ray_angles(scenario.sensors.scan)]
    out = np.full(len(angles), np.inf, dtype=np.float32)
    for deg, beyond in hits.items():
        i = min(range(len(angles)), key=lambda k: abs(math.remainder(angles[k] - deg, 360.0)))
        out[i] = scenario.robots.diameter / 2 + beyond
    return out


# ---------------------------------------------------------------------- scenario keys


def test_a_platform_model_writes_its_body_speeds_and_ring_into_the_scenario():
    s = _scenario("footbot_cpfa")
    assert s.robots.diameter == pytest.approx(2 * 0.085036758)
    assert (s.robots.max_linear_speed, s.robots.mass, s.robots.planar) == (0.16, 1.6, True)
    assert s.robots.max_angular_speed == pytest.approx(2 * 0.08 / 0.14)  # RobotRotationSpeed 8 cm/s
    assert (s.sensors.scan.rays, s.sensors.proximity_ring.range) == (24, 0.1)
    from swarm_controllers.avoidance import ray_angles

    degrees = sorted(round(math.degrees(a) % 360, 6) for a in ray_angles(s.sensors.scan))
    assert degrees == [7.5 + 15 * k for k in range(24)]  # the foot-bot's sensor directions
    generic = load_scenario("cpfa", ["robots.model=generic"])
    assert (generic.robots.model, generic.robots.diameter, generic.robots.planar) == ("generic", 0.17, False)
    assert scenario_from_dict(scenario_to_dict(s)) == s  # bag metadata reads back the same robot


def test_the_foraging_foot_bot_sees_the_light_everywhere_and_food_under_its_ground_sensors():
    s = load_scenario("drtm", ["robots.model=footbot_foraging"])
    assert s.sensors.light_range == pytest.approx(math.hypot(4.0, 4.0))
    assert s.sensors.resource_detection_radius == pytest.approx(0.1 + math.hypot(0.063, 0.0116))
    assert s.robots.start_spacing == pytest.approx(s.robots.diameter)  # the e-pucks' 0.1 m raised to a body
    assert (s.robots.max_linear_speed, s.robots.max_angular_speed) == (0.1, pytest.approx(2 * 0.1 / 0.14))


@pytest.mark.parametrize(("overrides", "message"), [
    (["robots.model=roomba"], "robots.model: unknown robot model 'roomba' (known: footbot_cpfa, footbot_foraging, "
                              "generic, khepera3)"),
    (["robots.platform.diameter=0.2"], "robots.platform.diameter: the generic robot takes robots.diameter itself"),
    (["robots.platform.light_range=2"], "robots.platform.light_range: the generic robot takes sensors.light_range itself"),
    (["robots.model=khepera3", "robots.platform.ring_range=0.2"],
     "robots.platform.ring_range: the khepera3 robot model has no proximity ring"),
    (["robots.model=footbot_cpfa", "robots.platform.ring_range=0"], "robots.platform.ring_range: must be positive"),
    (["robots.model=khepera3", "robots.platform.max_linear_speed=-1"], "robots.platform.max_linear_speed: must be positive"),
    (["robots.wheel_turning.soft_turn_angle=95"], "robots.wheel_turning: need 0 <= no_turn_angle <= soft_turn_angle"),
    (["robots.stop_turn_go.angle_tolerance=0"], "robots.stop_turn_go.angle_tolerance: must be positive"),
])
def test_bad_robot_keys_are_refused_naming_the_key(overrides, message):
    with pytest.raises(ScenarioError) as error:
        load_scenario("cpfa", ["robots.model=generic", *overrides])
    assert str(error.value).startswith(message)


def test_a_platform_value_can_be_varied_alone():
    s = _scenario("footbot_cpfa", "robots.platform.max_linear_speed=0.3", "robots.planar=false")
    assert (s.robots.max_linear_speed, s.robots.diameter, s.robots.planar) == (0.3, 2 * 0.085036758, False)


def test_a_platform_sensor_range_can_be_varied_alone():
    """The sensor-range factor: the foraging foot-bot's light and food sensing at the e-puck
    scenario's ranges, and a longer ring, each leaving the rest of the model as it is."""
    base = load_scenario("drtm")
    s = load_scenario("drtm", ["robots.platform.light_range=2.0"])
    assert (s.sensors.light_range, s.sensors.resource_detection_radius) == (2.0, base.sensors.resource_detection_radius)
    s = load_scenario("drtm", ["robots.platform.resource_detection_radius=0.2"])
    assert (s.sensors.resource_detection_radius, s.sensors.light_range) == (0.2, base.sensors.light_range)
    s = load_scenario("drtm", ["robots.platform.ring_range=0.15"])
    assert (s.sensors.proximity_ring.range, s.robots.diameter) == (0.15, base.robots.diameter)
    with pytest.raises(ScenarioError, match="vary it with robots.platform.light_range"):
        load_scenario("drtm", ["sensors.light_range=3.0"])


@pytest.mark.parametrize(("override", "message"), [
    ("sensors.scan.rays=48", "sensors.scan.rays=48: the footbot_cpfa robot model sets it to 24 "
                             "(robots.model=generic takes it as given)"),
    ("sensors.proximity_ring.range=0.3", "sensors.proximity_ring.range=0.3: the footbot_cpfa robot model sets it to 0.1"),
    ("robots.max_angular_speed=2", "robots.max_angular_speed=2: the footbot_cpfa robot model sets it to 1.142857"),
    ("robots.diameter=0.3", "robots.diameter=0.3: the footbot_cpfa robot model sets it to 0.170073"),
])
def test_a_value_the_model_would_replace_is_refused_not_dropped(override, message):
    """A ``--set`` of a value the platform fixes names the key and how to vary it; the model's own
    value, and the same key on the generic robot, are taken."""
    with pytest.raises(ScenarioError) as error:
        load_scenario("cpfa", [override])
    assert str(error.value).startswith(message), str(error.value)
    if override.startswith(("robots.", "sensors.proximity_ring.range")):
        assert "vary it with robots.platform." in str(error.value)
    assert load_scenario("cpfa", ["sensors.scan.rays=24", "sensors.proximity_ring.range=0.1"]).sensors.scan.rays == 24
    generic = load_scenario("cpfa", ["robots.model=generic", override])
    key, value = override.split("=")
    assert float(functools.reduce(getattr, key.split("."), generic)) == float(value)


def test_the_papers_scenarios_run_on_their_authors_robots():
    """Every shipped scenario's robot is its algorithm's authors' robot, but for the DRTM paper's
    real-robot experiment (the e-puck scenarios), and each one also runs on the generic robot."""
    for name in registry.scenario_files():
        s = load_scenario(name)
        want = "generic" if name.startswith("drtm_epuck") else registry.of(s).authors_robot
        assert s.robots.model == want, name
        assert load_scenario(name, ["robots.model=generic"]).robots.model == "generic"


def test_drive_for_gives_each_model_its_motion_layer():
    kinds = {m: type(drive_for(_scenario(m))) for m in ("generic", "footbot_cpfa", "footbot_foraging", "khepera3")}
    assert kinds == {"generic": ContinuousDrive, "footbot_cpfa": StopTurnGo, "footbot_foraging": WheelTurning,
                     "khepera3": ContinuousDrive}


# ---------------------------------------------------------------------- stop-turn-go


def _leg(drive, target, seconds=12.0):
    """Drive `drive` toward `target` on exact kinematics (a tick either turns or drives);
    returns the ticks' twists and the final pose."""
    x = y = yaw = 0.0
    twists = []
    for k in range(round(seconds / DT)):
        drive.begin(k * DT_NS)
        v, w = drive.to_point(x, y, yaw, *target)
        assert v == 0.0 or w == 0.0, "a stop-turn-go tick mixes turning and driving"
        twists.append((v, w))
        yaw += w * DT
        x += v * DT * math.cos(yaw)
        y += v * DT * math.sin(yaw)
    return twists, (x, y, yaw)


def test_a_stop_turn_go_leg_turns_on_the_spot_then_drives_the_whole_distance():
    s = _scenario("footbot_cpfa")
    omega, v = s.robots.max_angular_speed, s.robots.max_linear_speed
    twists, (x, y, yaw) = _leg(StopTurnGo(s, np.random.default_rng(1)), (0.0, 1.0))
    # By hand: BaseController turns 0.105 x 90 deg / 8 cm/s = 1.181 s, which at 2 x 8 / 14 rad/s
    # is 0.859 of 90 deg (77.3 deg); the second stop turns 0.105 x 12.65 / 8 = 0.166 s (10.9 deg);
    # the 1.78 deg left is within the 0.1 rad tolerance, so it drives the whole 1 m: 6.25 s.
    errors = [math.pi / 2]
    while errors[-1] > s.robots.stop_turn_go.angle_tolerance:
        errors.append(errors[-1] - omega * 0.105 * math.degrees(errors[-1]) / 8.0)
    assert [round(math.degrees(e), 2) for e in errors] == [90.0, 12.65, 1.78]
    turning = sum(abs(w) for _, w in twists) * DT / omega
    driving = sum(v_ for v_, _ in twists) * DT / v
    assert turning == pytest.approx((errors[0] - errors[-1]) / omega)  # turn time = angle / turn speed
    assert yaw == pytest.approx(errors[0] - errors[-1])
    assert driving == pytest.approx(1.0 / v)  # then straight, the whole distance, blind
    last_turn = max(k for k, (_, w) in enumerate(twists) if w)
    assert all(w == 0.0 for _, w in twists[last_turn + 1:]) and all(v_ == 0.0 for v_, _ in twists[:last_turn])
    assert twists[0] == (pytest.approx(0.0), pytest.approx(omega * (DT - PLAN_TIME) / DT))  # it stands PLAN_TIME first
    assert (x, y) == (pytest.approx(math.cos(yaw)), pytest.approx(math.sin(yaw)))  # 1 m along the heading
    assert math.hypot(x, y - 1.0) < s.robots.stop_turn_go.distance_tolerance  # at the target: it stops
    assert twists[-1] == (0.0, 0.0)


def test_a_stop_turn_go_move_runs_to_its_end_whatever_the_target_does():
    d = StopTurnGo(_scenario("footbot_cpfa"), np.random.default_rng(1))
    d.begin(0)
    d.to_point(0.0, 0.0, 0.0, 1.0, 0.0)  # plan: drive 1 m ahead
    d.begin(DT_NS)
    assert d.to_point(0.0, 0.0, 0.0, 1.0, 0.0) == (pytest.approx(0.16), 0.0)
    d.begin(2 * DT_NS)
    assert d.to_point(0.016, 0.0, 0.0, -5.0, 3.0) == (pytest.approx(0.16), 0.0)  # the new target waits


def test_a_collision_turns_clockwise_on_either_side_then_pushes_a_blind_step():
    s = _scenario("footbot_cpfa")
    for side in (37.5, -37.5):
        d = StopTurnGo(s, np.random.default_rng(1))
        avoid = d.avoidance(0.1)
        d.begin(0)
        command = avoid.update(_ranges(s, {side: 0.05}))
        assert command == Command(0.0, -s.robots.max_angular_speed)  # SetLeftTurn(<0) and SetRightTurn(>0): RIGHT
        assert (avoid.events, avoid.active) == (1, True)
        moves = d._next[0]
        assert [m[0] for m in moves] == [1, 0, 2]  # the rest of the turn, a stop, the step
        assert moves[0][1] == pytest.approx(0.105 * 37.5 / 8.0 - DT)
        assert moves[2][1] == pytest.approx(s.robots.stop_turn_go.collision_step / 0.16)
        d.begin(DT_NS)  # clear now, but within collisionDelay: the turn drives forward instead
        assert avoid.update(_ranges(s, {})) == Command(pytest.approx(0.16), 0.0)
    d = StopTurnGo(s, np.random.default_rng(1))
    d.begin(0)
    assert d.update(_ranges(s, {172.5: 0.02})) is None  # behind the +-80 deg cone
    assert d.update(_ranges(s, {30.0: 0.2})) is None  # beyond the ring's 0.1 m


def test_the_ddsa_authors_collision_turns_away_by_37_5_deg_more_and_keeps_turning():
    """DDSA BaseController: readings at +37.5 deg (left) turn the robot right by 75 deg, readings
    at -37.5 deg turn it left by 75 deg; then the step, and no forward drive in place of the turn."""
    s = _scenario("footbot_cpfa", "robots.stop_turn_go.collision_turn=away")
    w = s.robots.max_angular_speed
    for side, sign in ((37.5, -1.0), (-37.5, 1.0)):
        d = StopTurnGo(s, np.random.default_rng(1))
        d.begin(0)
        assert d.update(_ranges(s, {side: 0.05})) == Command(0.0, sign * w)
        moves = d._next[0]
        assert [m[0] for m in moves] == [1, 0, 2]
        assert moves[0][1] == pytest.approx(0.105 * 75.0 / 8.0 - DT)  # 37.5 + 37.5 deg at 8 cm/s
        d.begin(DT_NS)  # clear now: it goes on turning (no collisionDelay branch)
        assert d.update(_ranges(s, {})) == Command(0.0, sign * w)
    with pytest.raises(ScenarioError, match="robots.stop_turn_go.collision_turn"):
        _scenario("footbot_cpfa", "robots.stop_turn_go.collision_turn=left")


def test_an_idle_robot_only_turns_on_a_collision():
    s = _scenario("footbot_cpfa")
    d = StopTurnGo(s, np.random.default_rng(1))
    d.begin(0)
    assert d.turn_only(_ranges(s, {37.5: 0.03})) == Command(0.0, -s.robots.max_angular_speed)
    d.begin(DT_NS)
    assert d.turn_only(_ranges(s, {})) is None  # Stop() before every Move(): the step never runs
    assert d._next[0] == ()


def test_on_a_queue_path_the_foot_bot_stops_for_what_is_ahead_and_drops_its_move():
    """The queue authors' FOLLOWING_ENTRY_PATH rule: a reading within +-30 deg stops the robot and
    drops the move under way (Stop()); once clear it plans anew toward the target of that time."""
    s = _scenario("footbot_cpfa", name="queue_qmt")
    d = StopTurnGo(s, np.random.default_rng(1))
    d.begin(0)
    d.to_point(0.0, 0.0, 0.0, 1.0, 0.0)  # a blind 1 m leg planned
    d.begin(DT_NS)
    assert d.to_point(0.0, 0.0, 0.0, 1.0, 0.0) == (pytest.approx(0.16), 0.0)
    assert d.path_stop(_ranges(s, {52.5: 0.02}), 30.0) is False  # beside, not ahead: goes on
    assert d.path_stop(_ranges(s, {22.5: 0.05}), 30.0) is True  # ahead within the ring: Stop()
    assert d._next[0] == ()
    d.begin(2 * DT_NS)
    assert d.to_point(0.016, 0.0, 0.0, 0.016, 1.0)[0] == 0.0  # the new target is read: it turns first
    assert ContinuousDrive(s).path_stop(_ranges(s, {0.0: 0.01}), 30.0) is None  # generic: the queue's own brake
    assert WheelTurning(_scenario("footbot_foraging"), np.random.default_rng(1)).path_stop(
        _ranges(s, {0.0: 0.01}), 30.0) is None


def test_argos_robots_start_with_their_centres_in_the_nest():
    """ARGoS's <distribute> only keeps bodies apart (the foraging example counts a robot in the nest
    by its position): 20 foot-bots fit the DRTM paper's 1 m nest; the generic robot keeps its whole
    body inside, as before."""
    from swarm_sim.robots import depot_start_room
    from swarm_sim.world.start import start_positions

    s = load_scenario("drtm_l3", ["robots.model=footbot_foraging"])
    assert depot_start_room(s) == s.depot.radius
    for seed in range(5):
        p = start_positions(s, np.random.default_rng(seed))
        assert np.all(np.hypot(*p.T) <= s.depot.radius)
        gaps = np.hypot(*(p[:, None] - p[None]).transpose(2, 0, 1))[np.triu_indices(len(p), 1)]
        assert gaps.min() >= s.robots.diameter
    g = load_scenario("drtm_l3", ["robots.model=generic"])
    assert depot_start_room(g) == g.depot.radius - g.robots.diameter / 2


# ---------------------------------------------------------------------- wheel_turning


def test_the_foraging_examples_three_turning_regimes():
    s = _scenario("footbot_foraging")
    top, turn_in_place = 0.1, 2 * 0.1 / footbot.INTERWHEEL_DISTANCE

    def at(drive, k, degrees, length=top):
        drive.begin(k * DT_NS)
        a = math.radians(degrees)
        return drive.twist_from_vector(length * math.cos(a), length * math.sin(a))

    d = WheelTurning(s)
    assert at(d, 0, 5.0) == (top, 0.0)  # within 10 deg: no turn
    assert at(d, 1, 50.0) == (top, pytest.approx(2 * top * (1 - (90 - 50) / 90) / 0.14))  # soft: f = (90 - 50) / 90
    assert at(d, 2, -100.0) == (0.0, -turn_in_place)  # above 90 deg: hard, wheels at -+max_speed
    assert at(d, 3, 80.0) == (0.0, turn_in_place)  # hysteresis: hard until 70 deg
    assert at(d, 4, 70.0)[0] == top  # soft again
    assert at(d, 5, 20.0)[1] > 0.0  # soft down to 10 deg
    assert at(d, 6, 10.0) == (pytest.approx(top), 0.0)
    assert at(d, 7, 0.0, length=0.04) == (0.04, 0.0)  # the base speed: the vector's length, at most max_speed


def test_the_foraging_examples_diffusion():
    s = _scenario("footbot_foraging")
    d = WheelTurning(s)
    d.begin(0)
    assert d.update(_ranges(s, {})) is None and not d.active  # nothing near: straight (no OAE)
    d.begin(DT_NS)
    command = d.update(_ranges(s, {7.5: 0.05, -7.5: 0.05}))  # ahead: away is straight back, a hard turn
    assert command is not None and command.linear == 0.0 and abs(command.angular) == pytest.approx(2 * 0.1 / 0.14)
    assert (d.events, d.active) == (1, True)
    d.begin(2 * DT_NS)
    assert d.update(_ranges(s, {52.5: 0.08})).angular < 0.0  # something to the left: turn right
    assert d.events == 1  # the same episode
    d.begin(3 * DT_NS)
    assert d.update(_ranges(s, {})) is None
    d.begin(4 * DT_NS)
    d.update(_ranges(s, {-97.5: 0.08}))
    assert d.events == 2


def test_the_foraging_foot_bot_homes_on_half_the_goals_angle():
    d = WheelTurning(_scenario("footbot_foraging"))
    d.begin(0)
    v, w = d.hold(math.radians(40.0))  # max_speed x (straight ahead + unit toward the goal): 20 deg, soft
    assert (v, w) == (0.1, pytest.approx(2 * 0.1 * (1 - (90 - 20) / 90) / 0.14))


# ---------------------------------------------------------------------- the world


def test_the_khepera_iii_cannot_go_faster_than_k_teams_regulated_limit():
    s = load_scenario("caging", ["robots.model=khepera3", "robots.count=8"])
    assert (s.robots.max_linear_speed, s.robots.diameter, s.robots.mass) == (0.298, 0.13, 0.69)
    assert s.robots.max_angular_speed == pytest.approx(2 * 0.298 / 0.0885)
    s = _scenario("khepera3", "resources.count=0", "resources.distribution=uniform")
    with World(s, task_factory(s)) as world:
        world.reset()
        world.teleport({"robot_0": Pose2D(-1.0, 0.0, 0.0)})
        for _ in range(10):
            world.step({"robot_0": Command(1.0, 0.0)})
        x = world.true_poses()["robot_0"].x
        assert world.stats["robot_0"].clamped_commands == 10
    assert x + 1.0 == pytest.approx(0.298 * 1.0, rel=1e-3)


def test_planar_robots_stay_upright_in_a_crowd():
    from swarm_sim.world.bullet import pybullet as p

    for model, bound in (("footbot_cpfa", 1e-25), ("generic", 1e-6)):
        s = load_scenario("queue_qmt", [f"robots.model={model}", "robots.count=24", "sim.duration=30"])
        from swarm_sim.behaviour import behaviour_rng
        from swarm_sim.registry import make_behaviour

        with World(s, task_factory(s)) as world:
            robots = {r: make_behaviour(s, r, behaviour_rng(s.seed, r)) for r in world.robots}
            obs = world.reset()
            tilts = []
            for _ in range(200):
                obs = world.step({r: b.step(obs[r]) for r, b in robots.items()})
                tilts.append(max(max(abs(q) for q in p.getBasePositionAndOrientation(i, world.client)[1][:2])
                                 for i in range(len(world.robots))))
        assert max(tilts) < bound, model
        if model == "generic":
            assert max(tilts) > 1e-20  # the generic robot keeps its old (tiny) tilts: bit-identical runs


def test_a_stop_turn_go_leg_in_the_world_ends_at_its_target():
    s = _scenario("footbot_cpfa", "resources.count=0", "resources.distribution=uniform")
    drive = drive_for(s, np.random.default_rng(2))
    with World(s, task_factory(s)) as world:
        obs = world.reset()
        world.teleport({"robot_0": Pose2D(1.0, 1.0, 0.0)})
        obs = world.observe()
        for _ in range(150):
            o = obs["robot_0"]
            drive.begin(o.stamp_ns)
            obs = world.step({"robot_0": Command(*drive.to_point(o.pose.x, o.pose.y, o.pose.yaw, 2.0, 2.5))})
        end = world.true_poses()["robot_0"]
    assert math.hypot(end.x - 2.0, end.y - 2.5) < s.robots.stop_turn_go.distance_tolerance


# ---------------------------------------------------------------------- graph == batch


@pytest.mark.parametrize(("model", "scenario"), [
    ("footbot_cpfa", "queue_qmt"),  # the CPFA and the queue strategy share one BaseController
    ("footbot_foraging", "drtm"),
    ("khepera3", "caging"),
])
def test_each_robot_model_runs_the_same_on_the_graph_as_in_batch(model, scenario, tmp_path):
    import os

    from swarm_sim.conformance import check_algorithm

    robots = 8 if scenario == "caging" else 6
    passed = check_algorithm(scenario, [f"robots.model={model}"], robots=robots, graph_bag=tmp_path / "bag",
                             domain_id=int(os.environ["ROS_DOMAIN_ID"]))
    assert passed[-1] == "graph_equals_batch"


def test_every_algorithm_names_its_authors_robot_and_the_comparisons_can_run_on_it():
    import argparse

    from swarm_sim import registry
    from swarm_sim.compare.commands import build_parser, plans_of
    from swarm_sim.compare.sweep import RunPlan
    from swarm_sim.robots import known_models

    assert {a.authors_robot for a in registry.algorithms()} <= set(known_models())
    assert registry.algorithm("drtm").authors_robot == "footbot_foraging"
    assert registry.algorithm("caging").authors_robot == "khepera3"

    class _Fake:
        @staticmethod
        def plans(args, strategies):
            return [RunPlan(s, None, ("robots.count=4", *args.overrides)) for s in strategies]

    args = argparse.Namespace(robot_model="authors", overrides=["robots.count=5"])
    plans = plans_of(_Fake, args, ["queue_qmt", "drtm", "caging"])
    assert [p.overrides for p in plans] == [
        ("robots.count=4", "robots.model=footbot_cpfa", "robots.count=5"),  # the user's --set still wins
        ("robots.count=4", "robots.model=footbot_foraging", "robots.count=5"),
        ("robots.count=4", "robots.model=khepera3", "robots.count=5"),
    ]
    args.overrides = ["robots.platform.diameter=0.07"]  # one platform value varied on the authors' robots
    assert plans_of(_Fake, args, ["drtm"])[0].overrides[1:] == (
        "robots.model=footbot_foraging", "robots.platform.diameter=0.07")
    args.overrides = ["robots.count=5"]
    args.robot_model = "khepera3"
    assert {p.overrides[1] for p in plans_of(_Fake, args, ["queue_qmt", "drtm"])} == {"robots.model=khepera3"}
    parser = build_parser({})
    with pytest.raises(SystemExit):
        parser.parse_args(["all", "--robot-model", "roomba"])
    assert parser.parse_args(["all", "--robot-model", "authors"]).robot_model == "authors"


def test_the_foot_bot_ring_is_cast_as_a_full_circle_with_the_same_hits(monkeypatch):
    import swarm_sim.world.raycast as raycast

    s = load_scenario("queue_qmt", ["robots.model=footbot_cpfa", "robots.count=200"])
    assert raycast.evenly_round(24, s.sensors.scan.fov) and not raycast.evenly_round(5, math.pi)
    scene = raycast.StaticScene.from_scenario(s)
    rng = np.random.default_rng(4)
    pos, yaw = rng.uniform(-4, 4, (200, 2)), rng.uniform(-math.pi, math.pi, 200)
    fast = raycast.nearest_hits(pos, yaw, 0.085, scene, 24, s.sensors.scan.fov, 3.5)
    monkeypatch.setattr(raycast, "evenly_round", lambda rays, fov: False)
    assert np.array_equal(fast, raycast.nearest_hits(pos, yaw, 0.085, scene, 24, s.sensors.scan.fov, 3.5))

"""Node tests: the world node and a controller node, each in its own rclpy context, talking to
a scripted peer node in the same executor (no subprocesses)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from rclpy.executors import SingleThreadedExecutor
from rclpy.node import Node

from swarm_controllers.cpfa import codec as pheromone
from swarm_controllers.cpfa.codec import PHEROMONES, PHEROMONES_TOPIC
from swarm_controllers.cpfa.messages import PheromoneMessage
from swarm_msgs_py import diagnostics, odometry, scan, topics, twist
from swarm_msgs_py.types import Pose2D
from swarm_sim.analysis.replay import load_run
from swarm_sim.inbound import Reason
from swarm_sim.nodes.controller_node import ControllerConfig, ControllerNode
from swarm_sim.nodes.qos import EVENTS, SENSOR_LOCKSTEP
from swarm_sim.nodes.world_node import WorldNode, WorldNodeConfig
from swarm_sim.recording import bag_info
from swarm_sim.scenario import load_scenario
from swarm_sim.world.tasks.foraging import ForagingSense
from swarm_sim.world.tasks.foraging_sensing import SENSING

SMALL = ("robots.count=2", "sim.duration=1.0", "arena.size=5.0", "resources.distribution=uniform",
         "resources.count=20", "resources.min_depot_clearance=0.3")


class ScriptedControllers(Node):
    """Answers every robot's observations with a command chosen by `policy(robot, stamp)`."""

    def __init__(self, robots, policy, context, forge=(), mute=None, repeat=()):
        super().__init__("scripted", context=context)
        self.repeat = repeat
        """Robots that send each answer twice (as for a re-sent tick), then a different one."""
        self.mute = mute or {}
        """robot -> the stamp [ns] from which it stops answering (its controller died)."""
        self.forge = forge
        """Robots that, besides answering, also send a command stamped for the previous tick."""
        self.pubs = {}
        self.seen = {r: [] for r in robots}
        for r in robots:
            self.pubs[r] = self.create_publisher(
                topics.type_of(topics.CMD_VEL), f"/{r}/{topics.CMD_VEL}", SENSOR_LOCKSTEP)
            self.create_subscription(
                topics.type_of(topics.ODOM), f"/{r}/{topics.ODOM}",
                lambda data, r=r: self._answer(r, data), SENSOR_LOCKSTEP, raw=True)
            for name in (topics.SCAN, topics.SENSE):
                self.create_subscription(topics.type_of(name), f"/{r}/{name}", lambda d: None,
                                         SENSOR_LOCKSTEP, raw=True)
        self.policy = policy

    def _answer(self, robot, data):
        stamp, pose, _, _ = odometry.decode_odometry(data)
        self.seen[robot].append(stamp)
        linear, angular = self.policy(robot, stamp)
        if stamp >= self.mute.get(robot, stamp + 1):
            return
        self.pubs[robot].publish(twist.encode_twist(robot, stamp, linear, angular))
        if robot in self.repeat:
            self.pubs[robot].publish(twist.encode_twist(robot, stamp, linear, angular))
            self.pubs[robot].publish(twist.encode_twist(robot, stamp, 0.15, 0.0))
        if robot in self.forge and stamp > 0:  # a late (or forged) answer for the previous tick,
            # sent last: were it applied, the robot would drive at 0.15 m/s
            self.pubs[robot].publish(twist.encode_twist(robot, stamp - 10**8, 0.15, 0.0))


def run_world(context, tmp_path, policy, overrides=SMALL, forge=(), mute=None, repeat=(), **config):
    cfg = WorldNodeConfig(overrides=overrides, bag=str(tmp_path / "bag"), startup_timeout=10.0, **config)
    world = WorldNode(cfg, context=context)
    peer = ScriptedControllers(world.robots, policy, context, forge=forge, mute=mute, repeat=repeat)
    executor = SingleThreadedExecutor(context=context)
    executor.add_node(world)
    executor.add_node(peer)
    try:
        world.run(executor)
    finally:
        world.close()
        executor.shutdown()
        world.destroy_node()
        peer.destroy_node()
    return world, peer, tmp_path / "bag"


def test_world_node_lockstep_records_every_tick(context, tmp_path):
    world, peer, bag = run_world(context, tmp_path, lambda r, s: (0.1, 0.0))
    ticks = 10
    assert world.world.tick == ticks
    for r in world.robots:
        assert peer.seen[r] == [k * world.scenario.dt_ns for k in range(ticks)]
        assert world.world.stats[r].stale_ticks == 0
    counts = bag_info(bag).message_counts
    assert counts["/clock"] == ticks + 1 and counts["/robot_0/cmd_vel"] >= ticks
    trace = load_run(bag)
    assert trace.sim_seconds == pytest.approx(1.0)
    assert set(trace.stats) == set(world.robots)


def test_world_node_clamps_nan_and_counts_stale(context, tmp_path):
    def policy(robot, stamp):
        return (math.nan, math.inf) if robot == "robot_0" else (0.0, 0.0)

    # robot_1 is connected (its topics matched) and never answers (not subscribed at all, the world
    # would first wait out its start-up timeout for it)
    world, _, bag = run_world(context, tmp_path, policy, mute={"robot_1": 0}, tick_timeout=0.05)
    assert world.world.stats["robot_0"].clamped_commands == 10
    stale = world.world.stats["robot_1"].stale_ticks
    assert stale == 10  # never answered: counted every tick, waited for only `dead_after` times
    trace = load_run(bag)
    assert trace.stats["robot_1"].stale_ticks == 10


def test_world_node_warns_and_ignores_unknown_robot(context, tmp_path):
    stranger = Node("stranger", context=context)
    pub = stranger.create_publisher(topics.type_of(topics.CMD_VEL), "/robot_99/cmd_vel", SENSOR_LOCKSTEP)
    pub.publish(twist.encode_twist("robot_99", 0, 1.0, 0.0))
    try:
        world, _, _ = run_world(context, tmp_path, lambda r, s: (0.0, 0.0))
    finally:
        stranger.destroy_node()
    assert "/robot_99/cmd_vel" in world.recorder.known
    assert "robot_99" not in world.world.stats


def _observation_bytes(scenario, robot, stamp, carrying=False):
    return {
        topics.ODOM: odometry.encode_odometry(robot, stamp, Pose2D(2.0, 0.0, 0.0), 0.0, 0.0),
        topics.SCAN: scan.encode_scan(robot, stamp, np.full(scenario.sensors.scan.rays, np.inf, np.float32),
                                      scenario.sensors.scan),
        topics.SENSE: SENSING.encode(stamp, ForagingSense((), carrying)),
    }


class _InboxLog:
    """A behaviour that logs the messages of every observation it is stepped on, then steps the
    real one (behaviours have slots: their methods cannot be replaced on the instance)."""

    def __init__(self, behaviour, inbox):
        self._behaviour, self._inbox = behaviour, inbox

    def step(self, obs):
        self._inbox.append(obs.messages)
        return self._behaviour.step(obs)

    def __getattr__(self, name):
        return getattr(self._behaviour, name)


def _world_running(peer: Node):
    """`peer` says on /world/run that its run goes on, as the world does (latched)."""
    from swarm_msgs_py import run_state
    from swarm_sim.nodes.qos import STATE_LATCHED
    from swarm_sim.nodes.run_watch import WORLD_RUN

    pub = peer.create_publisher(topics.import_type(run_state.TYPE_NAME), WORLD_RUN, STATE_LATCHED)
    pub.publish(run_state.encode_run_state("test", run_state.RUNNING, 0))
    return pub


def test_controller_node_answers_each_tick_and_delivers_messages_a_tick_later(context):
    scenario = load_scenario("cpfa", SMALL)
    node = ControllerNode("robot_0", ControllerConfig(overrides=SMALL), context=context)
    peer = Node("peer", context=context)
    _world_running(peer)  # a stand-in world: nodes answer its ticks only (`run_watch`)
    received, statuses, inbox = [], [], []
    peer.create_subscription(topics.type_of(topics.CMD_VEL), "/robot_0/cmd_vel",
                             lambda d: received.append(twist.decode_twist(d)), SENSOR_LOCKSTEP, raw=True)
    peer.create_subscription(topics.type_of(topics.STATUS), "/robot_0/status",
                             lambda d: statuses.append(diagnostics.decode_status(d)), EVENTS, raw=True)
    pubs = {n: peer.create_publisher(topics.type_of(n), f"/robot_0/{n}", SENSOR_LOCKSTEP)
            for n in topics.OBSERVATIONS}
    # the world's relay of what the other robots send, and its end that hears what robot_0 sends:
    # robot_0 answers only once both are matched
    laid = peer.create_publisher(topics.import_type(PHEROMONES.type_name), topics.heard(PHEROMONES_TOPIC), EVENTS)
    peer.create_subscription(topics.import_type(PHEROMONES.type_name), PHEROMONES_TOPIC, lambda d: None, EVENTS, raw=True)
    node.behaviour = _InboxLog(node.behaviour, inbox)
    executor = SingleThreadedExecutor(context=context)
    executor.add_node(node)
    executor.add_node(peer)
    try:
        for _ in range(100):  # let discovery settle
            executor.spin_once(timeout_sec=0.02)
            if all(p.get_subscription_count() for p in pubs.values()) and node.connect():
                break
        assert node.connect()
        dt = scenario.dt_ns
        laid.publish(pheromone.encode_pheromone(PheromoneMessage(stamp_ns=0, x=1.0, y=2.0)))
        for k in range(3):
            for name, data in _observation_bytes(scenario, "robot_0", k * dt).items():
                pubs[name].publish(data)
            for _ in range(200):
                executor.spin_once(timeout_sec=0.02)
                if len(received) > k:
                    break
        assert [r[0] for r in received] == [0, dt, 2 * dt]
        assert all(abs(r[1]) <= scenario.robots.max_linear_speed for r in received)
        # stamped 0 -> not visible at tick 0, visible (once) at tick 1
        assert inbox[0] == () and inbox[1] == (PheromoneMessage(0, 1.0, 2.0),) and inbox[2] == ()
        assert statuses and statuses[0].robot == "robot_0"
        assert node.get_clock().now().nanoseconds == 2 * dt  # its time: the stamps it stepped on
    finally:
        executor.shutdown()
        node.destroy_node()
        peer.destroy_node()


def test_controllers_hear_no_clock_and_keep_sim_time(context):
    """Controller nodes (issue 40): no /clock subscription, even with ``use_sim_time:=true`` on
    the command line; ``use_sim_time`` reads true, read-only, and says where their time comes from;
    their clocks read the stamp of the newest tick a node of the process stepped on."""
    from rclpy.parameter import Parameter

    from swarm_sim.nodes.executor import STAMP_TIME, StampTime

    shared = StampTime()
    nodes = [ControllerNode(f"robot_{i}", ControllerConfig(overrides=SMALL), context=context, stamp_time=shared,
                            cli_args=["--ros-args", "-p", "use_sim_time:=true"]) for i in range(2)]
    alone = ControllerNode("robot_2", ControllerConfig(overrides=SMALL), context=context)
    try:
        assert nodes[0].count_subscribers("/clock") == 0
        for n in (*nodes, alone):
            assert n.get_parameter("use_sim_time").value is True
            assert n.describe_parameter("use_sim_time").read_only
            assert n.describe_parameter("use_sim_time").description == STAMP_TIME
            assert not n.set_parameters([Parameter("use_sim_time", value=False)])[0].successful
            assert n.get_clock().ros_time_is_active and n.get_clock().now().nanoseconds == 0
        shared.set(7 * 10**8)
        assert [n.get_clock().now().nanoseconds for n in nodes] == [7 * 10**8] * 2
        assert alone.get_clock().now().nanoseconds == 0  # another process's clock
        plain = ControllerNode("robot_3", ControllerConfig(overrides=SMALL), context=context, plain_twist=True)
        try:  # a robot's own computer steps on wall time
            assert plain.get_parameter("use_sim_time").value is False and not plain.get_clock().ros_time_is_active
        finally:
            plain.destroy_node()
    finally:
        for n in (*nodes, alone):
            n.destroy_node()


def test_controller_node_refuses_bad_robot_id(context):
    with pytest.raises(ValueError, match="unknown robot id"):
        ControllerNode("rover-1", ControllerConfig(overrides=SMALL), context=context)


def test_world_node_survives_malformed_commands(context, tmp_path):
    junk = Node("junk", context=context)
    pub = junk.create_publisher(topics.type_of(topics.CMD_VEL), "/robot_0/cmd_vel", SENSOR_LOCKSTEP)

    def policy(robot, stamp):
        pub.publish(b"\x00\x01\x00\x00\x01")  # a truncated TwistStamped
        return (0.05, 0.0)

    try:
        world, _, bag = run_world(context, tmp_path, policy)
    finally:
        junk.destroy_node()
    assert world.world.tick == 10 and world.world.stats["robot_0"].stale_ticks == 0
    assert load_run(bag).sim_seconds == pytest.approx(1.0)


def test_commands_stamped_for_another_tick_are_ignored_in_lockstep(context, tmp_path):
    from swarm_sim.analysis.replay import load_odometry

    world, _, bag = run_world(context, tmp_path, lambda r, s: (0.0, 0.0), forge=("robot_0",))
    assert world.rejected_commands == world.world.tick - 1 == 9
    assert world.world.stats["robot_0"].stale_ticks == 0
    rows = load_odometry(bag)["robot_0"]
    assert (rows[:, 1:3] == rows[0, 1:3]).all()  # it never drove: the forged 0.15 m/s was not applied


def test_an_answer_repeated_is_recorded_once_and_a_different_second_one_refused(context, tmp_path):
    """A controller repeats its answer for every topic of a re-sent tick: the bag keeps one command
    per robot and tick. A second, different command for a tick already answered is refused and
    recorded apart, never applied."""
    from swarm_sim.analysis.replay import load_odometry

    world, _, bag = run_world(context, tmp_path, lambda r, s: (0.0, 0.0), repeat=("robot_0",))
    ticks = world.world.tick
    assert bag_info(bag).message_counts["/robot_0/cmd_vel"] == ticks == 10
    assert world.rejections.counts[("/robot_0/cmd_vel", Reason.REFUSED.value)] == ticks
    rows = load_odometry(bag)["robot_0"]
    assert (rows[:, 1:3] == rows[0, 1:3]).all()  # the second answer's 0.15 m/s was never applied


def test_a_dead_controllers_robot_stops_instead_of_driving_on_blind(context, tmp_path):
    from swarm_sim.analysis.replay import load_odometry

    world, _, bag = run_world(context, tmp_path, lambda r, s: (0.15, 0.0), mute={"robot_1": 3 * 10**8},
                              tick_timeout=0.05)
    rows = load_odometry(bag)["robot_1"]  # t, x, y, yaw per tick
    moving, after_death = rows[rows[:, 0] <= 0.3], rows[rows[:, 0] >= 0.6]
    assert np.ptp(moving[:, 1:3], axis=0).max() > 0.02  # it drove while its controller answered
    assert np.ptp(after_death[:, 1:3], axis=0).max() < 1e-9  # dead after 3 silent ticks: stopped


def test_no_message_on_any_topic_kills_or_stalls_a_controller(context):
    """Issue 25: a 4-byte message on every observation topic, an odometry at x = 1e308, a scan
    with a NaN and a 19 MB array on the relay topic, between ticks: the controller answers every tick and
    counts each by reason."""
    from swarm_msgs_py.diagnostics import OK, encode_diagnostics

    scenario = load_scenario("cpfa", SMALL)
    node = ControllerNode("robot_0", ControllerConfig(overrides=SMALL), context=context)
    peer = Node("peer", context=context)
    _world_running(peer)  # a stand-in world: nodes answer its ticks only (`run_watch`)
    received, reports = [], []
    peer.create_subscription(topics.type_of(topics.CMD_VEL), "/robot_0/cmd_vel",
                             lambda d: received.append(twist.decode_twist(d)), SENSOR_LOCKSTEP, raw=True)
    peer.create_subscription(topics.type_of(topics.DIAGNOSTICS), topics.DIAGNOSTICS,
                             lambda d: reports.append(diagnostics.decode_rejections(d)[1]), EVENTS, raw=True)
    pubs = {n: peer.create_publisher(topics.type_of(n), f"/robot_0/{n}", SENSOR_LOCKSTEP)
            for n in topics.OBSERVATIONS}
    laid = peer.create_publisher(topics.import_type(PHEROMONES.type_name), topics.heard(PHEROMONES_TOPIC), EVENTS)
    peer.create_subscription(topics.import_type(PHEROMONES.type_name), PHEROMONES_TOPIC, lambda d: None, EVENTS, raw=True)
    executor = SingleThreadedExecutor(context=context)
    executor.add_node(node)
    executor.add_node(peer)
    dt = scenario.dt_ns
    huge = encode_diagnostics(0, [(OK, "PheromoneMessage", "", "", (("stamp_ns", "0"), ("x", "1.0"), ("y", "1.0")))]
                              * 200_000)
    try:
        for _ in range(100):
            executor.spin_once(timeout_sec=0.02)
            if all(p.get_subscription_count() for p in pubs.values()) and node.connect():
                break
        for k in range(3):
            stamp = k * dt
            for pub in pubs.values():
                pub.publish(b"\x00\x01\x00\x00")
            pubs[topics.ODOM].publish(odometry.encode_odometry("robot_0", stamp, Pose2D(1e308, 0.0, 0.0), 0.0, 0.0))
            nan_scan = np.full(scenario.sensors.scan.rays, np.inf, np.float32)
            nan_scan[0] = np.nan
            pubs[topics.SCAN].publish(scan.encode_scan("robot_0", stamp, nan_scan, scenario.sensors.scan))
            laid.publish(huge)
            for name, data in _observation_bytes(scenario, "robot_0", stamp).items():
                pubs[name].publish(data)
            for _ in range(300):
                executor.spin_once(timeout_sec=0.02)
                if len(received) > k:
                    break
        assert [r[0] for r in received] == [0, dt, 2 * dt]
        for _ in range(20):
            executor.spin_once(timeout_sec=0.02)
        counts = reports[-1]["/robot_0/controller"]
        for name in pubs:
            assert counts[(f"/robot_0/{name}", "malformed")] == 3
        assert counts[("/robot_0/odom", "out of bounds")] == 3 and counts[("/robot_0/scan", "out of bounds")] == 3
        assert counts[(topics.heard(PHEROMONES_TOPIC), "too big")] == 3
    finally:
        executor.shutdown()
        node.destroy_node()
        peer.destroy_node()


def test_a_clock_from_the_future_never_moves_a_server_off_the_schedule(context):
    """Issue 25: one forged /clock 10^4 s ahead made the depot stop acknowledging the real ticks
    (the run ended "server depot died"); now it is refused and counted."""
    from swarm_msgs_py import ack, clock
    from swarm_sim.nodes.server_node import ServerNode, ServerNodeConfig

    config = ServerNodeConfig(scenario="queue_qmt", overrides=("robots.count=2",), startup_timeout=0.1)
    server = ServerNode("depot", config, context=context)
    peer = Node("peer", context=context)
    _world_running(peer)  # a stand-in world: nodes answer its ticks only (`run_watch`)
    acks = []
    clock_pub = peer.create_publisher(topics.type_of(topics.CLOCK), topics.CLOCK, SENSOR_LOCKSTEP)
    peer.create_subscription(topics.type_of(topics.LOCKSTEP_ACK), topics.LOCKSTEP_ACK,
                             lambda d: acks.append(ack.decode_ack(d)[1]), SENSOR_LOCKSTEP, raw=True)
    executor = SingleThreadedExecutor(context=context)
    executor.add_node(server)
    executor.add_node(peer)
    dt = server.scenario.dt_ns
    try:
        server.wait_for_robots(executor)
        for _ in range(100):
            executor.spin_once(timeout_sec=0.02)
            if clock_pub.get_subscription_count() and peer.count_publishers(topics.LOCKSTEP_ACK):
                break
        for stamp in (0, 10**13, dt, 3 * dt, 2 * dt):
            clock_pub.publish(clock.encode_clock(stamp))
            for _ in range(10):
                executor.spin_once(timeout_sec=0.02)
        assert acks == [0, dt, 2 * dt]
        assert server.endpoint.rejections.counts == {(topics.CLOCK, "wrong tick"): 2}
    finally:
        executor.shutdown()
        server.destroy_node()
        peer.destroy_node()

"""Fault injection on the real graph (swarm-run in subprocesses): hostile publishers, killed
controllers, servers and world, a closed terminal. Each run is short (6 robots, up to a few
hundred sim seconds at ~10x), bounded by timeouts, on the test's own domain; every process is
found by parentage (never by name) and stopped by process group at the end."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time
import warnings
from pathlib import Path

import numpy as np
import pytest
import rclpy
from graph_helpers import launch, overrides  # noqa: F401 - launch: a fixture
from rclpy.node import Node

from depot_manager.codec import DEPOT, DEPOT_REPORTS, DEPOT_STATE, RADIO, RADIO_TOPIC
from depot_manager.protocol import DepotReport, RadioReply, ReportKind
from launch_py.dds import discovery_port
from swarm_msgs_py import ack, clock, diagnostics, server_state, topics, twist
from swarm_msgs_py.types import NS_PER_S, NodeDownEvent
from swarm_sim.analysis.replay import load_odometry
from swarm_sim.nodes.qos import EVENTS, SENSOR_LOCKSTEP, STATE_LATCHED
from swarm_sim.recording import BagError, BagTruncatedWarning, bag_info, read_bag

REPO = Path(__file__).resolve().parents[1]
# Q_MT in a 7 x 7 m arena with 200 uniform resources: the first deliveries within a minute.
BUSY_DEPOT = ["arena.size=7.0", "resources.distribution=uniform", "resources.count=200"]


def _last(bag: Path, topic: str):
    """The last message on `topic` recorded so far (None before the bag or the topic exists)."""
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", BagTruncatedWarning)
            found = [m for m in read_bag(bag) if m.topic == topic]
    except BagError:
        return None
    return found[-1] if found else None


def _dock_occupant(bag: Path) -> str:
    m = _last(bag, DEPOT_STATE)
    return next((r for r in server_state.decode_state(m.data)[1]["docks"].values() if r), "") if m else ""


def _type_of(topic: str):
    """The message class of a run topic, the depot's protocol topics included."""
    families = {DEPOT_REPORTS: DEPOT, RADIO_TOPIC: RADIO}
    return topics.import_type(families[topic].type_name) if topic in families else topics.type_of(topic)


class Hostile(Node):
    """A node on the run's bus that sends what the issue's table lists, each a few times."""

    def __init__(self, context) -> None:
        super().__init__("hostile", context=context)
        self.stamp = 0
        self.create_subscription(topics.type_of(topics.CLOCK), topics.CLOCK,
                                 lambda d: setattr(self, "stamp", clock.decode_clock(d)), SENSOR_LOCKSTEP, raw=True)
        self.counted: dict[str, dict[tuple[str, str], int]] = {}
        """What each node of the run reports it rejected so far (its /diagnostics)."""
        self.create_subscription(topics.type_of(topics.DIAGNOSTICS), topics.DIAGNOSTICS,
                                 lambda d: self.counted.update(diagnostics.decode_rejections(d)[1]), STATE_LATCHED,
                                 raw=True)
        self.pubs = {t: self.create_publisher(_type_of(t), t, qos) for t, qos in (
            (RADIO_TOPIC, EVENTS), (DEPOT_REPORTS, EVENTS), ("/robot_0/status", EVENTS),
            ("/robot_1/cmd_vel", SENSOR_LOCKSTEP), (topics.LOCKSTEP_ACK, SENSOR_LOCKSTEP))}

    def ready(self) -> bool:
        return self.stamp > 0 and all(p.get_subscription_count() > 0 for p in self.pubs.values())

    def all_counted(self) -> bool:
        """Whether the run's nodes report every kind of forged message as rejected: the depot
        manager 3 untagged reports, the world the forged commands, ack and status. (Each kind is
        sent again until counted: a receiver that has not matched the forger yet drops what it
        sends, and half of it is best-effort.)"""
        depot, world = self.counted.get("/depot_manager", {}), self.counted.get("/world", {})
        return (depot.get((DEPOT_REPORTS, "unauthenticated"), 0) >= 3
                and {"late", "wrong tick", "malformed"} <= {r for w, r in world if w == "/robot_1/cmd_vel"}
                and world.get((topics.LOCKSTEP_ACK, "unauthenticated"), 0) >= 1
                and any(w == "/robot_0/status" for w, _ in world))

    def attack(self) -> None:
        s = self.stamp
        self.pubs[RADIO_TOPIC].publish(RADIO.encode(s, [RadioReply(s, "robot_1", "robot_0", 0.0, 0.0, "entry_line_0", 10**9, False)])[0])
        self.pubs[DEPOT_REPORTS].publish(DEPOT.encode(s, [
            DepotReport(s, f"robot_{900 + k}", ReportKind.JOIN, "entry_line_0", k) for k in range(4)])[0])
        self.pubs["/robot_0/status"].publish(diagnostics.encode_diagnostics(s, [(0, "robot_0", "", "", (("garbage", "1"),))]))
        self.pubs["/robot_1/cmd_vel"].publish(twist.encode_twist("robot_1", s - 5 * 10**8, 0.15, 0.0))
        self.pubs["/robot_1/cmd_vel"].publish(twist.encode_twist("robot_1", s + 5 * 10**8 + 1, 0.15, 0.0))
        self.pubs["/robot_1/cmd_vel"].publish(b"\x00\x01\x00\x00\xff")
        self.pubs[topics.LOCKSTEP_ACK].publish(ack.encode_ack("nobody", s))


def test_hostile_messages_are_rejected_counted_and_change_nothing(launch, tmp_path):
    run = launch("--scenario", "queue_qmt", "--robots", "6", "--duration", "150", *overrides(BUSY_DEPOT))
    # once the world is up (before, this participant would hold the domain and the run refuse it)
    run.wait_until(lambda: (run.bag / "metadata.yaml").exists(), what="the world up")
    # a client of the run's discovery server (the world), as `ros2` on this machine would be
    os.environ["ROS_DISCOVERY_SERVER"] = f"127.0.0.1:{discovery_port(int(os.environ['ROS_DOMAIN_ID']))}"
    ctx = rclpy.Context()
    rclpy.init(context=ctx)
    try:
        node = Hostile(ctx)  # the DDS participant is made here
    finally:
        del os.environ["ROS_DISCOVERY_SERVER"]
    executor = rclpy.executors.SingleThreadedExecutor(context=ctx)
    executor.add_node(node)
    try:
        deadline = time.monotonic() + 90
        while not node.ready():
            assert time.monotonic() < deadline and run.proc.poll() is None, (
                f"the run's topics never matched: clock {node.stamp}, "
                f"{ {t: p.get_subscription_count() for t, p in node.pubs.items()} }")
            executor.spin_once(timeout_sec=0.1)
        while not node.all_counted():
            assert time.monotonic() < deadline and run.proc.poll() is None, f"not all counted: {node.counted}"
            node.attack()
            end = time.monotonic() + 0.3
            while time.monotonic() < end:
                executor.spin_once(timeout_sec=0.05)
    finally:
        executor.shutdown()
        node.destroy_node()
        ctx.try_shutdown()
    code, summary, err = run.finish()
    assert code == 6, err[-3000:]  # a foreign publisher on cmd_vel, which carries no tag: tainted
    assert "/robot_1/cmd_vel" in " ".join(summary["foreign_publishers"]) and "the run is tainted" in err
    rejected = summary["rejected_messages"]
    assert rejected["/depot/reports"]["unauthenticated"] >= 3  # untagged: by the depot manager's node
    assert {"late", "wrong tick", "malformed", "foreign publisher"} <= set(rejected["/robot_1/cmd_vel"])  # by the world
    assert rejected["/lockstep/ack"]["unauthenticated"] >= 1
    assert summary["malformed_messages"] == 0  # the garbage status was refused and recorded apart:
    assert bag_info(run.bag).message_counts["/robot_0/status/refused"] >= 1
    assert summary["dead_nodes"] == [] and summary["stale_ticks"] == 0 and summary["run_ended"] == "complete"
    # nothing forged reached a core: the run is the batch run of the same seed
    batch = subprocess.run([sys.executable, "-m", "swarm_sim.batch", "--scenario", "queue_qmt", "--robots", "6",
                            "--duration", "150", "--json", *overrides(BUSY_DEPOT)],
                           capture_output=True, text=True, timeout=120, cwd=REPO)
    expected = json.loads(batch.stdout.strip().splitlines()[-1])
    assert summary["resources_delivered"] == expected["resources_delivered"] > 0
    assert summary["trips_by_robot"] == expected["trips_by_robot"]
    assert "messages from the bus were rejected" in err


def test_a_killed_controller_holding_a_dock_is_declared_dead_and_its_dock_freed(launch, tmp_path):
    # seed 0: the first robot docks at 25.7 s of sim; 150 s leave the others time to deliver after its death
    run = launch("--scenario", "queue_qmt", "--robots", "6", "--duration", "150", "--controller-processes", "0",
                 "--tick-timeout", "0.5", *overrides([*BUSY_DEPOT, "docking.unload_time=20.0", "robots.model=generic"]))
    run.wait_until(lambda: _dock_occupant(run.bag), timeout=120, what="a robot at a dock")
    victim = _dock_occupant(run.bag)
    os.kill(run.child("swarm_sim.nodes.controller_node", victim), signal.SIGKILL)
    code, summary, err = run.finish()
    assert code == 4, err[-3000:]
    assert summary["dead_nodes"] == [victim] and f"declared dead during the run: {victim}" in err
    assert summary["run_ended"] == "complete" and summary["sim_seconds"] == 150.0
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        events = [e for m in read_bag(run.bag) if m.topic == topics.WORLD_EVENTS
                  for e in diagnostics.decode_events(m.data)[1]]
    (down,) = [e for e in events if isinstance(e, NodeDownEvent)]
    assert down.node == victim and down.kind == "robot"
    # the robot does not drive from its death on (others may push it: it is a body in the way;
    # the generic robot, whose steering goes round a body, because the foot-bot's blind
    # stop-turn-go legs pushed it on 27 % of its ticks in one run), and the depot no longer holds
    # anything for it
    track = load_odometry(run.bag)[victim]
    after = track[track[:, 0] > down.stamp_ns / NS_PER_S + 0.2]
    still = np.hypot(*np.diff(after[:, 1:3], axis=0).T) < 1e-9
    assert len(after) > 100 and still.mean() > 0.8, still.mean()
    state = server_state.decode_state(_last(run.bag, DEPOT_STATE).data)[1]
    assert victim not in state["docks"].values() and victim not in state["slots"].values()
    # and the others keep delivering through the depot after it
    assert any(e.stamp_ns > down.stamp_ns and e.robot != victim for e in events if type(e).__name__ == "DropEvent")


@pytest.mark.parametrize("scenario, channel", [("queue_qmt", "depot"), ("mdbsa_d", "center")])
def test_a_killed_server_ends_the_run_with_a_clear_message(launch, scenario, channel):
    run = launch("--scenario", scenario, "--robots", "4", "--duration", "600", "--tick-timeout", "0.5")
    run.wait_until(lambda: run.sim_time() > 5.0, what="5 s of sim time")
    os.kill(run.child("swarm_sim.nodes.server_node"), signal.SIGKILL)
    code, summary, err = run.finish()
    assert code == 3, err[-3000:]
    assert summary["run_ended"] == f"server {channel} died" and summary["dead_nodes"] == [channel]
    assert f"server {channel}" in err and "the run ended early" in err
    assert 5.0 < summary["sim_seconds"] < 600.0 and summary["server_stale_ticks"] == 3
    assert not run.alive()


def test_a_killed_world_leaves_a_bag_that_rosbags_reads(launch):
    from rosbags.highlevel import AnyReader

    run = launch("--robots", "4", "--duration", "600", *overrides(["arena.size=5.0"]))
    run.wait_until(lambda: run.sim_time() > 8.0, what="8 s of sim time")
    os.kill(run.child("swarm_sim.nodes.world_node"), signal.SIGKILL)
    code, summary, err = run.finish()
    assert code == 5, err[-3000:]
    assert "the world node" in err and "was killed by signal 9" in err
    assert summary["run_ended"] == "cut off"
    with AnyReader([run.bag]) as reader:  # refused "File end magic is invalid" before the repair
        stamps = [t for c, t, _ in reader.messages() if c.topic == topics.CLOCK]
    assert summary["sim_seconds"] == max(stamps) / NS_PER_S and 8.0 <= summary["sim_seconds"] < 600.0
    assert not run.alive()


@pytest.mark.parametrize("how", [signal.SIGHUP, signal.SIGKILL])
def test_no_node_outlives_the_launcher(launch, how):
    """SIGHUP (the terminal closed) stops the run cleanly; SIGKILL of the launcher makes the
    kernel stop every child (PR_SET_PDEATHSIG), the world closing its bag."""
    run = launch("--robots", "4", "--duration", "600", "--controller-processes", "0", *overrides(["arena.size=5.0"]))
    run.wait_until(lambda: run.sim_time() > 3.0, what="3 s of sim time")
    assert len(run.children()) == 6  # world, the controllers' parent and its 4 forks
    os.kill(run.proc.pid, how)
    run.proc.communicate(timeout=90)
    if how == signal.SIGHUP:
        assert run.proc.returncode == 130
    deadline = time.monotonic() + 60
    while run.alive() and time.monotonic() < deadline:
        time.sleep(0.2)
    assert not run.alive()
    info = bag_info(run.bag)  # closed cleanly either way: no truncation warning
    assert not info.truncated and info.metadata["ended"] == "interrupted"

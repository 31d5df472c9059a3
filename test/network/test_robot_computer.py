"""A robot's own computer (issue 26, item 4): a controller that speaks plain geometry_msgs/Twist on
wall-clock time, on its own host, drives the world's robot in a realtime run.

The world plays a TurtleBot-class robot: started by hand (``swarm-world --bind``), its robot_0
topics remapped the standard way to a TurtleBot's root names (``/cmd_vel``, ``/odom``, ``/scan``),
taking plain Twist there (``--plain-twist robot_0``). The controller on ``hosta`` is pointed at
those names by the same ``--ros-args -r`` rules. Skipped without root.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import time

import numpy as np
import pytest
from multihost import REPO, node_env, start_echo
from netns import Testbed, available, leftovers

from launch_py.dds import discovery_port
from swarm_msgs_py.twist import decode_plain_twist
from swarm_sim.analysis.metrics import summarize
from swarm_sim.analysis.replay import load_odometry, load_run
from swarm_sim.recording import read_bag

TURTLEBOT = ["--ros-args", "-r", "/robot_0/cmd_vel:=/cmd_vel", "-r", "/robot_0/odom:=/odom",
             "-r", "/robot_0/scan:=/scan"]
"""The robot's topics under a TurtleBot's root names, for both ends."""
SCENARIO = ["--scenario", "cpfa", "--seed", "5", "--set", "robots.count=1", "--set", "sim.duration=12"]


def test_a_plain_twist_controller_on_its_own_host_drives_the_robot(tmp_path):
    why = available()
    if why is not None:
        pytest.skip(f"no network namespaces here: {why}")
    bed = Testbed(("world", "hosta", "cli"))
    bag = tmp_path / "bag"
    try:
        world_address = bed.address["world"]
        server = f"{world_address}:{discovery_port(int(os.environ['ROS_DOMAIN_ID']))}"
        world = bed.popen("world", [sys.executable, "-m", "launch_py.hosts", "world", "--bind", "eth0", *SCENARIO,
                                    "--mode", "realtime", "--plain-twist", "robot_0", "--bag", str(bag), *TURTLEBOT],
                          env=node_env(), cwd=REPO, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
        robot = bed.popen("hosta", [sys.executable, "-m", "launch_py.hosts", "controllers", "--bind", "eth0",
                                    "--discovery-server", server, "--robots", "robot_0", "--plain-twist", "--mode", "realtime", *SCENARIO,
                                    *TURTLEBOT], env=node_env(), cwd=REPO, stdout=subprocess.DEVNULL,
                          stderr=subprocess.PIPE, text=True)
        echo = start_echo(bed, server, "/cmd_vel", 3, 60, tmp_path)  # a TurtleBot's command topic
        sockets = set()
        deadline = time.monotonic() + 120
        while world.poll() is None:
            assert time.monotonic() < deadline, "the realtime run did not end in 120 s"
            assert robot.poll() in (None, 0), robot.stderr.read()[-2000:]  # 0: it heard the run's end
            for host in bed.address:
                sockets |= {(host, local) for _, local, _ in bed.sockets(host)}
            time.sleep(0.3)
        out = world.stdout.read()
        assert world.returncode == 0, out[-3000:]
        ended = time.monotonic()
        try:  # the robot's computer leaves by itself when its world ends the run
            left = robot.wait(5.0)
        except subprocess.TimeoutExpired:
            raise AssertionError("the robot's controller outlived its world by 5 s") from None
        robot_said = robot.stderr.read().strip().splitlines()[-1:]
        robot_after = time.monotonic() - ended
        heard = json.loads(echo.communicate(timeout=30)[0].strip().splitlines()[-1])
    finally:
        bed.close()
        assert leftovers() == []
    assert left == 0 and "the world ended the run (complete)" in robot_said[0], (left, robot_said, robot_after)
    assert heard["type"] == "geometry_msgs/msg/Twist" and heard["publishers"] == ["/robot_0/controller"], heard
    assert {h for h, _ in sockets} == {"world", "hosta", "cli"}
    assert [s for s in sockets if s[1].rpartition(":")[0] != bed.address[s[0]]] == []
    assert "1/1 controllers connected" in out, out[-2000:]
    commands = [decode_plain_twist(m.data) for m in read_bag(bag) if m.topic == "/robot_0/cmd_vel"]
    assert len(commands) > 20 and any(linear > 0 for linear, _ in commands)  # plain Twists, recorded
    summary = summarize(load_run(bag))
    assert summary["run_ended"] == "complete" and summary["mode"] == "realtime"
    counts = summary["commands_by_robot"]["robot_0"]
    ticks = round(summary["sim_seconds"] / 0.1)
    assert counts["lost"] < ticks / 2, counts  # its wall-clock commands arrived at most ticks
    rows = load_odometry(bag)["robot_0"]
    assert np.hypot(*(rows[-1, 1:3] - rows[0, 1:3])) > 0.1  # the world's robot drove

"""Across hosts without namespaces: the flags' checks, the bound profiles and environments, the
launcher's refusals, and the world's command bookkeeping (`CommandWatch`). The runs across
namespaces are in test/network (``scripts/test --network``)."""

from __future__ import annotations

import os
import subprocess
import sys
import xml.etree.ElementTree as ET
from pathlib import Path

import pytest
from hypothesis import given
from hypothesis import strategies as st

from launch_py import dds, hosts
from swarm_msgs_py.types import Command
from swarm_sim.nodes import endpoint
from swarm_sim.nodes.command_watch import CommandWatch

REPO = Path(__file__).resolve().parents[1]
DT = 100_000_000


@pytest.mark.parametrize("text, why", [
    ("0.0.0.0", "never every interface"),
    ("239.255.0.1", "multicast"),
    ("255.255.255.255", "broadcast"),
    ("192.0.2.7", "no interface of this host holds"),
    ("no-such-if0", "neither an IPv4 address nor an interface"),
    ("127.0.0.1; rm -rf /", "neither an IPv4 address nor an interface"),
])
def test_bind_refuses_what_is_not_one_local_address(text, why):
    with pytest.raises(hosts.HostError, match=why):
        hosts.bind_address(text)


def test_bind_takes_a_local_address_or_an_interface_name():
    assert hosts.bind_address("127.0.0.1") == "127.0.0.1"
    assert hosts.bind_address("lo") == "127.0.0.1"


@pytest.mark.parametrize("text", ["198.18.0.1", "198.18.0.1:0", "198.18.0.1:65536", "0.0.0.0:7150", "host:7150",
                                  "224.0.0.1:7150", ":7150"])
def test_a_discovery_server_is_an_address_and_a_port(text):
    with pytest.raises(hosts.HostError):
        hosts.server_address(text)
    assert hosts.server_address("198.18.0.1:7150") == ("198.18.0.1", 7150)


@pytest.mark.parametrize("role", hosts.ROLES)
def test_every_role_s_profile_names_only_its_address(role):
    profile = hosts.host_profile(role, "198.18.0.2", 7150)
    root = ET.fromstring(profile)
    addresses = {e.text for e in root.iter(f"{{{dds._PROFILE_NS}}}address")}
    assert addresses == {"198.18.0.2"}  # allow-list, unicast, metatraffic, peers: nothing else
    assert "0.0.0.0" not in profile and "127.0.0.1" not in profile
    assert ("<discoveryProtocol>SERVER</discoveryProtocol>" in profile) == (role == "server")
    assert f"<nanosec>{hosts.HEARTBEAT_NS}</nanosec>" in profile


def test_roles_find_the_server_as_their_flags_say(tmp_path):
    assert hosts.resolve("server", "lo", None, 150) == ("127.0.0.1", ("127.0.0.1", 6550))
    with pytest.raises(hosts.HostError, match="on its own --bind address"):
        hosts.resolve("server", "lo", "198.18.0.1:7150", 150)
    with pytest.raises(hosts.HostError, match="needs --discovery-server"):
        hosts.resolve("robot", "lo", None, 150)
    assert hosts.resolve("client", "lo", "198.18.0.1:7150", 150) == ("127.0.0.1", ("198.18.0.1", 7150))
    base = {"ROS_DISCOVERY_SERVER": "192.0.2.9:1", "ROS_STATIC_PEERS": "192.0.2.9", "PATH": "/bin"}
    server = hosts.host_env("server", 150, "127.0.0.1", ("127.0.0.1", 7150), tmp_path / "p.xml", base)
    robot = hosts.host_env("robot", 150, "127.0.0.1", ("198.18.0.1", 7150), tmp_path / "p.xml", base)
    cli = hosts.host_env("cli", 150, "127.0.0.1", ("198.18.0.1", 7150), tmp_path / "p.xml", base)
    assert "ROS_DISCOVERY_SERVER" not in server and "ROS_STATIC_PEERS" not in server
    assert robot["ROS_DISCOVERY_SERVER"] == "198.18.0.1:7150" and "ROS_SUPER_CLIENT" not in robot
    assert cli["ROS_SUPER_CLIENT"] == "TRUE"
    for env in (server, robot, cli):
        assert env["FASTRTPS_DEFAULT_PROFILES_FILE"] == str(tmp_path / "p.xml")
        assert env[hosts.ACK_WAIT_ENV] == str(hosts.ACK_WAIT) and env["ROS_DOMAIN_ID"] == "150"
    assert hosts.ACK_WAIT_ENV == endpoint.ACK_WAIT_ENV


def _run(*args: str) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "launch_py.run", "--domain-id", "auto", "--duration", "1", *args],
                          capture_output=True, text=True, cwd=REPO, timeout=120)


@pytest.mark.parametrize("args, why", [
    (["--bind", "0.0.0.0"], "never every interface"),
    (["--remote-controllers", "b=robot_0"], "needs --bind"),
    (["--bind", "lo", "--remote-controllers", "b=robot_0"], "needs --bind (an address the other hosts reach) and "
                                                           "--key-file"),
    (["--bind", "lo", "--key-file", "k", "--remote-controllers", "b=robot_99"], "no robot 'robot_99'"),
    (["--bind", "lo", "--key-file", "k", "--remote-controllers", "b=robot_0", "--remote-controllers", "c=robot_0"],
     "named twice"),
    (["--bind", "lo", "--key-file", "k", "--remote-controllers", "b=robot_0", "--plain-twist"], "--mode realtime"),
    (["--bind", "lo", "--discovery", "simple"], "discovers through the world"),
    (["--bind", "lo", "--shared-memory"], "--shared-memory is for a run on one host"),
    (["--remote-controllers", "robot_0"], "expected HOST=ROBOT"),
])
def test_swarm_run_refuses_a_bad_host_set_up_before_starting_anything(args, why, tmp_path):
    done = _run("--out", str(tmp_path), *args)
    assert done.returncode == 2 and why in done.stderr, done.stderr
    assert "Traceback" not in done.stderr
    assert not any(tmp_path.iterdir()) and not (REPO / "k").exists()


def test_the_node_commands_take_the_host_flags_and_refuse_bad_ones():
    done = subprocess.run([sys.executable, "-m", "launch_py.hosts", "controllers", "--bind", "0.0.0.0",
                           "--discovery-server", "127.0.0.1:7150", "--robots", "robot_0"], capture_output=True,
                          text=True, cwd=REPO, timeout=60, env={**os.environ, "ROS_DOMAIN_ID": "150"})
    assert done.returncode == 2 and "never every interface (0.0.0.0)" in done.stderr
    done = subprocess.run([sys.executable, "-m", "launch_py.hosts", "world", "--help"], capture_output=True,
                          text=True, cwd=REPO, timeout=60)
    assert done.returncode == 0 and "--bind" in done.stdout and "--plain-twist" in done.stdout


# --------------------------------------------------------------------------- the world's bookkeeping


def test_realtime_stops_a_robot_whose_newest_command_is_older_than_the_timeout():
    watch = CommandWatch(["robot_0", "robot_1"], DT, ticks=100, timeout_ns=5 * DT)
    go = Command(0.2, 0.0)
    for k in range(3):
        assert watch.taken("robot_0", k * DT, k * DT) and watch.taken("robot_1", k * DT, k * DT)
        assert watch.fresh({"robot_0": go, "robot_1": go}, k * DT) == {"robot_0": go, "robot_1": go}
    for k in range(3, 12):  # robot_1 falls silent after its command of tick 2
        watch.taken("robot_0", k * DT, k * DT)
        out = watch.fresh({"robot_0": go, "robot_1": go}, k * DT)
        assert out["robot_0"] == go
        assert out["robot_1"] == (go if k * DT - 2 * DT <= 5 * DT else Command())
    assert not watch.taken("robot_1", DT, 12 * DT)  # an old command arriving now does not revive it
    assert watch.fresh({"robot_1": go}, 12 * DT)["robot_1"] == Command()
    assert watch.taken("robot_1", 12 * DT, 12 * DT)  # a fresh one does
    assert watch.fresh({"robot_1": go}, 12 * DT)["robot_1"] == go
    counts = watch.counts({"robot_1": 4})
    assert counts["robot_1"]["stops"] == [[2 * DT, 8 * DT, 12 * DT]] and counts["robot_1"]["stopped_ticks"] == 5
    assert counts["robot_1"]["late"] == 1 and counts["robot_1"]["stale"] == 4
    assert counts["robot_0"]["stopped"] == 0


@given(st.lists(st.tuples(st.integers(0, 49), st.integers(0, 60)), max_size=200), st.integers(1, 60))
def test_counts_add_up_whatever_arrives_when(arrivals, ticks):
    """Arrivals (stamp tick, arrival tick) in any order: a tick is lost iff no command stamped with
    it came; late iff it came after its tick; the newest stamp is what the robot holds."""
    watch = CommandWatch(["robot_0"], DT, ticks=60, timeout_ns=0)
    for stamp, at in arrivals:
        watch.taken("robot_0", stamp * DT, max(stamp, at) * DT)
    for k in range(ticks):
        assert watch.fresh({"robot_0": Command(0.1, 0.0)}, k * DT) == {"robot_0": Command(0.1, 0.0)}
    counts = watch.counts({})["robot_0"]
    heard = {s for s, _ in arrivals if s < ticks}
    assert counts["lost"] == ticks - len(heard)
    assert counts["late"] == sum(at > s for s, at in arrivals)
    assert counts["stops"] == [] and counts["stopped_ticks"] == 0

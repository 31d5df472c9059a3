"""A swarm-run across the hosts of a `netns.Testbed`: the world (and its servers) on host ``world``,
the controllers on ``hosta`` and ``hostb``, started from the very commands swarm-run prints for
them (docs/across_hosts.md), and a stand-in ``ros2 topic echo`` (`echo.py`) on ``cli``."""

from __future__ import annotations

import json
import os
import shlex
import subprocess
import sys
import threading
import time
from pathlib import Path

import numpy as np
from graph_helpers import recorded_sim_time
from netns import Testbed

from launch_py.dds import discovery_port

from swarm_sim.analysis.metrics import summarize
from swarm_sim.analysis.replay import load_odometry
from swarm_sim.batch import run_batch
from swarm_sim.scenario import load_scenario

REPO = Path(__file__).resolve().parents[2]
HOSTS = ("world", "hosta", "hostb", "cli")
CONTROLLER_HOSTS = ("hosta", "hostb")
SMALL_ARENA = ["arena.size=5.0", "resources.distribution=uniform", "resources.count=150",
               "resources.min_depot_clearance=0.3"]
"""test_determinism's busy arena (CPFA): a short run delivers resources."""
PAPERS = {
    "mdbsa_d": ("mdbsa_d", []),
    "queue_qmt": ("queue_qmt", ["arena.size=7.0", "resources.distribution=uniform", "resources.count=200"]),
    "drtm": ("drtm", []),
    "caging": ("caging", ["arena.size=5.0", "transport.landmarks.extent=[2.0, 2.0]"]),
}
"""The papers whose robots talk to a server or each other across the links: MDBSA-D's center,
Q_MT's depot manager (a busy arena), DRTM's nest, caging's robots (peer messages through the
world; a small arena and landmark grid: the object found and the protocol going within seconds)."""
COMPARED = ("resources_delivered", "collision_time_s_by_robot", "contact_time_s_by_robot", "oae_by_robot",
            "trips_by_robot", "clamped_commands", "stale_ticks")


def flags(duration: float, seed: int, scenario: str = "cpfa", overrides: list[str] = SMALL_ARENA) -> list[str]:
    """swarm-run's flags (default: the small arena)."""
    return ["--scenario", scenario, "--duration", str(duration), "--seed", str(seed),
            *(a for item in overrides for a in ("--set", item))]


def batch_differences(bag: Path, graph: dict, robots: int, duration: float, seed: int, scenario: str = "cpfa",
                      overrides: list[str] = SMALL_ARENA) -> list[str]:
    """Where the graph run (its bag and summary) differs from the batch run of its seed."""
    scenario = load_scenario(scenario, overrides, robots__count=robots, sim__duration=duration, seed=seed)
    batch = run_batch(scenario, record_poses=True)
    expected = summarize(batch.trace)
    odom = load_odometry(bag)
    out = [] if len(odom) == robots else [f"odometry of {len(odom)} robots"]
    for i, (robot, rows) in enumerate(odom.items()):
        if not np.array_equal(rows[:, 1:], batch.poses[:, i, :]):  # False for other shapes too
            out.append(f"{robot}'s odometry")
    return out + [key for key in COMPARED if graph[key] != expected[key]]


def protocol_messages(bag: Path, scenario: str) -> int:
    """Messages the bag holds on the topics of the scenario's message families (a server's,
    or the robots' to each other through the world)."""
    from swarm_sim import registry
    from swarm_sim.recording import bag_info

    inbound, outbound = registry.robot_topics(registry.of(load_scenario(scenario)))
    counts = bag_info(bag).message_counts
    return sum(counts.get(t, 0) for t in (*inbound, *outbound))


def robots_of(count: int) -> dict[str, list[str]]:
    """Robots dealt to the controller hosts: even ones on hosta, odd ones on hostb."""
    return {h: [f"robot_{i}" for i in range(k, count, 2)] for k, h in enumerate(CONTROLLER_HOSTS)}


def node_env() -> dict[str, str]:
    """This environment with this tree first on PYTHONPATH, for the processes on the hosts."""
    return {**os.environ, "PYTHONPATH": os.pathsep.join([str(REPO), *filter(None, [os.environ.get("PYTHONPATH")])])}


class _Lines:
    """A process's output lines, read by a thread (so its pipe never fills up)."""

    def __init__(self, stream) -> None:
        self.lines: list[str] = []
        self._thread = threading.Thread(target=lambda: self.lines.extend(iter(stream.readline, "")), daemon=True)
        self._thread.start()

    def wait_for(self, prefix: str, timeout: float) -> str:
        deadline = time.monotonic() + timeout
        while time.monotonic() < deadline:
            for line in list(self.lines):
                if line.startswith(prefix):
                    return line
            time.sleep(0.05)
        raise AssertionError(f"no line {prefix!r} within {timeout} s: {''.join(self.lines)[-2000:]}")

    def join(self, timeout: float) -> str:
        self._thread.join(timeout)
        return "".join(self.lines)


def start_echo(testbed: Testbed, server: str, topic: str, count: int, timeout: float, tmp: Path) -> subprocess.Popen:
    """The stand-in ``ros2 topic echo`` (`echo.py`) on host ``cli``, in the environment docs/across_hosts.md's
    recipe gives a stock ``ros2`` there (``python -m launch_py.hosts env``)."""
    lines = testbed.run("cli", [sys.executable, "-m", "launch_py.hosts", "env", "--bind", "eth0",
                                "--discovery-server", server, "--profile", str(tmp / "cli.xml")])
    env = {k: v for k, v in node_env().items() if not k.startswith(("ROS_", "FAST", "RMW_"))}
    for line in lines.splitlines():
        if line.startswith("export "):
            key, _, value = line[7:].partition("=")
            env[key] = value
    return testbed.popen("cli", [sys.executable, str(Path(__file__).with_name("echo.py")), topic, str(count),
                                 str(timeout)], env=env, cwd=REPO, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                         text=True)


class MultiHostRun:
    """swarm-run on ``world`` bound to its address, every controller remote (see the module doc)."""

    def __init__(self, testbed: Testbed, tmp: Path, robots: int, *args: str, domain: int | None = None) -> None:
        """`domain`: the run's ROS domain (default: the session's, ``ROS_DOMAIN_ID``)."""
        self.tb = testbed
        domain = int(os.environ["ROS_DOMAIN_ID"]) if domain is None else domain
        self.bag = tmp / "bag"
        self.robots = robots_of(robots)
        key = tmp / "run.key"
        world = testbed.address["world"]
        remote = [a for h, rs in self.robots.items() for a in ("--remote-controllers", f"{h}={','.join(rs)}")]
        cmd = [sys.executable, "-m", "launch_py.run", "--bag", str(self.bag), "--json", "--domain-id",
               str(domain), "--bind", world, "--key-file", str(key), *remote, "--robots", str(robots),
               *args]
        self.launcher = testbed.popen("world", cmd, env=node_env(), cwd=REPO, stdout=subprocess.PIPE,
                                      stderr=subprocess.PIPE, text=True)
        self.out, self.err = _Lines(self.launcher.stdout), _Lines(self.launcher.stderr)
        self.controllers = {}
        self.controller_err: dict[str, _Lines] = {}
        for host in self.robots:
            line = self.out.wait_for(f"[swarm-run] on {host}: ", 60)
            words = shlex.split(line.split(": ", 1)[1])
            assert words[:3] == [f"ROS_DOMAIN_ID={domain}", "SWARMFORAGE_KEY_FD=3",
                                 "swarm-controllers"] and words[-1] == f"3<{key}", words
            node_args = [testbed.address[host] if w == "ITS_ADDRESS" else w for w in words[3:-1]]
            fd = os.open(key, os.O_RDONLY)
            try:  # the key as the printed recipe hands it over: an inherited descriptor
                self.controllers[host] = testbed.popen(
                    host, [sys.executable, "-m", "launch_py.hosts", "controllers", *node_args],
                    env={**node_env(), "ROS_DOMAIN_ID": str(domain), "SWARMFORAGE_KEY_FD": str(fd)}, pass_fds=(fd,),
                    cwd=REPO,
                    stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
            finally:
                os.close(fd)
            self.controller_err[host] = _Lines(self.controllers[host].stderr)
        self.left: dict[str, tuple[int, float]] = {}
        """Controller host -> (exit code, when it exited [monotonic]), noted as they leave."""
        threading.Thread(target=self._watch_controllers, daemon=True).start()
        self.server = f"{world}:{discovery_port(domain)}"
        self.sockets: dict[str, set[tuple[str, str, str]]] = {h: set() for h in HOSTS}

    def echo(self, topic: str, count: int, timeout: float) -> subprocess.Popen:
        """`start_echo` on ``cli``."""
        return start_echo(self.tb, self.server, topic, count, timeout, self.bag.parent)

    def sim_time(self) -> float:
        return recorded_sim_time(self.bag)

    def wait_sim(self, seconds: float, timeout: float) -> None:
        """Until the run has recorded `seconds` of sim time, noting every host's sockets meanwhile."""
        deadline = time.monotonic() + timeout
        while self.sim_time() < seconds:
            assert self.launcher.poll() is None, f"swarm-run ended early:\n{self.diagnosis()}"
            assert time.monotonic() < deadline, f"sim time {self.sim_time()} s after {timeout} s wall:\n{self.diagnosis()}"
            self.note_sockets()
            time.sleep(0.2)

    def diagnosis(self) -> str:
        """What the run's processes have said so far (the launcher's stderr whole, so an error
        before a traceback is not cut off), for a failure's message."""
        parts = [f"--- swarm-run (world host) stdout (the nodes' Fast DDS log goes there):\n"
                 f"{''.join(self.out.lines)[-4000:]}",
                 f"--- swarm-run (world host) stderr:\n{''.join(self.err.lines)[-12000:]}"]
        parts += [f"--- {host}'s swarm-controllers stderr:\n{''.join(lines.lines)[-3000:]}"
                  for host, lines in self.controller_err.items()]
        return "\n".join(parts)

    def note_sockets(self) -> None:
        for host in HOSTS:
            self.sockets[host] |= set(self.tb.sockets(host))

    def finish(self, timeout: float) -> dict:
        """The run's JSON summary (it must exit 0)."""
        code = self.launcher.wait(timeout)
        out, _ = self.out.join(5), self.err.join(5)  # both readers done: the diagnosis holds every line
        assert code == 0, f"swarm-run exited {code}:\n{out[-3000:]}\n{self.diagnosis()}"
        return json.loads(out.strip().splitlines()[-1])

    def _watch_controllers(self) -> None:
        while len(self.left) < len(self.controllers):
            for host, proc in self.controllers.items():
                if host not in self.left and proc.poll() is not None:
                    self.left[host] = (proc.returncode, time.monotonic())
            time.sleep(0.05)

    def wait_controllers(self, since: float, within: float) -> dict[str, tuple[int, float, str]]:
        """Each controller host's process once it has left by itself: host -> (exit code, wall
        seconds from `since` (monotonic) to its exit, the line it said last); fails if one is
        still there `within` seconds after `since`."""
        while len(self.left) < len(self.controllers):
            left = [h for h in self.controllers if h not in self.left]
            assert time.monotonic() - since < within, f"still running {within} s after the end: {left}"
            time.sleep(0.05)
        out = {}
        for host, (code, at) in self.left.items():
            err = self.controller_err[host].join(5).strip().splitlines()
            out[host] = (code, at - since, err[-1] if err else "")
        return out

    def world_pid(self) -> int:
        """The world node's process (the launcher's child running swarm_sim.nodes.world_node)."""
        for entry in Path("/proc").iterdir():
            if not entry.name.isdigit():
                continue
            try:
                stat = (entry / "stat").read_text()
                cmdline = (entry / "cmdline").read_bytes()
            except (OSError, ValueError):
                continue
            if int(stat.rsplit(")", 1)[1].split()[1]) == self.launcher.pid and b"swarm_sim.nodes.world_node" in cmdline:
                return int(entry.name)
        raise AssertionError("no world node process")

    def foreign_sockets(self) -> list[str]:
        """Sockets noted on a host bound to anything but that host's own address (0.0.0.0, *,
        127.0.0.1, another address)."""
        return [f"{host}: {proto} {local} {proc}" for host, found in self.sockets.items()
                for proto, local, proc in found if local.rpartition(":")[0] != self.tb.address[host]]

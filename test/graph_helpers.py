"""Helpers for tests that start the real graph (swarm-run) in subprocesses."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time
import warnings
from pathlib import Path

import pytest

from swarm_msgs_py.types import NS_PER_S
from swarm_sim.recording import BagTruncatedWarning, bag_info

REPO = Path(__file__).resolve().parents[1]

# A small, busy arena so a short run delivers resources: 8 robots, 5 x 5 m, 150 uniform resources.
SMALL_ARENA = [
    "arena.size=5.0",
    "resources.distribution=uniform",
    "resources.count=150",
    "resources.min_depot_clearance=0.3",
]


def run_graph(bag: Path, *args: str, timeout: float = 300.0) -> dict:
    """Run swarm-run to completion and return its JSON summary."""
    cmd = [sys.executable, "-m", "launch_py.run", "--bag", str(bag), "--json", "--tick-timeout", "20",
           "--domain-id", os.environ["ROS_DOMAIN_ID"], *args]
    result = subprocess.run(cmd, capture_output=True, text=True, timeout=timeout,
                            cwd=Path(__file__).resolve().parents[1])
    assert result.returncode == 0, f"swarm-run failed:\n{result.stdout[-3000:]}\n{result.stderr[-3000:]}"
    assert "Traceback" not in result.stderr, result.stderr[-3000:]  # no node leaves a run with one
    return json.loads(result.stdout.strip().splitlines()[-1])


def overrides(items: list[str]) -> list[str]:
    return [a for item in items for a in ("--set", item)]


class Launch:
    """swarm-run in its own session; `stop` kills whatever is left of its process group. As in
    `run_graph`, the world waits up to 20 s for a tick's answers (a test's own ``--tick-timeout``,
    later on the line, wins): a slow tick on a busy machine is not a stale one."""

    def __init__(self, bag: Path, *args: str) -> None:
        self.bag = bag
        cmd = [sys.executable, "-m", "launch_py.run", "--bag", str(bag), "--json", "--tick-timeout", "20",
               "--domain-id", os.environ["ROS_DOMAIN_ID"], *args]
        self.proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                                     cwd=REPO, start_new_session=True)
        self.pids: dict[int, str] = {}

    def children(self) -> dict[int, str]:
        """The launcher's descendants: pid -> "<name> <command line>" (remembered for `alive`)."""
        parents: dict[int, int] = {}
        for p in Path("/proc").iterdir():
            if p.name.isdigit():
                try:
                    parents[int(p.name)] = int((p / "stat").read_text().rsplit(")", 1)[1].split()[1])
                except (OSError, ValueError, IndexError):
                    continue
        mine, grew = {self.proc.pid}, True
        while grew:
            new = {pid for pid, ppid in parents.items() if ppid in mine} - mine
            mine |= new
            grew = bool(new)
        for pid in mine - {self.proc.pid}:
            try:
                name = Path(f"/proc/{pid}/comm").read_text().strip()
                cmdline = Path(f"/proc/{pid}/cmdline").read_bytes().replace(b"\0", b" ").decode()
            except OSError:
                continue
            self.pids[pid] = f"{name} {cmdline}"
        return dict(self.pids)

    def child(self, module: str, robot: str | None = None) -> int:
        """The process running `module`, or with --fork the one named after `robot`."""
        found = [pid for pid, text in self.children().items()
                 if f"-m {module} " in text and (robot is None or text.startswith(robot + " "))]
        assert len(found) == 1, (module, robot, self.pids)
        return found[0]

    def alive(self) -> list[int]:
        """Processes this launcher started that still exist (zombies count as gone)."""
        out = []
        for pid in self.pids:
            try:
                state = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0]
            except OSError:
                continue
            if state != "Z":
                out.append(pid)
        return out

    def sim_time(self) -> float:
        return recorded_sim_time(self.bag)

    def wait_until(self, predicate, timeout: float = 90.0, what: str = "") -> None:
        deadline = time.monotonic() + timeout
        while not predicate():
            assert self.proc.poll() is None, f"swarm-run ended early ({what}): {self.proc.stderr.read()[-3000:]}"
            assert time.monotonic() < deadline, f"timed out waiting for {what}"
            time.sleep(0.05)

    def finish(self, timeout: float = 240.0) -> tuple[int, dict | None, str]:
        out, err = self.proc.communicate(timeout=timeout)
        lines = out.strip().splitlines()
        summary = json.loads(lines[-1]) if lines and lines[-1].startswith("{") else None
        return self.proc.returncode, summary, err

    def stop(self) -> None:
        if self.proc.poll() is None:
            os.killpg(self.proc.pid, signal.SIGKILL)
            self.proc.wait()
        for pid in self.alive():  # children live in their own sessions
            os.killpg(pid, signal.SIGKILL)


@pytest.fixture
def launch(tmp_path):
    """Start swarm-run (`Launch`); every run still going at the end is killed, with its nodes."""
    started: list[Launch] = []

    def start(*args: str, bag: str = "bag") -> Launch:
        started.append(Launch(tmp_path / bag, *args))
        return started[-1]

    yield start
    for run in started:
        run.stop()


def recorded_sim_time(bag: Path) -> float:
    """The last /clock a run's bag has recorded so far [s] (0 before the bag exists)."""
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", BagTruncatedWarning)
            return bag_info(bag).end_ns / NS_PER_S
    except Exception:  # noqa: BLE001 - not there yet, or mid-write
        return 0.0

"""Start-up of the graph: wall seconds from `swarm-run` until the world node is up (its topics
built) and until every controller is connected (the first tick goes out: every controller also
waits until its peer topics are matched), for several swarm sizes, splits over processes and both
discovery modes, with the CPU seconds the world and the controller processes spent until then.

    python benchmarks/bench_startup.py [--robots 16 112] [--discovery server simple] [--repeat 1]
    python benchmarks/bench_startup.py --robots 1000 --controller-processes 2 4 8 --repeat 3

Runs of 1000 robots get issue 14's 38 x 38 m arena (`--arena`, as profile_batch.py). Also prints
the launcher's exit code and whether any process printed a traceback on shutdown.
"""

from __future__ import annotations

import argparse
import re
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from profile_batch import scaled_fields
from profile_graph import process_cpu_s, tree

ROOT = Path(__file__).resolve().parents[1]


def cpu_seconds(root: int) -> dict[str, float]:
    """CPU seconds so far of the world and of all controller processes under `root`."""
    out = {"world": 0.0, "controllers": 0.0}
    for pid, role in tree(root).items():
        if role in out:
            out[role] += process_cpu_s(pid)
    return out


def one_run(scenario: str, robots: int, processes: int, discovery: str, sets: list[str],
            ) -> tuple[float, float, float, int, bool, dict[str, float]]:
    """(s to the world being up, s to every controller connected, s to the end, exit code, traceback
    seen, CPU seconds of the world and the controllers until connected)."""
    with tempfile.TemporaryDirectory() as tmp:
        cmd = [sys.executable, "-m", "launch_py.run", "--scenario", scenario, "--robots", str(robots),
               "--duration", "5", "--controller-processes", str(processes), "--bag", str(Path(tmp) / "bag"),
               "--discovery", discovery, *sets]
        t0 = time.perf_counter()
        proc = subprocess.Popen(cmd, cwd=ROOT, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
        up = connected = float("nan")
        cpu: dict[str, float] = {}
        traceback = False
        assert proc.stdout is not None
        for line in proc.stdout:
            traceback |= "Traceback" in line
            if line.startswith("[world] up") and up != up:
                up = time.perf_counter() - t0
            found = re.search(r"(\d+)/(\d+) controllers connected after [\d.]+ s: starting", line)
            if found and found.group(1) == found.group(2):
                connected = time.perf_counter() - t0
                cpu = cpu_seconds(proc.pid)
        proc.wait()
        return up, connected, time.perf_counter() - t0, proc.returncode, traceback, cpu


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--robots", type=int, nargs="+", default=[16, 112])
    parser.add_argument("--scenario", default="cpfa")
    parser.add_argument("--controller-processes", type=int, nargs="+", default=[0],
                        help="splits (alternated), 0 = one per robot (default)")
    parser.add_argument("--arena", type=lambda t: (int(t.split("=")[0]), float(t.split("=")[1])), nargs="*",
                        default=[(1000, 38.0)], metavar="ROBOTS=SIDE",
                        help="arena side for runs of ROBOTS robots, resources scaled (as profile_batch.py)")
    parser.add_argument("--repeat", type=int, default=1)
    parser.add_argument("--run-arg", action="append", default=[], metavar="ARG",
                        help="a swarm-run option, e.g. --run-arg=--no-parameter-services (repeatable)")
    parser.add_argument("--discovery", nargs="+", default=["server"], choices=("server", "simple"),
                        help="one or both (alternated) of swarm-run's discovery modes")
    args = parser.parse_args()
    for n in args.robots:
        sets = list(args.run_arg)
        for key, value in scaled_fields(args.scenario, n, dict(args.arena).get(n)).items():
            if key != "robots__count":
                sets += ["--set", f"{key.replace('__', '.')}={value}"]
        for _ in range(args.repeat):
            for k in args.controller_processes:
                for discovery in args.discovery:
                    up, connected, total, code, traceback, cpu = one_run(args.scenario, n, k, discovery, sets)
                    print(f"startup robots={n:4d} processes={k} discovery={discovery:6s} "
                          f"world up {up:5.1f} s, all connected (first tick) {connected:6.1f} s (CPU until then: "
                          f"world {cpu.get('world', float('nan')):.1f} s, controllers "
                          f"{cpu.get('controllers', float('nan')):.1f} s), 5 s run ends "
                          f"{total:6.1f} s after launch, exit {code}, traceback: {traceback}", flush=True)


if __name__ == "__main__":
    main()

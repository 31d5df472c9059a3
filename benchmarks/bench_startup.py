"""Start-up of the graph with one process per robot: wall seconds from `swarm-run` until the
world node is up (its topics built) and until every controller is connected (the first tick goes
out: every controller also waits until its peer topics are matched), for several swarm sizes and
both discovery modes.

    python benchmarks/bench_startup.py [--robots 16 112] [--discovery server simple] [--repeat 1]

Also prints the launcher's exit code and whether any process printed a traceback on shutdown.
"""

from __future__ import annotations

import argparse
import re
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def one_run(scenario: str, robots: int, processes: int, discovery: str) -> tuple[float, float, float, int, bool]:
    """(s to the world being up, s to every controller connected, s to the end, exit code, traceback seen)."""
    with tempfile.TemporaryDirectory() as tmp:
        cmd = [sys.executable, "-m", "launch_py.run", "--scenario", scenario, "--robots", str(robots),
               "--duration", "5", "--controller-processes", str(processes), "--bag", str(Path(tmp) / "bag"),
               "--discovery", discovery]
        t0 = time.perf_counter()
        proc = subprocess.Popen(cmd, cwd=ROOT, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
        up = connected = float("nan")
        traceback = False
        assert proc.stdout is not None
        for line in proc.stdout:
            traceback |= "Traceback" in line
            if line.startswith("[world] up") and up != up:
                up = time.perf_counter() - t0
            found = re.search(r"(\d+)/(\d+) controllers connected after [\d.]+ s: starting", line)
            if found and found.group(1) == found.group(2):
                connected = time.perf_counter() - t0
        proc.wait()
        return up, connected, time.perf_counter() - t0, proc.returncode, traceback


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--robots", type=int, nargs="+", default=[16, 112])
    parser.add_argument("--scenario", default="cpfa")
    parser.add_argument("--controller-processes", type=int, default=0, help="0 = one per robot (default)")
    parser.add_argument("--repeat", type=int, default=1)
    parser.add_argument("--discovery", nargs="+", default=["server"], choices=("server", "simple"),
                        help="one or both (alternated) of swarm-run's discovery modes")
    args = parser.parse_args()
    for n in args.robots:
        for _ in range(args.repeat):
            for discovery in args.discovery:
                up, connected, total, code, traceback = one_run(args.scenario, n, args.controller_processes, discovery)
                print(f"startup robots={n:4d} processes={args.controller_processes} discovery={discovery:6s} "
                      f"world up {up:5.1f} s, all connected (first tick) {connected:6.1f} s, 5 s run ends "
                      f"{total:6.1f} s after launch, exit {code}, traceback: {traceback}", flush=True)


if __name__ == "__main__":
    main()

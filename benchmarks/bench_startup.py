"""Start-up of the graph with one process per robot: wall seconds from `swarm-run` to the
world's first tick (every controller and server matched), for several swarm sizes.

    python benchmarks/bench_startup.py [--robots 16 112] [--scenario cpfa] [--repeat 1]

Also prints the launcher's exit code and whether any process printed a traceback on shutdown.
"""

from __future__ import annotations

import argparse
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def one_run(scenario: str, robots: int, processes: int, discovery: str) -> tuple[float, float, int, bool]:
    """(seconds to the first tick, seconds to the end, exit code, traceback seen)."""
    with tempfile.TemporaryDirectory() as tmp:
        cmd = [sys.executable, "-m", "launch_py.run", "--scenario", scenario, "--robots", str(robots),
               "--duration", "5", "--controller-processes", str(processes), "--bag", str(Path(tmp) / "bag"),
               "--discovery", discovery]
        t0 = time.perf_counter()
        proc = subprocess.Popen(cmd, cwd=ROOT, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
        first = float("nan")
        lines = []
        assert proc.stdout is not None
        for line in proc.stdout:
            lines.append(line)
            if line.startswith("[world] first tick") and first != first:
                first = time.perf_counter() - t0
        proc.wait()
        total = time.perf_counter() - t0
    return first, total, proc.returncode, any("Traceback" in line for line in lines)


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
                first, total, code, traceback = one_run(args.scenario, n, args.controller_processes, discovery)
                print(f"startup robots={n:4d} processes={args.controller_processes} discovery={discovery:6s} "
                      f"first tick after {first:6.1f} s, whole 5 s run {total:6.1f} s, exit {code}, "
                      f"traceback on shutdown: {traceback}", flush=True)


if __name__ == "__main__":
    main()

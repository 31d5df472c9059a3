"""Start-up of one process per robot: how long until the world has every controller connected.

Runs ``swarm-run --controller-processes 0`` for a 1 s run and notes when the world node's lines
arrive: "up" (the world node built its topics) and "N/N controllers connected ...: starting"
(every controller matched: the first tick goes out); prints those wall times from launch, and
launch to exit.

    python benchmarks/bench_startup.py [--robots 112] [--repeat 1] [--scenario cpfa]
"""

from __future__ import annotations

import argparse
import os
import re
import subprocess
import sys
import tempfile
import time
from pathlib import Path


def measure(robots: int, scenario: str, domain: str) -> tuple[float | None, float | None, float, int]:
    """(wall s from launch to the world being up, to every controller connected, to exit; exit status)."""
    with tempfile.TemporaryDirectory() as tmp:
        cmd = [sys.executable, "-m", "launch_py.run", "--scenario", scenario, "--robots", str(robots),
               "--duration", "1", "--controller-processes", "0", "--bag", str(Path(tmp) / "bag"),
               "--tick-timeout", "20", "--domain-id", domain]
        t0 = time.monotonic()
        up = connected = None
        with subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True,
                              cwd=Path(__file__).resolve().parents[1]) as run:
            for line in run.stdout:
                if up is None and line.startswith("[world] up"):
                    up = time.monotonic() - t0
                found = re.search(r"(\d+)/(\d+) controllers connected after [\d.]+ s: starting", line)
                if found and found.group(1) == found.group(2):
                    connected = time.monotonic() - t0
        return up, connected, time.monotonic() - t0, run.returncode


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--robots", type=int, default=112)
    parser.add_argument("--repeat", type=int, default=1)
    parser.add_argument("--scenario", default="cpfa")
    args = parser.parse_args()
    domain = os.environ.get("ROS_DOMAIN_ID", "150")
    for _ in range(args.repeat):
        up, connected, wall, code = measure(args.robots, args.scenario, domain)
        show = lambda t: f"{t:.1f} s" if t is not None else "never"  # noqa: E731
        print(f"{args.robots} one-robot processes: world up {show(up)}, all controllers connected "
              f"{show(connected)}, exit {wall:.1f} s after launch (status {code})", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())

"""Graph speed and memory: swarm-run in lockstep with recording on, for several swarm sizes.

Prints the real-time factor and the peak total RSS of every process of the run (launcher,
world, controllers), sampled from /proc every 0.5 s.

    python benchmarks/bench_graph.py [--robots 16 112] [--duration 60] [--controller-processes 1]
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path


def tree_rss_mb(root: int) -> float:
    """Sum of VmRSS over `root` and all its descendants [MB]."""
    children: dict[int, list[int]] = {}
    for entry in os.listdir("/proc"):
        if entry.isdigit():
            try:
                with open(f"/proc/{entry}/stat") as f:
                    ppid = int(f.read().rsplit(")", 1)[1].split()[1])
            except (OSError, IndexError, ValueError):
                continue
            children.setdefault(ppid, []).append(int(entry))
    total, stack = 0.0, [root]
    while stack:
        pid = stack.pop()
        stack.extend(children.get(pid, []))
        try:
            with open(f"/proc/{pid}/status") as f:
                for line in f:
                    if line.startswith("VmRSS:"):
                        total += int(line.split()[1]) / 1024
        except OSError:
            pass
    return total


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--robots", type=int, nargs="+", default=[16, 112])
    parser.add_argument("--duration", type=float, default=60.0)
    parser.add_argument("--controller-processes", type=int, default=1)
    parser.add_argument("--scenario", default="cpfa")
    args = parser.parse_args()
    root = Path(__file__).resolve().parents[1]
    for n in args.robots:
        with tempfile.TemporaryDirectory() as tmp:
            bag = Path(tmp) / "bag"
            cmd = [sys.executable, "-m", "launch_py.run", "--scenario", args.scenario, "--robots", str(n),
                   "--duration", str(args.duration), "--bag", str(bag), "--json",
                   "--controller-processes", str(args.controller_processes)]
            t0 = time.perf_counter()
            proc = subprocess.Popen(cmd, cwd=root, stdout=subprocess.PIPE, text=True)
            peak = 0.0
            while proc.poll() is None:
                peak = max(peak, tree_rss_mb(proc.pid))
                time.sleep(0.5)
            wall = time.perf_counter() - t0
            out = proc.stdout.read().strip().splitlines()
            summary = json.loads(out[-1]) if out else {}
            bag_mb = sum(f.stat().st_size for f in bag.glob("*")) / 2**20 if bag.exists() else 0
        print(f"graph lockstep robots={n:4d} processes={args.controller_processes} sim={args.duration:.0f}s "
              f"loop rtf={summary.get('real_time_factor')}x (incl. start-up: {args.duration / wall:.2f}x) "
              f"peak RSS total={peak:.0f} MB  bag={bag_mb:.1f} MB  stale={summary.get('stale_ticks')} "
              f"delivered={summary.get('resources_delivered')}", flush=True)


if __name__ == "__main__":
    main()

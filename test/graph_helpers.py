"""Helpers for tests that start the real graph (swarm-run) in subprocesses."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

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
    return json.loads(result.stdout.strip().splitlines()[-1])


def overrides(items: list[str]) -> list[str]:
    return [a for item in items for a in ("--set", item)]

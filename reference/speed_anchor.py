"""The speed anchor: the queue authors' ARGoS code and our batch runner on the same cell, whole
processes alternated A B A B on this machine, CPU seconds (user + system) and wall seconds each.

The cell is their experiment (``queue_argos.EXPERIMENT``, branch ``main``: Q_SE) at ``--robots``
robots for ``--duration`` sim seconds, against ``swarm-batch --scenario queue_qse`` on the same
swarm and arena. For a swarm larger than their 12 x 12 m arena holds (``--arena`` metres a side),
the file is scaled as our `benchmarks/profile_batch.py` scales ours: the four walls moved out,
the four start grids (their ``<distribute>`` groups) made square enough for N / 4 robots each and
moved out with the arena (their centres at a quarter of the side from the nest, as 3 m is in
12 m), and the resources (``FoodItemCount``, ``NumberOfClusters``) in the same ratio to the arena's
area as ours; ``experiment length`` ends the run (their loop functions end it at 18 minutes).
"""
from __future__ import annotations

import argparse
import math
import re
import subprocess
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))  # run as a script or loaded by path
from argos_run import ReferenceError, children_cpu_s, run_argos  # noqa: E402
from queue_argos import EXPERIMENT, experiment_xml  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
AUTHORS_ARENA = 12.0
"""The side of their arena [m] (``<arena size="12.0, 12.0, 1">``)."""


def _sub(pattern: str, repl: str, text: str, count: int, what: str) -> str:
    text, n = re.subn(pattern, repl, text)
    if n != count:
        raise ReferenceError(f"{EXPERIMENT}: expected {count} {what}, found {n}")
    return text


def scaled_xml(text: str, robots: int, seed: int, arena: float, duration: float, resources: int,
               clusters: int) -> str:
    """Their experiment file for `robots` robots in an `arena` x `arena` m square (see the module
    docstring), ending after `duration` sim seconds."""
    text = experiment_xml(text, robots, seed)
    text = _sub(r'<experiment length="\d+"', f'<experiment length="{duration:g}"', text, 1, "experiment length")
    half, side = arena / 2, math.ceil(math.sqrt(robots / 4))
    text = _sub(r'<arena center="0,0,0.5" size="[^"]+">', f'<arena center="0,0,0.5" size="{arena:g}, {arena:g}, 1">',
                text, 1, "arena")
    for axis, sign in (("north1", 1), ("south", -1)):
        text = _sub(rf'(<box id="wall_{axis}" movable="false" size=")[^,]+(,0.02,0.5">\s*<body orientation="0,0,0" '
                    r'position=")[^"]+(")', rf'\g<1>{arena:g}\g<2>0,{sign * half:g},0\g<3>', text, 1, f"wall_{axis}")
    for axis, sign in (("east", 1), ("west", -1)):
        text = _sub(rf'(<box id="wall_{axis}" movable="false" size="0.02, )[^,]+(,0.5">\s*<body orientation="0,0,0" '
                    r'position=")[^"]+(")', rf'\g<1>{arena:g}\g<2>{sign * half:g},0,0\g<3>', text, 1, f"wall_{axis}")
    quarter = arena / 4
    centres = iter(((quarter, 0.0), (0.0, quarter), (-quarter, 0.0), (0.0, -quarter)))
    text = _sub(r'<position center="[^"]+" distances="0.3, 0.3, 0.0" layout="6, 6, 1" method="grid"/>',
                lambda _m: (lambda c: f'<position center="{c[0]:g}, {c[1]:g}, 0.0" distances="0.3, 0.3, 0.0" '
                            f'layout="{side}, {side}, 1" method="grid"/>')(next(centres)), text, 4, "start grids")
    text = _sub(r'FoodItemCount="\d+"', f'FoodItemCount="{resources}"', text, 1, "FoodItemCount")
    return _sub(r'NumberOfClusters="\d+"', f'NumberOfClusters="{clusters}"', text, 1, "NumberOfClusters")


def _ours(robots: int, arena: float, duration: float, resources: int, clusters: int, seed: int) -> tuple[float, float]:
    """Our batch runner on the cell, as a whole process: (wall s, CPU s)."""
    cmd = [sys.executable, "-m", "swarm_sim.batch", "--scenario", "queue_qse", "--robots", str(robots),
           "--duration", f"{duration:g}", "--seed", str(seed), "--set", f"arena.size={arena:g}",
           "--set", f"resources.count={resources}", "--set", f"resources.clusters={clusters}"]
    start, cpu = time.perf_counter(), children_cpu_s()
    done = subprocess.run(cmd, cwd=ROOT, capture_output=True, text=True)
    wall, cpu = time.perf_counter() - start, children_cpu_s() - cpu
    if done.returncode != 0:
        raise ReferenceError(f"swarm-batch exited {done.returncode}: {(done.stderr or done.stdout).strip()[-300:]}")
    return wall, cpu


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--argos", required=True, help="the argos3 executable built here")
    p.add_argument("--tree", required=True, type=Path, help="a built checkout of the authors' branch main")
    p.add_argument("--robots", type=int, default=1000)
    p.add_argument("--arena", type=float, default=38.0, help="arena side [m] (default 38: our 1000-robot arena)")
    p.add_argument("--resources", type=int, default=3200, help="resources (default 3200: ours at 38 m)")
    p.add_argument("--clusters", type=int, default=50, help="resource clusters (default 50: ours at 38 m)")
    p.add_argument("--duration", type=float, default=120.0, help="sim seconds")
    p.add_argument("--pairs", type=int, default=3)
    p.add_argument("--seed", type=int, default=123456)
    a = p.parse_args(argv)
    try:
        if not (a.tree / EXPERIMENT).is_file():
            raise ReferenceError(f"--tree {a.tree}: no {EXPERIMENT}")
        if a.arena < AUTHORS_ARENA or a.duration <= 0 or a.pairs < 1:
            raise ReferenceError(f"--arena at least {AUTHORS_ARENA:g} m, --duration and --pairs positive")
        xml = scaled_xml((a.tree / EXPERIMENT).read_text(), a.robots, a.seed, a.arena, a.duration, a.resources,
                         a.clusters)
        for i in range(a.pairs):
            _, wall, cpu = run_argos([a.argos], a.tree, xml, f".swarmforage_anchor_r{a.robots}.xml",
                                     f"{a.robots} robots", 3600.0)
            print(f"pair {i + 1}: ARGoS   {a.robots} robots {a.duration:g} s: {wall:7.1f} s wall, {cpu:7.1f} s CPU",
                  flush=True)
            wall, cpu = _ours(a.robots, a.arena, a.duration, a.resources, a.clusters, a.seed)
            print(f"pair {i + 1}: ours    {a.robots} robots {a.duration:g} s: {wall:7.1f} s wall, {cpu:7.1f} s CPU",
                  flush=True)
    except (ReferenceError, OSError) as e:
        print(f"speed_anchor: {e}", file=sys.stderr)
        return 2
    return 0


if __name__ == "__main__":
    sys.exit(main())

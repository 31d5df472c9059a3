"""Is this tree slower than a commit before it? Batch and graph runs of two trees, alternated.

    python benchmarks/ab_commits.py --b ddd9316                      # this tree (A) against ddd9316 (B)
    python benchmarks/ab_commits.py --b HEAD~3 --batch queue_qmt:112:120 --graph none --pairs 7
    python benchmarks/ab_commits.py --b ddd9316 --batch cpfa:1000:10:38

Each revision other than the working tree is checked out into a temporary git worktree (removed
at the end). A measurement is one child process per run, with ``PYTHONPATH`` set to its tree, run
A, B, A, B, ... (``--pairs`` pairs, after a warm-up run of each: numba compiles into a fresh
tree's cache): a machine whose speed drifts slows both alike. A batch run
(``SCENARIO:ROBOTS:SIM_SECONDS[:ARENA_SIDE]``; an arena side scales the scenario's resources with
the area, as ``profile_batch.py --arena`` does) reports the CPU time per tick of `run_batch`
(``time.process_time``, so other processes on a shared machine stretch it less than the wall
time); a graph run (``SCENARIO:ROBOTS:SIM_SECONDS``, lockstep, recording on, controllers in one
process) reports the real-time factor of its simulation loop and the CPU seconds of all its
processes per sim second (``RUSAGE_CHILDREN``). The table gives each tree's median and the median
of the A/B ratios pair by pair; a run whose result (deliveries) differs between the trees is
flagged, since then the two trees did not do the same work.
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import statistics
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]

_BATCH_CHILD = r"""
import json, sys, time
from swarm_sim.batch import run_batch
from swarm_sim.scenario import load_scenario
from swarm_sim.world.core import tune_malloc
tune_malloc()  # as swarm-batch's runs do (idempotent: a tree whose World tunes itself does it once)
name, robots, duration, arena = sys.argv[1], int(sys.argv[2]), float(sys.argv[3]), sys.argv[4]
fields = {"robots__count": robots, "sim__duration": duration}
if arena:
    base = load_scenario(name)
    factor = (float(arena) / base.arena.size) ** 2
    fields["arena__size"] = float(arena)
    res = base.resources
    if res.distribution == "clustered":
        fields["resources__clusters"] = max(1, round(res.clusters * factor))
        fields["resources__count"] = fields["resources__clusters"] * res.cluster_side ** 2
    else:
        fields["resources__count"] = max(1, round(res.count * factor))
scenario = load_scenario(name, **fields)
c0 = time.process_time()
run = run_batch(scenario)
cpu = time.process_time() - c0
print(json.dumps({"ms_per_tick": 1e3 * cpu / scenario.ticks, "delivered": len(run.trace.drops)}))
"""


def checkout(rev: str, into: Path) -> Path:
    """`rev` as a tree: the working tree for ``.``, else a detached worktree under `into`."""
    if rev == ".":
        return ROOT
    path = into / rev.replace("/", "_").replace("~", "-")
    subprocess.run(["git", "-C", str(ROOT), "worktree", "add", "--detach", "-q", str(path), rev], check=True)
    return path


def batch_run(tree: Path, spec: str) -> dict:
    name, robots, duration, *arena = spec.split(":")
    out = subprocess.run([sys.executable, "-c", _BATCH_CHILD, name, robots, duration, arena[0] if arena else ""],
                         cwd=tree, env={**os.environ, "PYTHONPATH": str(tree)}, capture_output=True, text=True)
    if out.returncode != 0:
        raise SystemExit(f"batch run in {tree} exited {out.returncode}: {out.stderr.strip().splitlines()[-1:]}")
    return json.loads(out.stdout.strip().splitlines()[-1])


def graph_run(tree: Path, spec: str) -> dict:
    name, robots, duration = spec.split(":")
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    with tempfile.TemporaryDirectory() as tmp:
        out = subprocess.run([sys.executable, "-m", "launch_py.run", "--scenario", name, "--robots", robots,
                              "--duration", duration, "--bag", str(Path(tmp) / "bag"), "--json"],
                             cwd=tree, env={**os.environ, "PYTHONPATH": str(tree)}, capture_output=True, text=True)
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    if out.returncode != 0:
        raise SystemExit(f"graph run in {tree} exited {out.returncode}: {out.stderr.strip().splitlines()[-1:]}")
    summary = json.loads(out.stdout.strip().splitlines()[-1])
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    return {"rtf": summary["real_time_factor"], "cpu_s_per_sim_s": cpu / float(duration),
            "delivered": summary["resources_delivered"]}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--a", default=".", help="revision A (default: the working tree)")
    parser.add_argument("--b", required=True, help="revision B, e.g. the commit before a change")
    parser.add_argument("--batch", nargs="*", default=["cpfa:112:120", "queue_qmt:112:120", "cpfa:1000:10:38"],
                        metavar="SCENARIO:ROBOTS:SECONDS[:ARENA]")
    parser.add_argument("--graph", nargs="*", default=["cpfa:112:40"], metavar="SCENARIO:ROBOTS:SECONDS",
                        help="graph runs ('none' for none)")
    parser.add_argument("--pairs", type=int, default=5)
    args = parser.parse_args()
    graphs = [g for g in args.graph if g != "none"]
    with tempfile.TemporaryDirectory(prefix="ab_commits_") as tmp:
        trees = {"A": checkout(args.a, Path(tmp)), "B": checkout(args.b, Path(tmp))}
        try:
            print(f"A = {args.a} ({trees['A']}), B = {args.b}; {args.pairs} alternated pairs each", flush=True)
            for kind, specs, run, figure in (("batch", args.batch, batch_run, "ms_per_tick"),
                                             ("graph", graphs, graph_run, "cpu_s_per_sim_s")):
                for spec in specs:
                    results: dict[str, list[dict]] = {"A": [], "B": []}
                    for side in ("A", "B"):  # a warm-up each: numba compiles into a fresh tree's cache
                        run(trees[side], spec)
                    for _ in range(args.pairs):
                        for side in ("A", "B"):
                            results[side].append(run(trees[side], spec))
                    a = [r[figure] for r in results["A"]]
                    b = [r[figure] for r in results["B"]]
                    ratio = statistics.median(x / y for x, y in zip(a, b))
                    same = {r["delivered"] for r in results["A"]} == {r["delivered"] for r in results["B"]}
                    extra = ""
                    if kind == "graph":
                        extra = (f"  rtf A {statistics.median(r['rtf'] for r in results['A']):.2f}x"
                                 f" B {statistics.median(r['rtf'] for r in results['B']):.2f}x")
                    print(f"{kind} {spec:20s} {figure}: A {statistics.median(a):.3f} B {statistics.median(b):.3f}"
                          f"  A/B {ratio:.3f} (min {min(a):.3f}/{min(b):.3f}){extra}"
                          f"{'' if same else '  RESULTS DIFFER'}", flush=True)
        finally:
            for side, tree in trees.items():
                if tree != ROOT:
                    subprocess.run(["git", "-C", str(ROOT), "worktree", "remove", "--force", str(tree)], check=False)


if __name__ == "__main__":
    main()

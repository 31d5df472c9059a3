"""Run the queue authors' own ARGoS code here and record it in our results schema.

The reference for the queue paper's levels: Tameem786/Collision_Free_CPFA (branch ``main``: the
single queue with entry-point joining, the paper's Q_SE; branch ``CPFA-2.0``: tail joining, Q_ST),
run on an ARGoS 3 built on this machine. Nothing of theirs is committed and nothing here builds
it (reference/README.md says why and what a checkout must hold): this script takes a checkout
that is already built, writes their experiment file with a swarm size and a seed set, runs
``argos3`` on it and turns the one line their ``CPFA_loop_functions::PostExperiment`` prints into
a row of ``results/reference/queue/results.jsonl``.

Their experiment (``experiments/Clustered_CPFA_r64_tag512_16by16.xml``) places the robots in
four ``<distribute>`` groups of equal ``quantity`` (28 each = 112); a swarm of N robots is four
groups of N / 4, as their logs' sizes 48-112 are. Seeds are their ``run.sh`` list.
"""
from __future__ import annotations

import argparse
import json
import re
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))  # run as a script or loaded by path
from argos_run import done_keys, ReferenceError, run_argos  # noqa: E402

AUTHORS_SEEDS = (123456, 789012, 345678, 901234, 567890, 135791, 246802, 864209, 751936, 428573,
                 613579, 982034, 704321, 319864, 580246, 162738, 947120, 830591, 204869, 678345)
"""The authors' 20 seeds, in their order (``run.sh`` of Tameem786/Collision_Free_CPFA)."""

EXPERIMENT = "experiments/Clustered_CPFA_r64_tag512_16by16.xml"
TOTAL_RESOURCES = 320
"""``FoodItemCount`` of their experiment file."""

LINE = re.compile(
    r"Resource Collected: (?P<score>[-\d.]+), Collision Time: (?P<collision>[-\d.naif]+), "
    r"Time Inside RedCircle: (?P<circle>[-\d.naif]+), Time Took: (?P<minutes>[-\d.]+) minutes, "
    r"Random Seed: (?P<seed>\d+)")
"""The line ``PostExperiment`` prints (collision in minutes, all robots; circle in minutes per
delivery: their ``(TimeInsideRedCircle / 60) / score``)."""


def experiment_xml(text: str, robots: int, seed: int) -> str:
    """Their experiment file with ``robots`` split over the four groups and ``seed`` set."""
    if robots % 4:
        raise ReferenceError(f"--robots {robots}: their experiment has four equal start groups, "
                             "so the swarm size must be a multiple of 4")
    groups = re.findall(r'<entity max_trials="\d+" quantity="\d+">', text)
    if len(groups) != 4:
        raise ReferenceError(f"{EXPERIMENT}: expected 4 robot groups, found {len(groups)}")
    text = re.sub(r'(<entity max_trials="\d+" quantity=")\d+(">)', rf"\g<1>{robots // 4}\g<2>", text)
    text, n = re.subn(r'random_seed="\d+"', f'random_seed="{seed}"', text)
    if n != 1:
        raise ReferenceError(f"{EXPERIMENT}: expected one random_seed attribute, found {n}")
    return text


def parse_line(output: str) -> dict:
    """The numbers of the one ``Resource Collected`` line in a run's output."""
    found = LINE.findall(output)
    if len(found) != 1:
        raise ReferenceError(f"argos3 printed {len(found)} 'Resource Collected' lines, expected 1")
    match = LINE.search(output)
    return {k: float(v) for k, v in match.groupdict().items()}


def row(strategy: str, robots: int, seed: int, printed: dict, wall_s: float, provenance: dict,
        cpu_s: float | None = None) -> dict:
    """One reference run in our results schema (the fields our queue rows share) plus provenance."""
    if int(printed["seed"]) != seed:
        raise ReferenceError(f"the run printed seed {int(printed['seed'])}, it was given {seed}")
    score = printed["score"]
    sim_s = printed["minutes"] * 60.0
    return {
        "strategy": strategy, "cell": robots, "scenario": strategy, "seed": seed, "robots": robots,
        "mode": "reference", "reference": True,
        "sim_seconds": round(sim_s, 3), "wall_seconds": round(wall_s, 3),
        "cpu_seconds": None if cpu_s is None else round(cpu_s, 3),
        "real_time_factor": round(sim_s / wall_s, 2) if wall_s > 0 else None,
        "total_resources": TOTAL_RESOURCES, "resources_delivered": int(round(score)),
        "resources_collected_pct": round(100.0 * score / TOTAL_RESOURCES, 6),
        "resources_per_robot": round(score / robots, 6),
        "authors_collision_time_total_min": printed["collision"],
        "authors_collision_time_per_robot_s": round(60.0 * printed["collision"] / robots, 6),
        "authors_time_in_circle_per_delivery_min": printed["circle"],
        **provenance,
    }


def run_one(argos: str, tree: Path, robots: int, seed: int, timeout_s: float) -> tuple[dict, float, float]:
    """The printed numbers, the wall seconds and the CPU seconds (user + system) of one run."""
    xml = experiment_xml((tree / EXPERIMENT).read_text(), robots, seed)
    output, wall, cpu = run_argos([argos], tree, xml, f".swarmforage_r{robots}_s{seed}.xml",
                                  f"robots {robots} seed {seed}", timeout_s)
    return parse_line(output), wall, cpu


def _done(out: Path) -> set[tuple[str, int, int, str]]:
    return done_keys(out, lambda r: (r["strategy"], int(r["robots"]), int(r["seed"]), r["commit"]))


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                epilog="Appends one row per run to --out; runs already there are skipped.")
    p.add_argument("--argos", required=True, help="the argos3 executable built here")
    p.add_argument("--tree", required=True, type=Path, help="a built checkout of the authors' repository")
    p.add_argument("--strategy", required=True, choices=("queue_qse", "queue_qst"),
                   help="what the checkout's branch is (main: queue_qse, CPFA-2.0: queue_qst)")
    p.add_argument("--repository", default="Tameem786/Collision_Free_CPFA")
    p.add_argument("--branch", required=True)
    p.add_argument("--commit", required=True, help="the checkout's commit (40 hex digits)")
    p.add_argument("--argos-commit", required=True, help="ARGoS 3's commit it was built from")
    p.add_argument("--build-fixes", default="", help="what was changed to build it, in words")
    p.add_argument("--robots", type=int, nargs="+", default=[48, 112])
    p.add_argument("--seeds", type=int, default=20, help="the first N of the authors' 20 seeds")
    p.add_argument("--timeout", type=float, default=1800.0, help="wall seconds one run may take")
    p.add_argument("--out", type=Path, default=Path("results/reference/queue/results.jsonl"))
    a = p.parse_args(argv)
    try:
        if not re.fullmatch(r"[0-9a-f]{40}", a.commit) or not re.fullmatch(r"[0-9a-f]{40}", a.argos_commit):
            raise ReferenceError("--commit and --argos-commit take 40 hex digits")
        if not 1 <= a.seeds <= len(AUTHORS_SEEDS):
            raise ReferenceError(f"--seeds {a.seeds}: the authors' list has {len(AUTHORS_SEEDS)}")
        if not (a.tree / EXPERIMENT).is_file():
            raise ReferenceError(f"--tree {a.tree}: no {EXPERIMENT}")
        provenance = {"repository": a.repository, "branch": a.branch, "commit": a.commit, "xml": EXPERIMENT,
                      "argos_commit": a.argos_commit, "build_fixes": a.build_fixes}
        a.out.parent.mkdir(parents=True, exist_ok=True)
        done = _done(a.out)
        for robots in a.robots:
            for seed in AUTHORS_SEEDS[:a.seeds]:
                if (a.strategy, robots, seed, a.commit) in done:
                    continue
                printed, wall, cpu = run_one(a.argos, a.tree, robots, seed, a.timeout)
                r = row(a.strategy, robots, seed, printed, wall, provenance, cpu)
                with a.out.open("a") as f:
                    f.write(json.dumps(r) + "\n")
                print(f"[reference] {a.strategy} {robots} robots seed {seed}: "
                      f"{r['resources_delivered']} resources in {wall:.1f} s wall, {cpu:.1f} s CPU", flush=True)
    except (ReferenceError, OSError) as e:
        print(f"reference: {e}", file=sys.stderr)
        return 2
    return 0


if __name__ == "__main__":
    sys.exit(main())

"""Run the queue authors' own ARGoS code here and record it in our results schema.

The reference for the queue paper's levels: Tameem786/Collision_Free_CPFA (branch ``main``: the
single queue with entry-point joining, the paper's Q_SE; branch ``CPFA-2.0``: tail joining, Q_ST),
run on an ARGoS 3 built on this machine; for the CPFA baseline, the plain CPFA in their
repositories (Artglz/Collision_Free_CPFA ``main``, "add existing files": the queue code's
``BaseController`` without the queues' additions) in their queue experiment's arena, with its one
nest at the centre (it takes one ``NestPosition``). Nothing of theirs is committed and nothing
here builds it (reference/README.md says why and what a checkout must hold): this script takes a
checkout that is already built, writes their experiment file with a swarm size and a seed set, runs
``argos3`` on it and turns the one line their ``CPFA_loop_functions::PostExperiment`` prints into
a row of ``results/reference/queue/results.jsonl``.

Their experiment (``experiments/Clustered_CPFA_r64_tag512_16by16.xml``) places the robots in
four ``<distribute>`` groups of equal ``quantity`` (28 each = 112); a swarm of N robots is four
groups of N / 4, as their logs' sizes 48-112 are. Seeds are their ``run.sh`` list.

That CPFA ends a run at ``MaxSimTimeInSeconds`` (theirs: at 18 minutes by the clock)
and prints ``score, seconds, seed``; its collision count (detections, not time) is not kept.
"""
from __future__ import annotations

import argparse
import json
import math
import re
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))  # run as a script or loaded by path
from argos_run import ANSI, done_keys, ReferenceError, run_argos  # noqa: E402

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
"""The line ``PostExperiment`` prints (collision in minutes, all robots: the ticks their
``CPFA_controller::CollisionDetection`` fired, one count a tick, divided by 2 x ticks per second,
so half the time; circle in minutes per delivery: their ``(TimeInsideRedCircle / 60) / score``,
each carrier's time from boarding (Q_SE) or entering the red circle (Q_ST) to reaching the nest:
the paper's drop-off time, which ours measures as ``dropoff_time_mean_s``)."""
CPFA_LINE = re.compile(r"^(?P<score>\d+(?:\.\d+)?), (?P<seconds>\d+(?:\.\d+)?), (?P<seed>\d+)$", re.MULTILINE)
"""The line that CPFA prints in ``PostExperiment`` (``printf("%f, %f, %lu\\n", ...)``)."""
CPFA = "queue_cpfa"
DURATION_S = 1080
"""The paper's 18 minutes (Table I)."""


def _set_one(text: str, attribute: str, value: str) -> str:
    text, n = re.subn(rf'{attribute}="[^"]*"', f'{attribute}="{value}"', text)
    if n != 1:
        raise ReferenceError(f"{EXPERIMENT}: expected one {attribute} attribute, found {n}")
    return text


def experiment_xml(text: str, robots: int, seed: int, strategy: str = "queue_qse") -> str:
    """Their experiment file with ``robots`` split over the four groups and ``seed`` set; for the
    CPFA baseline one nest at the centre and the run's end at 18 minutes."""
    if robots % 4:
        raise ReferenceError(f"--robots {robots}: their experiment has four equal start groups, "
                             "so the swarm size must be a multiple of 4")
    groups = re.findall(r'<entity max_trials="\d+" quantity="\d+">', text)
    if len(groups) != 4:
        raise ReferenceError(f"{EXPERIMENT}: expected 4 robot groups, found {len(groups)}")
    text = re.sub(r'(<entity max_trials="\d+" quantity=")\d+(">)', rf"\g<1>{robots // 4}\g<2>", text)
    text = _set_one(text, "random_seed", str(seed))
    if strategy == CPFA:
        text = _set_one(_set_one(text, "NestPosition", "0,0"), "MaxSimTimeInSeconds", str(DURATION_S))
    return text


def parse_line(output: str, strategy: str = "queue_qse") -> dict:
    """The numbers of the one result line in a run's output."""
    if strategy == CPFA:
        found = CPFA_LINE.findall(ANSI.sub("", output))
        if len(found) != 1:
            raise ReferenceError(f"argos3 printed {len(found)} 'score, seconds, seed' lines, expected 1")
        score, seconds, seed = (float(v) for v in found[0])
        return {"score": score, "minutes": seconds / 60.0, "seed": seed, "collision": None, "circle": None}
    found = LINE.findall(output)
    if len(found) != 1:
        raise ReferenceError(f"argos3 printed {len(found)} 'Resource Collected' lines, expected 1")
    match = LINE.search(output)
    return {k: float(v) for k, v in match.groupdict().items()}


def _finite(value: float | None) -> float | None:
    """A printed number, None where their print has none (``nan`` from a run that delivered nothing)."""
    return value if value is not None and math.isfinite(value) else None


def row(strategy: str, robots: int, seed: int, printed: dict, wall_s: float, provenance: dict,
        cpu_s: float | None = None) -> dict:
    """One reference run in our results schema (the fields our queue rows share) plus provenance."""
    if int(printed["seed"]) != seed:
        raise ReferenceError(f"the run printed seed {int(printed['seed'])}, it was given {seed}")
    score, collision, circle = printed["score"], _finite(printed["collision"]), _finite(printed["circle"])
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
        # their print is half the time their rule fired (`LINE`); ours counts the whole of it
        "authors_collision_time_total_min": None if collision is None else round(2.0 * collision, 6),
        "authors_collision_time_per_robot_s": (None if collision is None
                                               else round(2.0 * 60.0 * collision / robots, 6)),
        "authors_time_in_circle_per_delivery_min": circle,
        "dropoff_time_mean_s": None if circle is None else round(60.0 * circle, 6),
        **provenance,
    }


def run_one(argos: str, tree: Path, experiment: str, strategy: str, robots: int, seed: int,
            timeout_s: float) -> tuple[dict, float, float]:
    """The printed numbers, the wall seconds and the CPU seconds (user + system) of one run."""
    xml = experiment_xml(experiment, robots, seed, strategy)
    output, wall, cpu = run_argos([argos], tree, xml, f".swarmforage_r{robots}_s{seed}.xml",
                                  f"robots {robots} seed {seed}", timeout_s)
    return parse_line(output, strategy), wall, cpu


def _done(out: Path) -> set[tuple[str, int, int, str]]:
    return done_keys(out, lambda r: (r["strategy"], int(r["robots"]), int(r["seed"]), r["commit"]))


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                epilog="Appends one row per run to --out; runs already there are skipped.")
    p.add_argument("--argos", required=True, help="the argos3 executable built here")
    p.add_argument("--tree", required=True, type=Path, help="a built checkout of the authors' repository")
    p.add_argument("--strategy", required=True, choices=("queue_qse", "queue_qst", CPFA),
                   help="what the checkout's branch is (main: queue_qse, CPFA-2.0: queue_qst; "
                        "Artglz/Collision_Free_CPFA main: queue_cpfa)")
    p.add_argument("--experiment", type=Path,
                   help=f"the queue authors' experiment file (default: the checkout's {EXPERIMENT}; "
                        "queue_cpfa needs a Tameem786/Collision_Free_CPFA checkout's)")
    p.add_argument("--experiment-commit", help="the commit --experiment was taken from (40 hex digits)")
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
        experiment = a.experiment or a.tree / EXPERIMENT
        if a.strategy == CPFA and (a.experiment is None or a.experiment_commit is None):
            raise ReferenceError("--strategy queue_cpfa takes --experiment and --experiment-commit: the queue "
                                 "authors' experiment file, which the CPFA's own checkout does not hold")
        if a.experiment_commit is not None and not re.fullmatch(r"[0-9a-f]{40}", a.experiment_commit):
            raise ReferenceError("--experiment-commit takes 40 hex digits")
        if not experiment.is_file():
            raise ReferenceError(f"no experiment file {experiment}")
        xml = (EXPERIMENT if a.experiment is None else
               f"Tameem786/Collision_Free_CPFA {a.experiment_commit}:{EXPERIMENT}")
        if a.strategy == CPFA:
            xml += f' (NestPosition="0,0", MaxSimTimeInSeconds="{DURATION_S}")'
        provenance = {"repository": a.repository, "branch": a.branch, "commit": a.commit, "xml": xml,
                      "argos_commit": a.argos_commit, "build_fixes": a.build_fixes}
        text = experiment.read_text()
        a.out.parent.mkdir(parents=True, exist_ok=True)
        done = _done(a.out)
        for robots in a.robots:
            for seed in AUTHORS_SEEDS[:a.seeds]:
                if (a.strategy, robots, seed, a.commit) in done:
                    continue
                printed, wall, cpu = run_one(a.argos, a.tree, text, a.strategy, robots, seed, a.timeout)
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

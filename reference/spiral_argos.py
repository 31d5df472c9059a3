"""Run the spiral paper's authors' own ARGoS code here and record it in our results schema.

The reference for the MDBSA paper's levels (Lu & Luna 2023): MARSLab-UTRGV/Adaptive-Multiple-
Distributed-Spiral-Search-Algorithm, branch ``luki-dev`` ("the version for the submission"),
``Centralized/`` (MDBSA-C: a robot delivers to the nest, ``IsInTheNest``) and ``Distributed/``
(MDBSA-D: to its region's centre, ``IsInTheRegion``), and MARSLab-UTRGV/DDSA-Distributed-
Deterministic-Spiral-Search-Algorithm, branch ``luki-dev`` (DDSA), run on an ARGoS 3 built on
this machine. Nothing of theirs is committed and nothing here builds it: this script takes a
checkout that is already built, writes their experiment file with a seed, runs ``argos3`` on it
(``-z``: their files' ``<visualization>`` is ignored) and turns what their loop functions print
into a row of ``results/reference/spiral/exp<E>/results.jsonl``.

What they print (``DSA_loop_functions``, all three trees): a ``Minute Passed... getSimTimeInSeconds:
<s>, Food Collected: <n>`` line at every full minute (``PreStep``) and, after the run's full length
(no ``IsExperimentFinished``: a run is the file's ``length``), one summary line under the header
``Sim Time(s), Bots, Collected, Total, Collision Time(s), Percentage`` (``PostExperiment``). Their
collision time is the ticks on which each robot's ``BaseController::CollisionDetection`` fired,
summed over the robots and divided by ``2 * ticks_per_second``: seconds, halved.

Their experiment files set ``random_seed="0"`` or none (ARGoS then seeds from the clock) and their
``run_exp*.py`` rerun one file N times, so there is no seed list of theirs: seeds are 1..N here.
"""
from __future__ import annotations

import argparse
import json
import os
import re
import signal
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))  # run as a script or loaded by path
from argos_run import done_keys, ANSI, ReferenceError, run_argos  # noqa: E402

STRATEGIES = {
    "ddsa": ("MARSLab-UTRGV/DDSA-Distributed-Deterministic-Spiral-Search-Algorithm", ""),
    "mdbsa_c": ("MARSLab-UTRGV/Adaptive-Multiple-Distributed-Spiral-Search-Algorithm", "Centralized/"),
    "mdbsa_d": ("MARSLab-UTRGV/Adaptive-Multiple-Distributed-Spiral-Search-Algorithm", "Distributed/"),
}
"""Our strategy name: (the authors' repository, the tree's folder in it)."""

CELLS = {1: (4, 16, 64), 2: (8, 14, 20, 26, 32), 3: (100, 150, 200, 250, 300)}
"""The paper's Tables I-III: regions (exp. 1), robots (exp. 2), resources (exp. 3)."""

SUMMARY_HEADER = "Sim Time(s), Bots, Collected, Total, Collision Time(s), Percentage"
SUMMARY = re.compile(r"^\s*(?P<sim>\d+(?:\.\d*)?),\s+(?P<bots>\d+),\s+(?P<collected>\d+),\s+(?P<total>\d+),"
                     r"\s+(?P<collision>[-+\d.eE]+),\s+(?P<pct>[-+\d.eE]+)%\s*$")
MINUTE = re.compile(r"Minute Passed\.\.\. getSimTimeInSeconds: (?P<s>\d+), Food Collected: (?P<n>\d+)")
SEED = re.compile(r"Using random seed = (\d+)")

def xml_name(strategy: str, experiment: int, cell: int | None) -> str:
    """Their experiment file for a cell, relative to the tree. DDSA reads no ``NumOfRegions``:
    its three experiment-1 files differ in nothing else, so it runs once (cell None), as ours."""
    if experiment == 1:
        if strategy == "ddsa":
            if cell is not None:
                raise ReferenceError("DDSA has no regions: experiment 1 runs it with no cell")
            return "experiments/Experiment1_rg4.xml"
        return f"experiments/Experiment1_rg{cell}.xml"
    return f"experiments/Experiment{experiment}_{'r' if experiment == 2 else 'food'}{cell}.xml"


def experiment_xml(text: str, seed: int) -> str:
    """Their experiment file with ``random_seed`` set (replaced, or added to ``<experiment>``)."""
    if seed <= 0:
        raise ReferenceError(f"seed {seed}: ARGoS takes 0 as 'seed from the clock'; give one > 0")
    tags = re.findall(r"<experiment\b[^>]*>", text)
    if len(tags) != 1:
        raise ReferenceError(f"expected one <experiment> element, found {len(tags)}")
    tag = tags[0]
    if "random_seed" in tag:
        new, n = re.subn(r'random_seed\s*=\s*"\d*"', f'random_seed="{seed}"', tag)
        if n != 1:
            raise ReferenceError(f"cannot read the random_seed attribute of {tag!r}")
    else:
        new = tag.replace("<experiment", f'<experiment random_seed="{seed}"', 1)
    return text.replace(tag, new, 1)


def xml_facts(text: str) -> dict:
    """What the file says a run must print: its length [s], robots, resources, regions."""
    body = re.sub(r"<!--.*?-->", "", text, flags=re.S)

    def one(pattern: str, what: str) -> int:
        found = re.findall(pattern, body)
        if len(found) != 1:
            raise ReferenceError(f"expected one {what} in the experiment file, found {len(found)}")
        return int(found[0])
    return {"length_s": one(r'<experiment\b[^>]*\blength\s*=\s*"(\d+)"', "experiment length"),
            "robots": one(r'<entity\b[^>]*\bquantity\s*=\s*"(\d+)"', "robot quantity"),
            "resources": one(r'FoodItemCount\s*=\s*"(\d+)"', "FoodItemCount"),
            "regions": one(r'NumOfRegions\s*=\s*"(\d+)"', "NumOfRegions") if "NumOfRegions" in body else None}


def parse_output(output: str) -> dict:
    """The numbers of a run's summary line and its minute lines."""
    lines = ANSI.sub("", output).splitlines()
    heads = [i for i, line in enumerate(lines) if line.strip() == SUMMARY_HEADER]
    if len(heads) != 1:
        raise ReferenceError(f"argos3 printed {len(heads)} summary headers, expected 1")
    match = SUMMARY.match(lines[heads[0] + 1]) if heads[0] + 1 < len(lines) else None
    if match is None:
        raise ReferenceError("the line after the summary header is not 'time, bots, collected, total, "
                             "collision, percentage%'")
    seeds = {int(s) for line in lines for s in SEED.findall(line)}
    if len(seeds) != 1:
        raise ReferenceError(f"argos3 printed {len(seeds)} random seeds, expected 1")
    minutes = [(int(m["s"]), int(m["n"])) for line in lines if (m := MINUTE.search(line))]
    for k, (s, _) in enumerate(minutes):
        if s != 60 * (k + 1):
            raise ReferenceError(f"minute line {k + 1} says {s} s, expected {60 * (k + 1)}")
    printed = {k: float(v) for k, v in match.groupdict().items()}
    if sum(n for _, n in minutes) > printed["collected"]:
        raise ReferenceError("the minute lines count more resources than the summary's Collected")
    return {**printed, "seed": seeds.pop(), "minutes": [n for _, n in minutes]}


def row(strategy: str, experiment: int, cell: int | None, seed: int, facts: dict, printed: dict,
        wall_s: float, cpu_s: float | None, provenance: dict) -> dict:
    """One reference run in our spiral results schema (the fields our rows share) plus provenance."""
    if printed["seed"] != seed:
        raise ReferenceError(f"the run printed seed {printed['seed']}, it was given {seed}")
    robots, total, sim_s = int(printed["bots"]), int(printed["total"]), printed["sim"]
    if (robots, total, sim_s) != (facts["robots"], facts["resources"], facts["length_s"]):
        raise ReferenceError(f"the run printed {robots} robots, {total} resources, {sim_s:g} s; its file "
                             f"says {facts['robots']}, {facts['resources']}, {facts['length_s']}")
    delivered = int(printed["collected"])
    halved = printed["collision"]
    per_minute = [[60.0 * (k + 1), round(n / robots, 6)] for k, n in enumerate(printed["minutes"])]
    return {
        "strategy": strategy, "experiment": experiment, "cell": cell, "scenario": strategy, "seed": seed,
        "robots": robots, "regions": None if strategy == "ddsa" else facts["regions"], "layout": "tiers",
        "mode": "reference", "reference": True,
        "sim_seconds": sim_s, "wall_seconds": round(wall_s, 3),
        "cpu_seconds": None if cpu_s is None else round(cpu_s, 3),
        "real_time_factor": round(sim_s / wall_s, 2) if wall_s > 0 else None,
        "total_resources": total, "resources_delivered": delivered,
        "resources_collected_pct": round(100.0 * delivered / total, 6),
        "resources_per_robot": round(delivered / robots, 6),
        "foraging_rate_per_min": round(delivered / (sim_s / 60.0), 6),
        "resources_per_robot_per_min": per_minute,
        "resources_per_robot_per_min_mean":
            round(sum(v for _, v in per_minute) / len(per_minute), 6) if per_minute else None,
        # Their counter is our measure (ticks the ring saw something within the controller's
        # ahead range); they print it summed and halved, so the per-robot seconds are 2x / robots.
        "collision_time_per_robot_s": round(2.0 * halved / robots, 6),
        "collision_time_total_min": round(2.0 * halved / 60.0, 6),
        "authors_collision_time_per_robot_s": round(halved / robots, 6),
        "authors_collision_time_total_min": round(halved / 60.0, 6),
        **provenance,
    }


def run_one(argos: str, env: dict, tree: Path, xml: str, seed: int, timeout_s: float) -> tuple[dict, dict, float, float]:
    """(the file's facts, what the run printed, its wall seconds, its CPU seconds)."""
    text = (tree / xml).read_text()
    facts = xml_facts(text)
    output, wall, cpu = run_argos([argos, "-n", "-z"], tree, experiment_xml(text, seed),
                                  f".swarmforage_{Path(xml).stem}_s{seed}.xml", f"{xml} seed {seed}", timeout_s, env)
    try:
        return facts, parse_output(output), wall, cpu
    except ReferenceError as e:
        raise ReferenceError(f"{xml} seed {seed}: {e}") from None


def _done(out: Path) -> set[tuple]:
    return done_keys(out, lambda r: (r["strategy"], r["experiment"], r["cell"], int(r["seed"]), r["commit"]))


def _env(argos: str) -> dict:
    """The child's environment: the ARGoS install's libraries (``<prefix>/lib``, ``lib/argos3``) first."""
    prefix = Path(argos).resolve().parent.parent
    paths = [str(prefix / "lib"), str(prefix / "lib" / "argos3")]
    env = dict(os.environ)
    env["LD_LIBRARY_PATH"] = os.pathsep.join(paths + [p for p in env.get("LD_LIBRARY_PATH", "").split(os.pathsep) if p])
    return env


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                epilog="Appends one row per run to --out; runs already there are skipped.")
    p.add_argument("--argos", required=True, help="the argos3 executable built here")
    p.add_argument("--tree", required=True, type=Path,
                   help="a built tree of theirs: MDBSA's Centralized/ or Distributed/, or DDSA's root")
    p.add_argument("--strategy", required=True, choices=tuple(STRATEGIES),
                   help="what the tree is (Centralized/: mdbsa_c, Distributed/: mdbsa_d, DDSA: ddsa)")
    p.add_argument("--branch", default="luki-dev")
    p.add_argument("--commit", required=True, help="the tree's commit (40 hex digits)")
    p.add_argument("--argos-commit", required=True, help="ARGoS 3's commit it was built from")
    p.add_argument("--build-fixes", default="", help="what was changed to build it, in words")
    p.add_argument("--experiment", type=int, required=True, choices=tuple(CELLS))
    p.add_argument("--cells", type=int, nargs="+", help="a subset of the experiment's cells (not for DDSA in exp. 1)")
    p.add_argument("--seeds", type=int, default=20, help="seeds 1..N")
    p.add_argument("--timeout", type=float, default=1800.0, help="wall seconds one run may take")
    p.add_argument("--out", type=Path, help="default results/reference/spiral/exp<E>/results.jsonl")
    a = p.parse_args(argv)
    # a stopped sweep (SIGTERM) unwinds like ^C: the running argos3 is killed, its temporary file removed
    previous = signal.signal(signal.SIGTERM, lambda *_: sys.exit(143))
    try:
        if not re.fullmatch(r"[0-9a-f]{40}", a.commit) or not re.fullmatch(r"[0-9a-f]{40}", a.argos_commit):
            raise ReferenceError("--commit and --argos-commit take 40 hex digits")
        if a.seeds < 1:
            raise ReferenceError(f"--seeds {a.seeds}: at least 1")
        if a.experiment == 1 and a.strategy == "ddsa":
            if a.cells:
                raise ReferenceError("--cells: DDSA has no regions, experiment 1 runs it once per seed")
            cells: tuple = (None,)
        else:
            cells = tuple(a.cells or CELLS[a.experiment])
            if bad := [c for c in cells if c not in CELLS[a.experiment]]:
                raise ReferenceError(f"--cells {bad}: experiment {a.experiment}'s cells are {CELLS[a.experiment]}")
        repository, folder = STRATEGIES[a.strategy]
        out = a.out or Path(f"results/reference/spiral/exp{a.experiment}/results.jsonl")
        out.parent.mkdir(parents=True, exist_ok=True)
        done = _done(out)
        env = _env(a.argos)
        for cell in cells:
            xml = xml_name(a.strategy, a.experiment, cell)
            if not (a.tree / xml).is_file():
                raise ReferenceError(f"--tree {a.tree}: no {xml}")
            provenance = {"repository": repository, "branch": a.branch, "commit": a.commit, "xml": folder + xml,
                          "argos_commit": a.argos_commit, "build_fixes": a.build_fixes}
            for seed in range(1, a.seeds + 1):
                if (a.strategy, a.experiment, cell, seed, a.commit) in done:
                    continue
                facts, printed, wall, cpu = run_one(a.argos, env, a.tree, xml, seed, a.timeout)
                r = row(a.strategy, a.experiment, cell, seed, facts, printed, wall, cpu, provenance)
                with out.open("a") as f:
                    f.write(json.dumps(r) + "\n")
                print(f"[reference] {a.strategy} exp {a.experiment} cell {cell} seed {seed}: "
                      f"{r['resources_delivered']} resources in {wall:.1f} s wall, {cpu:.1f} s CPU", flush=True)
    except (ReferenceError, OSError) as e:
        print(f"reference: {e}", file=sys.stderr)
        return 2
    finally:
        signal.signal(signal.SIGTERM, previous)
    return 0


if __name__ == "__main__":
    sys.exit(main())

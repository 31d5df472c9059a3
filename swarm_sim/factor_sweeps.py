"""One factor at a time (issue 24, item 5): for the claims that do not hold on the authors' robots,
sweeps that each change one factor of the robot (or one reading of a rule) against a baseline on
the authors' robots, then FACTORS.md (`swarm_sim.compare.factors`). ``scripts/factors`` runs this.

Each paper declares its groups in its own package, a ``factors`` module beside its registration
holding ``GROUPS`` (a tuple of `FactorGroup`); this module finds them through the registry's entry
points and runs them. Every sweep is an ordinary ``swarm-compare`` run into OUT/<group>/<factor>/
and resumes (``--resume``): rerunning adds only what is missing. A group's baseline starts from
the main sweep's runs of the same cells (MAIN, default results/authors), so they are not run
twice. Each factor swaps one value of the authors' robot for today's generic robot's (or another
documented value) and says where it comes from in the group's README; nothing is chosen to
approach a paper's number.
"""

from __future__ import annotations

import argparse
import importlib
import importlib.util
import json
import subprocess
import sys
from dataclasses import dataclass
from importlib.metadata import entry_points
from pathlib import Path

from swarm_sim.registry import ENTRY_POINT_GROUP


@dataclass(frozen=True)
class Factor:
    name: str
    """Its folder under the group, and its name in FACTORS.md."""
    note: str
    """One line for the group's README: what it changes, instead of what, and where that comes from."""
    args: tuple[str, ...]
    """``swarm-compare`` arguments after the group's `FactorGroup.command`."""


@dataclass(frozen=True)
class FactorGroup:
    name: str
    command: tuple[str, ...]
    """``swarm-compare`` arguments every factor of the group starts with (the paper and its cells)."""
    main: str
    """The main sweep's results file under MAIN whose runs seed the baseline."""
    cells: str
    """Which of those runs: comma-separated cells, or ``all``."""
    factors: tuple[Factor, ...]
    baseline: str = "baseline"
    """Where under the group the baseline's ``swarm-compare`` keeps its results.jsonl."""
    strategies: tuple[str, ...] = ()
    """Which strategies' runs of those cells seed the baseline (empty: all), for a group that
    studies one strategy."""
    then: tuple[str, ...] = ()
    """A command run after the sweeps, as ``python -m`` arguments, given ``--jobs`` and ``--out
    OUT/<group>`` (a study that is no sweep, say)."""


def groups() -> dict[str, FactorGroup]:
    """Every paper's factor groups by name, in the order of the papers' entry points."""
    out: dict[str, FactorGroup] = {}
    for entry in entry_points(group=ENTRY_POINT_GROUP):
        module = entry.value.rpartition(".")[0] + ".factors"
        if importlib.util.find_spec(module) is None:
            continue
        for group in importlib.import_module(module).GROUPS:
            if group.name in out:
                raise ValueError(f"factor group {group.name!r} is declared twice ({module})")
            out[group.name] = group
    return out


def seed_baseline(group: FactorGroup, out: Path, main: Path) -> None:
    """The main sweep's runs of the group's cells as its baseline's runs (once: never over a
    baseline that has results already)."""
    src, dst = main / group.main, out / group.name / group.baseline / "results.jsonl"
    dst.parent.mkdir(parents=True, exist_ok=True)
    if not src.is_file() or dst.is_file():
        return
    cells = group.cells.split(",")
    lines = src.read_text().splitlines(keepends=True)
    rows = [(line, json.loads(line)) for line in lines if line.strip()]
    dst.write_text("".join(line for line, row in rows if (group.cells == "all" or str(row.get("cell")) in cells)
                           and (not group.strategies or row.get("strategy") in group.strategies)))


def sweep(group: FactorGroup, factor: Factor, out: Path, seeds: int, jobs: int) -> None:
    """One factor's sweep, its note added to the group's README if it is not there yet."""
    where = out / group.name / factor.name
    where.mkdir(parents=True, exist_ok=True)
    readme, line = out / group.name / "README", f"- `{factor.name}`: {factor.note}"
    if line not in (readme.read_text().splitlines() if readme.is_file() else []):
        with readme.open("a") as f:
            f.write(line + "\n")
    subprocess.run([sys.executable, "-m", "swarm_sim.compare.cli", *group.command, *factor.args,
                    "--seeds", str(seeds), "--jobs", str(jobs), "--out", str(where), "--resume"], check=True)


def main(argv: list[str] | None = None) -> int:
    known = groups()
    parser = argparse.ArgumentParser(prog="scripts/factors", description=__doc__.split("\n\n")[0])
    parser.add_argument("--seeds", type=int, default=2)
    parser.add_argument("--jobs", type=int, default=2)
    parser.add_argument("--out", type=Path, default=Path("results/factors"))
    parser.add_argument("--main", type=Path, default=Path("results/authors"))
    parser.add_argument("groups", nargs="*", metavar="GROUP", help=f"default: all ({', '.join(known)})")
    args = parser.parse_args(argv)
    unknown = [g for g in args.groups if g not in known]
    if unknown:
        print(f"factors: unknown group {unknown[0]} (known: {' '.join(known)})", file=sys.stderr)
        return 2
    try:
        for name in args.groups or known:
            group = known[name]
            seed_baseline(group, args.out, args.main)
            for factor in group.factors:
                sweep(group, factor, args.out, args.seeds, args.jobs)
            if group.then:
                subprocess.run([sys.executable, "-m", *group.then, "--jobs", str(args.jobs),
                                "--out", str(args.out / group.name)], check=True)
        subprocess.run([sys.executable, "-m", "swarm_sim.compare.factors", str(args.out)], check=True)
    except subprocess.CalledProcessError as exc:
        print(f"factors: {' '.join(exc.cmd[2:4])} failed (exit {exc.returncode})", file=sys.stderr)
        return exc.returncode
    return 0


if __name__ == "__main__":
    sys.exit(main())

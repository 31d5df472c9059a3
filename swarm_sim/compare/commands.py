"""``swarm-compare``'s parser and one comparison's run (a sweep, then its report): what the
single-comparison subcommands and ``all`` (`swarm_sim.compare.reproduce`) share."""

from __future__ import annotations

import argparse
import dataclasses
import sys
from collections.abc import Mapping, Sequence
from pathlib import Path

from swarm_sim import compare, registry
from swarm_sim.cli import first_paragraph, number
from swarm_sim.compare.comparison import Comparison
from swarm_sim.compare.report import caption, note_cut_runs, runs_caption
from swarm_sim.compare.sweep import (
    FAILED,
    RESULTS,
    ResultsFileError,
    RunFunction,
    RunPlan,
    SweepResult,
    read_results,
    run_sweep,
)
from swarm_sim.executors import Executor, add_executor_arguments
from swarm_sim.robots import known_models
from swarm_sim.scenario import ScenarioError, load_scenario

AUTHORS = "authors"
"""``--robot-model authors``: each run on its algorithm's authors' robot (`registry.Algorithm.authors_robot`)."""


def strategies_of(text: Sequence[str] | None, known: Sequence[str], parser: argparse.ArgumentParser) -> list[str]:
    if not text:
        return list(known)
    unknown = [s for s in text if s not in known]
    if unknown:
        parser.error(f"unknown strategy {unknown[0]!r} (known: {', '.join(known)})")
    return [s for s in known if s in text]  # the paper's order


ALL = "all"
"""The subcommand that runs every comparison's `reproduce` sweeps and writes REPORT.md."""


def common_arguments(p: argparse.ArgumentParser, out: str, *, strategies: bool = True) -> None:
    p.add_argument("--seeds", type=number(int, 1, 10**6), default=10, help="runs per cell, seeds 0..N-1 (default 10)")
    add_executor_arguments(p)
    p.add_argument("--out", type=Path, default=Path(out), help=f"output directory (default {out})")
    p.add_argument("--duration", type=number(float, 0, open_low=True),
                   help="sim seconds (sim.duration), overrides the paper's")
    p.add_argument("--set", dest="overrides", action="append", default=[], metavar="KEY=VALUE",
                   help="override any scenario field for every run")
    p.add_argument("--robot-model", choices=(*known_models(), AUTHORS), metavar="NAME",
                   help=f"the robot model of every run ({', '.join(known_models())}; {AUTHORS}: each "
                        "algorithm's authors' robot); default: each scenario's own (the authors' robot, but for the "
                        "DRTM paper's e-puck experiments)")
    if strategies:
        p.add_argument("--strategies", nargs="+", metavar="NAME", help="a subset of the strategies")
    mode = p.add_mutually_exclusive_group()
    mode.add_argument("--resume", action="store_true", help="keep results.jsonl and run only missing runs")
    mode.add_argument("--overwrite", action="store_true", help="discard an existing results.jsonl")
    mode.add_argument("--report-only", action="store_true",
                      help="run nothing: write the report from the runs results.jsonl holds (any seeds)")


def build_parser(comparisons: Mapping[str, Comparison]) -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog="swarm-compare", description=first_paragraph(compare.__doc__))
    sub = parser.add_subparsers(dest="command", required=True)
    for name, comparison in comparisons.items():
        if name == ALL:
            raise ValueError(f"a comparison may not be named {ALL!r}")
        p = sub.add_parser(name, help=comparison.help)
        comparison.add_arguments(p)
        common_arguments(p, comparison.default_out)
    p = sub.add_parser(ALL, help=f"every comparison ({', '.join(comparisons)}) with the papers' settings, "
                                 "then one REPORT.md")
    common_arguments(p, "results", strategies=False)
    return parser


def plans_of(comparison: Comparison, args: argparse.Namespace, strategies: list[str]) -> list[RunPlan]:
    """The comparison's runs, on the robot model ``--robot-model`` asks for (``robots.model`` set
    before the user's ``--set``s, which still win)."""
    plans = comparison.plans(args, strategies)
    model = getattr(args, "robot_model", None)
    if not model:
        return plans
    out = []
    for plan in plans:
        name = model
        if model == AUTHORS:
            # The algorithm decides the model; `robots.platform` values apply only once it is chosen.
            known = [o for o in plan.overrides if not o.startswith("robots.platform.")]
            scenario = load_scenario(plan.strategy, known, **dict(plan.fields))
            name = registry.of(scenario).authors_robot
        given = tuple(o for o in plan.overrides if o not in args.overrides)
        out.append(dataclasses.replace(plan, overrides=(*given, f"robots.model={name}", *args.overrides)))
    return out


def held_rows(plans: list[RunPlan], path: Path) -> list[dict]:
    """The runs of `plans` that the results file holds, in plan then seed order."""
    order = {(p.strategy, p.settings): i for i, p in enumerate(plans)}
    rows = [r for r in read_results(path) if (r.get("strategy"), r.get("settings")) in order]
    return sorted(rows, key=lambda r: (order[(r.get("strategy"), r.get("settings"))], r.get("seed", 0)))


def run_comparison(comparison: Comparison, args: argparse.Namespace, strategies: list[str], *,
                   run: RunFunction | None, executor: Executor) -> tuple[int, list[Path]]:
    """One comparison's sweep then its report: (exit status, files written)."""
    try:
        plans = plans_of(comparison, args, strategies)
    except ScenarioError as exc:
        print(f"swarm-compare: {exc}", file=sys.stderr)
        return 2, []
    out = comparison.out_dir(args)
    if run is None:
        for plan in plans:
            try:
                load_scenario(plan.strategy, plan.overrides, **dict(plan.fields))
            except ScenarioError as exc:
                print(f"swarm-compare: {plan.strategy} (cell {plan.cell}): {exc}", file=sys.stderr)
                return 2, []
    path = out / RESULTS
    if args.overwrite:
        for old in (path, out / FAILED):
            old.unlink(missing_ok=True)
    if getattr(args, "report_only", False):
        result = SweepResult(held_rows(plans, path))
        if not result.rows:
            print(f"swarm-compare: {path} holds no runs of this sweep", file=sys.stderr)
            return 2, []
    else:
        try:
            result = run_sweep(plans, list(range(args.seeds)), path, executor=executor, run=run, resume=args.resume)
        except (FileExistsError, ResultsFileError) as exc:
            print(f"swarm-compare: {exc}", file=sys.stderr)
            return 2, []
        except KeyboardInterrupt:
            print(f"\nswarm-compare: interrupted; finished runs are in {path} (continue with --resume)",
                  file=sys.stderr)
            return 130, []
    with caption(runs_caption(result.rows, args.overrides, _scenario_model)):
        written = comparison.write_report(result.rows, out, args, strategies)
    note_cut_runs(written, args.duration)
    print(f"{len(result.rows)} runs in {path}; wrote {', '.join(p.name for p in written)} in {out}")
    if result.failed:
        print(f"swarm-compare: {len(result.failed)} runs failed (errors in {out / FAILED}; --resume "
              "tries them again)", file=sys.stderr)
        return 1, written
    return 0, written


def _scenario_model(strategy: str | None) -> str:
    """The robot model a shipped scenario names ("?" for one that no longer loads)."""
    try:
        return load_scenario(strategy).robots.model
    except (ScenarioError, TypeError):
        return "?"

"""``swarm-compare``: one subcommand per paper comparison, each a sweep then a report.

The subcommands come from a mapping of name -> `Comparison` (by default
`swarm_sim.compare.comparisons()`); nothing here knows a paper.
"""

from __future__ import annotations

import argparse
import sys
from collections.abc import Mapping, Sequence
from pathlib import Path

from swarm_sim import compare
from swarm_sim.compare.comparison import Comparison
from swarm_sim.compare.sweep import RESULTS, Runner, RunPlan, run_sweep


def _strategies(text: Sequence[str] | None, known: Sequence[str], parser: argparse.ArgumentParser) -> list[str]:
    if not text:
        return list(known)
    unknown = [s for s in text if s not in known]
    if unknown:
        parser.error(f"unknown strategy {unknown[0]!r} (known: {', '.join(known)})")
    return [s for s in known if s in text]  # the paper's order


def _common(p: argparse.ArgumentParser, out: str) -> None:
    p.add_argument("--seeds", type=int, default=10, help="runs per cell, seeds 0..N-1 (default 10)")
    p.add_argument("--jobs", type=int, default=1, help="runs in parallel (processes)")
    p.add_argument("--out", type=Path, default=Path(out), help=f"output directory (default {out})")
    p.add_argument("--duration", type=float, help="sim seconds (sim.duration), overrides the paper's")
    p.add_argument("--set", dest="overrides", action="append", default=[], metavar="KEY=VALUE",
                   help="override any scenario field for every run")
    p.add_argument("--strategies", nargs="+", metavar="NAME", help="a subset of the strategies")
    mode = p.add_mutually_exclusive_group()
    mode.add_argument("--resume", action="store_true", help="keep results.jsonl and run only missing runs")
    mode.add_argument("--overwrite", action="store_true", help="discard an existing results.jsonl")


def build_parser(comparisons: Mapping[str, Comparison]) -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog="swarm-compare", description=compare.__doc__.splitlines()[0])
    sub = parser.add_subparsers(dest="command", required=True)
    for name, comparison in comparisons.items():
        p = sub.add_parser(name, help=comparison.help)
        comparison.add_arguments(p)
        _common(p, comparison.default_out)
    return parser


def main(argv: list[str] | None = None, runner: Runner | None = None,
         comparisons: Mapping[str, Comparison] | None = None) -> int:
    """`runner` replaces `run_many` (tests); with the real runner every scenario is loaded first.
    `comparisons` replaces `swarm_sim.compare.comparisons()`."""
    comparisons = compare.comparisons() if comparisons is None else comparisons
    parser = build_parser(comparisons)
    args = parser.parse_args(argv)
    comparison = comparisons[args.command]
    strategies = _strategies(args.strategies, comparison.strategies, parser)
    plans = comparison.plans(args, strategies)
    out = comparison.out_dir(args)
    if runner is None:
        from swarm_sim.scenario import ScenarioError, load_scenario

        for plan in plans:
            try:
                load_scenario(plan.strategy, plan.overrides, **dict(plan.fields))
            except ScenarioError as exc:
                print(f"swarm-compare: {plan.strategy} (cell {plan.cell}): {exc}", file=sys.stderr)
                return 2
    path = out / RESULTS
    if args.overwrite and path.exists():
        path.unlink()
    failed: list[str] = []

    def on_error(plan: RunPlan, exc: Exception) -> None:
        failed.append(f"{plan.strategy} (cell {plan.cell})")
        print(f"swarm-compare: {plan.strategy} cell={plan.cell} failed, going on without it: "
              f"{type(exc).__name__}: {exc}", file=sys.stderr)

    try:
        rows = run_sweep(plans, list(range(args.seeds)), path, jobs=args.jobs, runner=runner,
                         resume=args.resume, on_error=on_error)
    except FileExistsError as exc:
        print(f"swarm-compare: {exc}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print(f"\nswarm-compare: interrupted; finished runs are in {path} (continue with --resume)",
              file=sys.stderr)
        return 130
    written = comparison.write_report(rows, out, args, strategies)
    print(f"{len(rows)} runs in {path}; wrote {', '.join(p.name for p in written)} in {out}")
    if failed:
        print(f"swarm-compare: {len(failed)} plans failed: {', '.join(failed)}", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())

"""``swarm-compare all``: every registered comparison's reproduction sweeps, then one REPORT.md.

The comparisons come from the registry (`swarm_sim.compare.comparisons`), so a paper whose
algorithm registers a `Comparison` is picked up without a change here. Each comparison's
`reproduce` option sets are run as its own subcommand would run them, into ``OUT/<name>/``
(the ``results/queue``, ``results/spiral/exp1`` ... layout), on one shared executor. REPORT.md then
gathers, per comparison and sweep, the markdown files it wrote (its tables next to the paper's
numbers and its statistics) and its plots, after a summary table of the papers' headline claims
and whether our runs bear them out.
"""

from __future__ import annotations

import argparse
import sys
from contextlib import nullcontext
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from datetime import datetime, timezone
from pathlib import Path

from swarm_sim.compare.comparison import Comparison, Headline
from swarm_sim.compare.commands import build_parser, plans_of, run_comparison
from swarm_sim.compare.report import md_table
from swarm_sim.compare.sweep import RESULTS, RunFunction, read_results
from swarm_sim.executors import Executor, executor_from_args

REPORT = "REPORT.md"


@dataclass
class SweepReport:
    """What one comparison sweep of ``all`` left for REPORT.md."""

    comparison: Comparison
    options: tuple[str, ...]
    out: Path
    status: int
    written: list[Path] = field(default_factory=list)
    headlines: list[Headline] = field(default_factory=list)
    runs: int = 0
    error: str = ""


def sweep_argv(name: str, options: Sequence[str], args: argparse.Namespace, out: Path) -> list[str]:
    """The single-comparison command line that one sweep of ``all`` amounts to."""
    argv = [name, *options, "--seeds", str(args.seeds), "--out", str(out)]
    if args.duration is not None:
        argv += ["--duration", repr(args.duration)]
    for text in args.overrides:
        argv += ["--set", text]
    if getattr(args, "robot_model", None):
        argv += ["--robot-model", args.robot_model]
    if args.resume:
        argv.append("--resume")
    if args.overwrite:
        argv.append("--overwrite")
    return argv


def reproduce_all(args: argparse.Namespace, comparisons: Mapping[str, Comparison], *,
                  run: RunFunction | None = None, executor: Executor | None = None) -> int:
    parser = build_parser(comparisons)
    reports: list[SweepReport] = []
    try:
        with nullcontext(executor) if executor else executor_from_args(args) as ex:
            for name, comparison in comparisons.items():
                out = args.out / Path(comparison.default_out).name
                for options in comparison.reproduce:
                    argv = sweep_argv(name, options, args, out)
                    print(f"[swarm-compare all] swarm-compare {' '.join(argv)}", flush=True)
                    sub = parser.parse_args(argv)
                    strategies = list(comparison.strategies)
                    report = SweepReport(comparison, tuple(options), comparison.out_dir(sub), 0)
                    try:
                        report.status, report.written = run_comparison(comparison, sub, strategies, run=run,
                                                                       executor=ex)
                        rows = _rows(report.out, comparison, sub, strategies)
                        report.runs = len(rows)
                        report.headlines = comparison.headlines(rows, sub, strategies)
                    except KeyboardInterrupt:
                        raise
                    except Exception as exc:  # one paper's broken report must not lose the others
                        report.status, report.error = 1, f"{type(exc).__name__}: {exc}"
                        print(f"swarm-compare all: {name} {' '.join(options)}: {report.error}", file=sys.stderr)
                    reports.append(report)
                    if report.status == 130:
                        raise KeyboardInterrupt
    except (RuntimeError, OSError) as exc:
        print(f"swarm-compare: {exc}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print("swarm-compare all: interrupted; continue with --resume", file=sys.stderr)
        return 130
    path = write_report(reports, args)
    print(f"[swarm-compare all] wrote {path}")
    return max((r.status for r in reports), default=0)


def _rows(out: Path, comparison: Comparison, args: argparse.Namespace, strategies: list[str]) -> list[dict]:
    """This sweep's rows from its results file (the plans' strategies and settings only)."""
    keys = {(p.strategy, p.settings) for p in plans_of(comparison, args, strategies)}
    return [r for r in read_results(out / RESULTS) if (r.get("strategy"), r.get("settings")) in keys]


def _holds(value: bool | None) -> str:
    return {True: "yes", False: "**no**", None: "n/a"}[value]


def _demote(text: str, levels: int) -> list[str]:
    """Markdown `text` with every heading `levels` deeper, so it nests under ours."""
    return [("#" * levels + line) if line.startswith("#") else line for line in text.splitlines()]


def write_report(reports: Sequence[SweepReport], args: argparse.Namespace) -> Path:
    out: Path = args.out
    out.mkdir(parents=True, exist_ok=True)
    command = f"swarm-compare all --seeds {args.seeds} --out {out}"
    if args.duration is not None:
        command += f" --duration {args.duration:g}"
    command += "".join(f" --set {s}" for s in args.overrides)
    if getattr(args, "robot_model", None):
        command += f" --robot-model {args.robot_model}"
    lines = ["# The papers' results, reproduced", "",
             f"Generated {datetime.now(timezone.utc):%Y-%m-%d %H:%M} UTC by `{command}` (batch runner, seeds "
             f"0..{args.seeds - 1} per cell, and every further seed a sweep's results file already held: each "
             "section gives its run count). Every number labelled *paper* is the paper's, hard-coded from its "
             "text; every other number is ours, from `results.jsonl` beside each section's files.", ""]
    if args.duration is not None:
        lines += [f"> **Rehearsal:** every run was cut to {args.duration:g} s of sim time, so these numbers "
                  "are not comparable with the papers'.", ""]
    lines += ["## Headline claims", "",
              "Each claim checked on our runs (means per cell; the tests behind them are in each section). "
              "*holds*: yes / **no** / n/a (our runs cannot tell).", ""]
    body = []
    for r in reports:
        where = f"{r.comparison.name} {' '.join(r.options)}".strip()
        for h in r.headlines:
            body.append([where, h.claim, h.paper, h.ours, _holds(h.holds)])
        if not r.headlines:
            body.append([where, "(no headline claims declared)" if not r.error else f"failed: {r.error}",
                         "", "", "n/a"])
    lines += md_table(["sweep", "claim", "paper", "ours", "holds"], body) + [""]
    held = [h.holds for r in reports for h in r.headlines]
    lines += [f"{held.count(True)} of {len(held)} claims hold, {held.count(False)} do not, "
              f"{held.count(None)} cannot be told.", ""]
    for r in reports:
        title = f"{r.comparison.name} {' '.join(r.options)}".strip()
        lines += [f"## {title}: {r.comparison.help}", "",
                  f"{r.runs} runs in `{_rel(r.out / RESULTS, out)}`" + (f"; exit status {r.status}" if r.status else ""),
                  ""]
        if r.error:
            lines += [f"The report of this sweep failed: `{r.error}`", ""]
        for path in r.written:
            if path.suffix == ".md":
                lines += _demote(path.read_text(), 2) + [""]
        for path in r.written:
            if path.suffix == ".png":
                lines += [f"![{path.stem}]({_rel(path, out)})", ""]
    path = out / REPORT
    path.write_text("\n".join(lines))
    return path


def _rel(path: Path, root: Path) -> str:
    try:
        return str(path.relative_to(root))
    except ValueError:
        return str(path)

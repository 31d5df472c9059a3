"""``swarm-compare all``: every registered comparison's reproduction sweeps, then one REPORT.md.

The comparisons come from the registry (`swarm_sim.compare.comparisons`), so a paper whose
algorithm registers a `Comparison` is picked up without a change here. Each comparison's
`reproduce` option sets are run as its own subcommand would run them, into ``OUT/<name>/``
(the ``results/queue``, ``results/spiral/exp1`` ... layout), on one shared executor. REPORT.md then
opens with the verdicts on every claim each paper's package declares (`swarm_sim.compare.verdicts`,
`report_verdicts`): the count per verdict class for each paper and robot model, every level cell,
the relations and trends, the causes of what does not hold with their grades, and where a paper's
text and its authors' code disagree which rule each scenario follows; then, per comparison and
sweep, the markdown files it wrote and its plots.

Without ``--robot-model``, every sweep runs twice: on each algorithm's authors' robot
(``--robot-model authors``, into ``OUT/authors/``) and on today's generic robot (``OUT/generic/``),
and REPORT.md puts each claim's result on both side by side, with the count of claims holding for
each, then includes ``OUT/CAUSES.md`` (the evidence behind the causes, written from the
one-factor-at-a-time sweeps) when there is one. Where ``OUT/reference/<comparison>/**/results.jsonl``
holds runs of the authors' own code (same fields as ours, plus ``reference: true``), every level cell,
relation and trend also shows them and our runs judged against them (`swarm_sim.compare.reference`),
and every comparison figure draws them beside our boxes and the paper's numbers.
"""

from __future__ import annotations

import argparse
import sys
from collections.abc import Mapping, Sequence
from contextlib import nullcontext
from dataclasses import dataclass, field
from datetime import datetime, timezone
from pathlib import Path

from swarm_sim.compare.commands import AUTHORS, build_parser, plans_of, run_comparison
from swarm_sim.compare.comparison import Comparison
from swarm_sim.compare.reference import load_reference, matching
from swarm_sim.compare.report import reference_runs
from swarm_sim.compare.sweep import RESULTS, RunFunction, read_results
from swarm_sim.compare.verdict_report import common_fields, report_verdicts
from swarm_sim.compare.verdicts import Claim
from swarm_sim.executors import Executor, executor_from_args
from swarm_sim.robots import GENERIC

REPORT = "REPORT.md"
CAUSES = "CAUSES.md"
"""In OUT, written by hand from the factor sweeps: REPORT.md includes it after the claims."""
MODELS = (AUTHORS, GENERIC)
"""What ``all`` runs without ``--robot-model``: the authors' robots, then today's robot."""
MODEL_TITLES = {AUTHORS: "authors' robots", GENERIC: "generic robot"}


@dataclass
class SweepReport:
    """What one comparison sweep of ``all`` left for REPORT.md."""

    comparison: Comparison
    options: tuple[str, ...]
    out: Path
    status: int
    written: list[Path] = field(default_factory=list)
    claims: tuple[Claim, ...] = ()
    rows: list[dict] = field(default_factory=list)
    extra: dict = field(default_factory=dict)
    """The fields every run of the sweep carries alike (``experiment``): reference runs match on them."""
    runs: int = 0
    error: str = ""


def sweep_argv(name: str, options: Sequence[str], args: argparse.Namespace, out: Path,
               model: str | None = None) -> list[str]:
    """The single-comparison command line that one sweep of ``all`` amounts to (on robot `model`)."""
    argv = [name, *options, "--seeds", str(args.seeds), "--out", str(out)]
    if args.duration is not None:
        argv += ["--duration", repr(args.duration)]
    for text in args.overrides:
        argv += ["--set", text]
    if model:
        argv += ["--robot-model", model]
    if args.resume:
        argv.append("--resume")
    if args.overwrite:
        argv.append("--overwrite")
    if getattr(args, "report_only", False):
        argv.append("--report-only")
    return argv


def reproduce_all(args: argparse.Namespace, comparisons: Mapping[str, Comparison], *,
                  run: RunFunction | None = None, executor: Executor | None = None) -> int:
    parser = build_parser(comparisons)
    models = (args.robot_model,) if getattr(args, "robot_model", None) else MODELS
    by_model: dict[str, list[SweepReport]] = {}
    try:
        with nullcontext(executor) if executor else executor_from_args(args) as ex:
            for model in models:
                by_model[model] = _reproduce(args, comparisons, parser, model, len(models) > 1, run, ex)
    except (RuntimeError, OSError) as exc:
        print(f"swarm-compare: {exc}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print("swarm-compare all: interrupted; continue with --resume", file=sys.stderr)
        return 130
    path = write_report(by_model, args)
    print(f"[swarm-compare all] wrote {path}")
    return max((r.status for reports in by_model.values() for r in reports), default=0)


def _reproduce(args: argparse.Namespace, comparisons: Mapping[str, Comparison], parser: argparse.ArgumentParser,
               model: str, own_dir: bool, run: RunFunction | None, ex: Executor) -> list[SweepReport]:
    """Every comparison's sweeps on robot `model`, into OUT/<model>/ when `own_dir`, else OUT."""
    reports: list[SweepReport] = []
    base = args.out / model if own_dir else args.out
    reference = {name: load_reference(args.out, name) for name in comparisons}
    for name, comparison in comparisons.items():
        out = base / Path(comparison.default_out).name
        for options in comparison.reproduce:
            argv = sweep_argv(name, options, args, out, model)
            print(f"[swarm-compare all] swarm-compare {' '.join(argv)}", flush=True)
            sub = parser.parse_args(argv)
            strategies = list(comparison.strategies)
            report = SweepReport(comparison, tuple(options), comparison.out_dir(sub), 0)
            try:
                report.claims = tuple(comparison.claims(sub))  # first: a failed sweep's claims read n/a
                extra = common_fields([dict(p.extra) for p in plans_of(comparison, sub, strategies)])
                with reference_runs(matching(reference.get(name) or (), extra)):
                    report.status, report.written = run_comparison(comparison, sub, strategies, run=run,
                                                                   executor=ex)
                report.rows, report.extra = _rows(report.out, comparison, sub, strategies)
                report.runs = len(report.rows)
            except KeyboardInterrupt:
                raise
            except Exception as exc:  # one paper's broken report must not lose the others
                report.status, report.error = 1, f"{type(exc).__name__}: {exc}"
                print(f"swarm-compare all: {name} {' '.join(options)}: {report.error}", file=sys.stderr)
            reports.append(report)
            if report.status == 130:
                raise KeyboardInterrupt
    return reports


def _rows(out: Path, comparison: Comparison, args: argparse.Namespace, strategies: list[str]
          ) -> tuple[list[dict], dict]:
    """This sweep's rows from its results file (the plans' strategies and settings only), and the
    fields all its plans add alike."""
    plans = plans_of(comparison, args, strategies)
    keys = {(p.strategy, p.settings) for p in plans}
    rows = [r for r in read_results(out / RESULTS) if (r.get("strategy"), r.get("settings")) in keys]
    return rows, common_fields([dict(p.extra) for p in plans])


def _demote(text: str, levels: int) -> list[str]:
    """Markdown `text` with every heading `levels` deeper, so it nests under ours."""
    return [("#" * levels + line) if line.startswith("#") else line for line in text.splitlines()]


def write_report(by_model: Mapping[str, Sequence[SweepReport]], args: argparse.Namespace) -> Path:
    """REPORT.md: the verdicts on every claim (`report_verdicts`, on each robot model side by side
    when there are two), the evidence behind the causes (``OUT/CAUSES.md``), then every sweep's
    tables and plots."""
    out: Path = args.out
    out.mkdir(parents=True, exist_ok=True)
    models = list(by_model)
    report_only = getattr(args, "report_only", False)
    command = f"swarm-compare all --report-only --out {out}" if report_only else \
        f"swarm-compare all --seeds {args.seeds} --out {out}"
    if args.duration is not None:
        command += f" --duration {args.duration:g}"
    command += "".join(f" --set {s}" for s in args.overrides)
    if getattr(args, "robot_model", None):
        command += f" --robot-model {args.robot_model}"
    lines = ["# The papers' results, reproduced", "",
             f"Generated {datetime.now(timezone.utc):%Y-%m-%d %H:%M} UTC by `{command}` (batch runner, "
             + ("every run each sweep's results file holds, whatever its seeds" if report_only else
                f"seeds 0..{args.seeds - 1} per cell, and every further seed a sweep's results file already held")
             + ": each section gives its run count). Every number labelled *paper* is the paper's, hard-coded from "
             "its text; every other number is ours, from `results.jsonl` beside each section's files.", ""]
    if len(models) > 1:
        lines += ["Every sweep ran on two robot models (`swarm_sim.robots`, [docs/robot_models.md](../docs/robot_models.md)): "
                  + "; ".join(f"*{MODEL_TITLES.get(m, m)}* (`--robot-model {m}`, in `{m}/`)" for m in models)
                  + ".", ""]
    if args.duration is not None:
        lines += [f"> **Rehearsal:** every run was cut to {args.duration:g} s of sim time, so these numbers "
                  "are not comparable with the papers'.", ""]
    lines += report_verdicts(by_model, out, MODEL_TITLES)
    causes = out / CAUSES
    if causes.is_file():
        lines += _demote(causes.read_text(), 1) + [""]
    for m in models:
        for r in by_model[m]:
            title = f"{r.comparison.name} {' '.join(r.options)}".strip()
            on = f" ({MODEL_TITLES.get(m, m)})" if len(models) > 1 else ""
            lines += [f"## {title}{on}: {r.comparison.help}", "",
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

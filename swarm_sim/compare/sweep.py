"""The resumable sweep: run plans for every seed and append each result to ``results.jsonl`` at once.

An interrupted sweep keeps what it finished and ``--resume`` runs only what is missing, whatever
executed the runs (`swarm_sim.executors`: local pool or Dask), since the bookkeeping happens here,
as each run's outcome arrives. A run is identified by its strategy (scenario name), its settings
(the overrides and fields it was loaded with) and its seed. A run that raises is appended to
``failed.jsonl`` with its error and the sweep goes on; ``--resume`` tries it again. The per-run
function is an argument so tests can feed the sweep fake summaries.
"""

from __future__ import annotations

import json
import sys
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from swarm_sim import registry
from swarm_sim.compare.report import fmt
from swarm_sim.executors import Executor, LocalExecutor, Progress

RunFunction = Callable[[tuple[str, tuple[str, ...], dict, int]], dict]
"""`swarm_sim.batch.run_one`'s signature: (scenario, overrides, fields, seed) -> summary; a
module-level function, since executors pickle it."""

RESULTS = "results.jsonl"
FAILED = "failed.jsonl"
"""Next to the results: one line per failed run (strategy, cell, settings, seed, error)."""


def frozen_fields(fields: dict[str, Any]) -> tuple[tuple[str, Any], ...]:
    """`fields` as a sorted tuple without the unset (None) ones, for `RunPlan.fields`."""
    return tuple(sorted((k, v) for k, v in fields.items() if v is not None))


@dataclass(frozen=True)
class RunPlan:
    """One strategy in one cell, to be run for every seed."""

    strategy: str
    """Scenario name (stored as the row's `strategy`)."""
    cell: int | None
    """Value of the swept setting (swarm size, regions, resources); None: the same runs serve
    every cell (DDSA in experiment 1)."""
    overrides: tuple[str, ...] = ()
    """``--set`` strings, applied in order (the user's last, so they win)."""
    fields: tuple[tuple[str, Any], ...] = ()
    """`load_scenario` field overrides (``robots__count``); applied after `overrides`."""
    extra: tuple[tuple[str, Any], ...] = ()
    """Keys added to every stored row (``experiment``, ``layout``)."""

    @property
    def settings(self) -> str:
        """Canonical text of what the runs were loaded with (the resume key with strategy, seed)."""
        return json.dumps({"overrides": list(self.overrides), "fields": dict(self.fields)}, sort_keys=True)


def slim(summary: dict[str, Any]) -> dict[str, Any]:
    """A summary without the per-robot dicts and the probes' per-event lists, each of which
    is kept as its length (`swarm_sim.registry.Probe.details`); their means stay."""
    details = dict(d for p in registry.probes() for d in p.details)
    row = {k: v for k, v in summary.items() if not k.endswith("_by_robot") and k not in details}
    row.update({count: len(summary[field]) for field, count in details.items() if field in summary})
    return row


class ResultsFileError(ValueError):
    """A results file that is not one of ours (not a regular file, not UTF-8 text)."""


def read_results(path: Path) -> list[dict[str, Any]]:
    """Rows of a results file; a line cut short by an interrupted write is skipped. A file that
    cannot be ours (a FIFO or directory, not UTF-8 text: we write JSON lines) raises
    ResultsFileError naming the problem, before anything is appended to it."""
    if not path.exists():
        return []
    if not path.is_file():
        raise ResultsFileError(f"{path} is not a regular file; move it away or choose another --out")
    try:
        text = path.read_bytes().decode("utf-8")
    except UnicodeDecodeError as exc:
        raise ResultsFileError(f"{path} is not UTF-8 text (byte {exc.start}): not a results file of ours; move it "
                               "away or use --overwrite") from None
    except OSError as exc:
        raise ResultsFileError(f"{path}: cannot read: {exc.strerror}") from None
    rows = []
    for line in text.splitlines():
        if not line.strip():
            continue
        try:
            rows.append(json.loads(line))
        except json.JSONDecodeError:
            print(f"swarm-compare: skipping a damaged line in {path}", file=sys.stderr)
    return rows


def _default_run(job: tuple[str, tuple[str, ...], dict, int]) -> dict:
    # lazy: the batch runner loads pybullet and the controllers, which only a run needs
    from swarm_sim.batch import run_one

    return run_one(job)


@dataclass
class SweepResult:
    rows: list[dict[str, Any]]
    """This sweep's rows (old and new), in plan order then seed order."""
    failed: list[dict[str, Any]] = field(default_factory=list)
    """The runs that raised in this sweep: their plan keys, seed and ``error``."""


def run_sweep(
    plans: Sequence[RunPlan],
    seeds: Sequence[int],
    path: Path,
    *,
    executor: Executor | None = None,
    run: RunFunction | None = None,
    resume: bool = False,
    log: Callable[[str], None] = print,
) -> SweepResult:
    """Run every plan for every seed on `executor`, appending each result to `path` as it arrives.

    With `resume`, runs already in `path` (same strategy, settings and seed) are skipped; without
    it `path` must not hold results yet. Failed runs go to ``failed.jsonl`` beside `path` and the
    sweep goes on. An interrupt (KeyboardInterrupt) propagates; every finished run is on disk.
    """
    executor = executor or LocalExecutor(1)
    run = run or _default_run
    old = read_results(path)
    if old and not resume:
        raise FileExistsError(f"{path} already holds {len(old)} runs; use --resume or --overwrite")
    order = {(p.strategy, p.settings): i for i, p in enumerate(plans)}
    done = {(r.get("strategy"), r.get("settings"), r.get("seed")) for r in old}
    rows = [r for r in old if (r.get("strategy"), r.get("settings")) in order]
    todo = [(p, s) for p in plans for s in seeds if (p.strategy, p.settings, s) not in done]
    if resume and old:
        log(f"resume: {len(rows)} runs of this sweep already in {path}, {len(todo)} to go")
    path.parent.mkdir(parents=True, exist_ok=True)
    _end_line(path)
    _end_line(path.parent / FAILED)
    failed: list[dict[str, Any]] = []
    jobs = [(p.strategy, tuple(p.overrides), dict(p.fields), s) for p, s in todo]
    with Progress(len(jobs), f"sweep ({executor.name}, {executor.workers} workers)") as bar:
        for outcome in executor.map(run, jobs):
            plan, seed = todo[outcome.index]
            ours = {"strategy": plan.strategy, "cell": plan.cell, **dict(plan.extra), "settings": plan.settings}
            if outcome.ok:
                row = {**ours, **slim(outcome.value), **ours}  # ours first in the line, and ours win
                _append(path, row)
                rows.append(row)
                bar.write(f"{plan.strategy} cell={plan.cell} seed={row.get('seed')}: delivered "
                          f"{row.get('resources_delivered')}/{row.get('total_resources')}, collision "
                          f"{fmt(row.get('collision_time_per_robot_s'))} s/robot", log)
            else:
                failure = {**ours, "seed": seed, "error": outcome.error}
                _append(path.parent / FAILED, failure)
                failed.append(failure)
                bar.write(f"FAILED {plan.strategy} cell={plan.cell} seed={seed}: {outcome.error}", log)
            bar.update(ok=outcome.ok)
    rows.sort(key=lambda r: (order[(r.get("strategy"), r.get("settings"))], r.get("seed", 0)))
    return SweepResult(rows, failed)


def _end_line(path: Path) -> None:
    """A line cut short by an interrupted write must not swallow the next one."""
    if path.exists() and path.stat().st_size and not path.read_bytes().endswith(b"\n"):
        with path.open("a") as f:
            f.write("\n")


def _append(path: Path, row: dict[str, Any]) -> None:
    with path.open("a") as f:
        f.write(json.dumps(row) + "\n")

"""The resumable sweep: run plans for every seed and append each result to ``results.jsonl`` at once.

An interrupted sweep keeps what it finished and ``--resume`` runs only what is missing. A run is
identified by its strategy (scenario name), its settings (the overrides and fields it was loaded
with) and its seed. The sweep takes its runner as an argument so tests can feed it fake summaries.
"""

from __future__ import annotations

import json
import sys
from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from swarm_sim.compare.report import fmt

Runner = Callable[[str, list[str], dict, list[int], int], Iterable[dict]]
"""`swarm_sim.batch.run_many`'s signature: (scenario, overrides, fields, seeds, jobs) -> summaries."""

RESULTS = "results.jsonl"


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
    """A summary without the per-robot dicts and the per-delivery drop-off list (their means stay)."""
    row = {k: v for k, v in summary.items() if not k.endswith("_by_robot") and k != "dropoff_times_s"}
    if "dropoff_times_s" in summary:
        row["dropoff_count"] = len(summary["dropoff_times_s"])
    return row


def read_results(path: Path) -> list[dict[str, Any]]:
    """Rows of a results file; a line cut short by an interrupted write is skipped."""
    if not path.exists():
        return []
    rows = []
    for line in path.read_text().splitlines():
        if not line.strip():
            continue
        try:
            rows.append(json.loads(line))
        except json.JSONDecodeError:
            print(f"swarm-compare: skipping a damaged line in {path}", file=sys.stderr)
    return rows


def _default_runner(name: str, overrides: list[str], fields: dict, seeds: list[int], jobs: int):
    from swarm_sim.batch import run_many  # heavy (pybullet, controllers): only when running

    return run_many(name, overrides, fields, seeds, jobs)


def run_sweep(
    plans: Sequence[RunPlan],
    seeds: Sequence[int],
    path: Path,
    *,
    jobs: int = 1,
    runner: Runner | None = None,
    resume: bool = False,
    log: Callable[[str], None] = print,
    on_error: Callable[[RunPlan, Exception], None] | None = None,
) -> list[dict[str, Any]]:
    """Run every plan for every seed, appending each result to `path` as it arrives.

    With `resume`, runs already in `path` (same strategy, settings and seed) are skipped; without
    it `path` must not hold results yet. A plan whose runner raises is reported to `on_error` and
    the sweep goes on with the next plan (without `on_error` the exception propagates).
    Returns the rows of these plans (old and new).
    """
    runner = runner or _default_runner
    old = read_results(path)
    if old and not resume:
        raise FileExistsError(f"{path} already holds {len(old)} runs; use --resume or --overwrite")
    keys = {(p.strategy, p.settings) for p in plans}
    done = {(r.get("strategy"), r.get("settings"), r.get("seed")) for r in old}
    rows = [r for r in old if (r.get("strategy"), r.get("settings")) in keys]
    todo = [(p, [s for s in seeds if (p.strategy, p.settings, s) not in done]) for p in plans]
    total = sum(len(s) for _, s in todo)
    if resume and old:
        log(f"resume: {len(rows)} runs of this sweep already in {path}, {total} to go")
    path.parent.mkdir(parents=True, exist_ok=True)
    if path.exists() and path.stat().st_size and not path.read_bytes().endswith(b"\n"):
        with path.open("a") as f:
            f.write("\n")  # a line cut short must not swallow the next one
    start = len(rows)
    for plan, plan_seeds in todo:
        if not plan_seeds:
            continue
        try:
            _run_plan(plan, plan_seeds, path, jobs, runner, rows, start, total, log)
        except Exception as exc:
            if on_error is None:
                raise
            on_error(plan, exc)
    return rows


def _run_plan(plan: RunPlan, seeds: list[int], path: Path, jobs: int, runner: Runner,
              rows: list[dict], start: int, total: int, log: Callable[[str], None]) -> None:
    """Run one plan, appending each row to `path` and to `rows` (which held `start` before the sweep)."""
    results = runner(plan.strategy, list(plan.overrides), dict(plan.fields), list(seeds), jobs)
    for summary in results:
        ours = {"strategy": plan.strategy, "cell": plan.cell, **dict(plan.extra), "settings": plan.settings}
        row = {**ours, **slim(summary), **ours}  # ours first in the line, and ours win
        with path.open("a") as f:
            f.write(json.dumps(row) + "\n")
        rows.append(row)
        log(f"[{len(rows) - start}/{total}] {plan.strategy} cell={plan.cell} seed={row.get('seed')}: "
            f"delivered {row.get('resources_delivered')}/{row.get('total_resources')}, "
            f"collision {fmt(row.get('collision_time_per_robot_s'))} s/robot")

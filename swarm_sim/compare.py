"""Paper comparisons: sweep seeds and settings, then write tables, box plots and tests next to the papers' numbers.

``swarm-compare queue`` reproduces the queue paper's evaluation (Zaman et al.,
queue_depot_traffic.md: Table II, Figs 8-10, independent two-sample t-tests) and
``swarm-compare spiral`` the MDBSA paper's experiments 1-3 (Lu & Luna 2023,
mdbsa_spiral_search.md: Figs 6-10, two-sided Mann-Whitney U tests).

Every finished run is appended to ``results.jsonl`` at once, so an interrupted sweep keeps what
it finished and ``--resume`` runs only what is missing. A run is identified by its strategy
(scenario name), its settings (the overrides and fields it was loaded with) and its seed.
The report functions take plain lists of result dicts, so they work on any results file and
tests feed them synthetic data; the sweep takes its runner as an argument for the same reason.
"""

from __future__ import annotations

import argparse
import json
import math
import sys
import warnings
from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from swarm_sim.cli import scenario_fields

Runner = Callable[[str, list[str], dict, list[int], int], Iterable[dict]]
"""`swarm_sim.batch.run_many`'s signature: (scenario, overrides, fields, seeds, jobs) -> summaries."""

RESULTS = "results.jsonl"

# --------------------------------------------------------------------------- the queue paper

QUEUE_STRATEGIES: tuple[str, ...] = ("queue_cpfa", "queue_qse", "queue_qst", "queue_qme", "queue_qmt")
"""Scenario names of the queue paper's five strategies, in the paper's Table II row order."""
QUEUE_LABELS: dict[str, str] = {
    "queue_cpfa": "CPFA", "queue_qse": "Q_SE", "queue_qst": "Q_ST", "queue_qme": "Q_ME", "queue_qmt": "Q_MT",
}
QUEUE_SIZES: tuple[int, ...] = (48, 64, 80, 96, 112)
"""The paper's swarm sizes (Table I)."""

PAPER_TABLE_II: dict[str, dict[int, float]] = {
    "queue_cpfa": {48: 15.17, 64: 13.33, 80: 12.17, 96: 11.47, 112: 11.39},
    "queue_qse": {48: 17.39, 64: 18.09, 80: 17.36, 96: 16.63, 112: 18.06},
    "queue_qst": {48: 37.98, 64: 38.88, 80: 42.45, 96: 37.44, 112: 34.60},
    "queue_qme": {48: 46.61, 64: 54.29, 80: 59.19, 96: 61.42, 112: 64.22},
    "queue_qmt": {48: 62.94, 64: 71.93, 80: 76.39, 96: 82.31, 112: 82.39},
}
"""THE PAPER'S numbers, not ours: queue paper Table II, "Resource Collection (%)", mean over 50
ARGoS runs of 18 min, 12 x 12 m arena, 320 resources in five 8 x 8 clusters."""
PAPER_QUEUE_QUOTES = (
    "Given a total of 320 available resources, the average number of collected resources "
    "decreases from 49 with 48 robots to 37 with 112 robots. [CPFA]",
    "Among all strategies, Q_MT achieves the best performance, collecting 202 resources with 48 "
    "robots and 264 resources with 112 robots.",
    "As expected, CPFA exhibits the highest collision time (see Fig. 9). [...] Q_SE shows a "
    "notably faster increase in collision time as the number of robots grows.",
    "Among all strategies, Q_SE exhibits the highest resource drop-off time [...] its drop-off "
    "time is even higher than that of CPFA. In contrast, Q_MT consistently achieves the lowest "
    "drop-off time across all experiments (see Fig. 10).",
)

QUEUE_METRICS: dict[str, str] = {
    "resources_collected_pct": "resources collected [%]",
    "collision_time_per_robot_s": "collision time per robot [s]",
    "dropoff_time_mean_s": "drop-off time (per-run mean over deliveries) [s]",
}

# --------------------------------------------------------------------------- the MDBSA paper

SPIRAL_STRATEGIES: tuple[str, ...] = ("ddsa", "mdbsa_c", "mdbsa_d")
SPIRAL_LABELS: dict[str, str] = {"ddsa": "DDSA", "mdbsa_c": "MDBSA-C", "mdbsa_d": "MDBSA-D"}
REGION_FREE: frozenset[str] = frozenset({"ddsa"})
"""Strategies that do not use regions: run once in experiment 1 and shown in every regions
column (the paper: "DDSA's results remained the same as the algorithm does not utilize regions")."""
SPIRAL_PAIRS: tuple[tuple[str, str], ...] = (("ddsa", "mdbsa_c"), ("ddsa", "mdbsa_d"), ("mdbsa_c", "mdbsa_d"))

SPIRAL_METRICS: dict[str, str] = {
    "resources_per_robot": "resources collected per robot",
    "collision_time_per_robot_s": "collision time per robot [s]",
    "foraging_rate_per_min": "foraging rate [resources / min, whole swarm]",
}
SPIRAL_TABLE_EXTRA: dict[str, str] = {"resources_collected_pct": "resources collected [%]"}

POWERLAW_LEVELS = 3
"""`powerlaw` layout: piles of 16 (one 4 x 4), 4 (four 2 x 2) and 1 (sixteen), 48 resources in
piles; the rest of the count is scattered uniformly (see `resource_layout`)."""


@dataclass(frozen=True)
class SpiralExperiment:
    """One of the MDBSA paper's experiments (its Tables I-III); `vary` names the swept setting."""

    number: int
    vary: str
    """`regions`, `robots` or `resources`."""
    values: tuple[int, ...]
    robots: int
    resources: int
    regions: int
    duration_s: float
    figures: str


SPIRAL_EXPERIMENTS: dict[int, SpiralExperiment] = {
    # Table I: 8 x 8 m, 8 robots, 160 resources, regions 4/16/64, 12 min, 100 runs.
    1: SpiralExperiment(1, "regions", (4, 16, 64), 8, 160, 16, 720.0, "Figs 6-7"),
    # Table II: 8 robots ... 32 robots in steps of 6, 200 resources, 16 regions, 16 min.
    2: SpiralExperiment(2, "robots", (8, 14, 20, 26, 32), 8, 200, 16, 960.0, "Figs 8-9"),
    # Table III: 16 robots, 100 ... 300 resources in steps of 50, 16 regions, 12 min.
    3: SpiralExperiment(3, "resources", (100, 150, 200, 250, 300), 16, 200, 16, 720.0, "Fig 10"),
}


@dataclass(frozen=True)
class PaperClaim:
    """A difference the MDBSA paper reports: metric of `b` relative to `a`."""

    experiment: int
    metric: str
    a: str
    b: str
    paper: str
    """The paper's number in short, e.g. "≈ +101 % (average)"."""
    quote: str
    cells: tuple[int, ...] | None = None
    """The cells the claim is about; None: every cell."""
    min_cell: int | None = None
    """Alternatively: every cell >= this."""

    def covers(self, cell: int) -> bool:
        if self.cells is not None:
            return cell in self.cells
        return self.min_cell is None or cell >= self.min_cell


_C, _D = "MDBSA_{Centralized}", "MDBSA_{Distributed}"
_EXP3_COLLECTION_QUOTE = (
    f"As the total number of resources increases, {_D} demonstrates an almost 100% collection rate "
    "on average with a ≈60% to ≈350% improvement in the number of collected resources as the number "
    "of robots increases in comparison to DDSA."
)
PAPER_SPIRAL_CLAIMS: tuple[PaperClaim, ...] = (
    # ---- experiment 1 (Fig. 6, Fig. 7)
    PaperClaim(1, "resources_per_robot", "ddsa", "mdbsa_c", "similar (≈ 0 %)",
               f"When using 4 and 16 regions, {_C} achieved similar performance to DDSA regarding "
               "the number of collected resources.", cells=(4, 16)),
    PaperClaim(1, "resources_per_robot", "ddsa", "mdbsa_c", "≈ −25 %",
               "However, we observed a decrease of approximately 25% in the number of collected "
               "resources using 64 regions. [baseline not stated; compared here with DDSA]", cells=(64,)),
    PaperClaim(1, "resources_per_robot", "ddsa", "mdbsa_d", "≈ +101 % (average)",
               f"On average, {_D} collected around 101% more resources than DDSA and around 112% "
               f"more resources than {_C}."),
    PaperClaim(1, "resources_per_robot", "mdbsa_c", "mdbsa_d", "≈ +112 % (average)",
               f"On average, {_D} collected around 101% more resources than DDSA and around 112% "
               f"more resources than {_C}."),
    PaperClaim(1, "collision_time_per_robot_s", "ddsa", "mdbsa_d", "≈ −33 %",
               f"When using 4 and 64 regions, {_D} has approximately 33% less time in collisions "
               "than DDSA, and around 72% less time when using 16 regions.", cells=(4, 64)),
    PaperClaim(1, "collision_time_per_robot_s", "ddsa", "mdbsa_d", "≈ −72 %",
               f"When using 4 and 64 regions, {_D} has approximately 33% less time in collisions "
               "than DDSA, and around 72% less time when using 16 regions.", cells=(16,)),
    PaperClaim(1, "collision_time_per_robot_s", "ddsa", "mdbsa_c", "> 0, highest, grows with regions",
               f"The collision time in {_C} increased as the number of regions increased, with both "
               "collision time and standard deviation being the highest among all algorithms."),
    PaperClaim(1, "foraging_rate_per_min", "ddsa", "mdbsa_d", "> 0 (Fig. 7 per-minute curves)",
               f"The results show that {_D} outperforms both {_C} and DDSA consistently."),
    PaperClaim(1, "foraging_rate_per_min", "mdbsa_c", "mdbsa_d", "> 0 (Fig. 7 per-minute curves)",
               f"The results show that {_D} outperforms both {_C} and DDSA consistently."),
    # ---- experiment 2 (Fig. 8, Fig. 9)
    PaperClaim(2, "resources_per_robot", "ddsa", "mdbsa_d", "≈ +100 % … +200 %, growing with robots",
               f"Specifically, {_D} outperforms DDSA by ≈100% to ≈200% in terms of the number of "
               "resources collected per robot as the number of robots increases."),
    PaperClaim(2, "resources_per_robot", "ddsa", "mdbsa_c", "≈ −44 %",
               f"On the other hand, {_C} collects ≈44% fewer resources than DDSA as the number of "
               "robots increases from 14 to 32.", min_cell=14),
    PaperClaim(2, "collision_time_per_robot_s", "ddsa", "mdbsa_d", "≈ −21 % … −58 %",
               f"As the number of robots increases, {_D} spends the least amount of time in "
               "collisions, achieving ≈21% to ≈58% less collision time than DDSA."),
    PaperClaim(2, "collision_time_per_robot_s", "ddsa", "mdbsa_c", "> 0, rising sharply with robots",
               f"Increasing the number of robots has a significant effect on the collision times for "
               f"{_C}, with the collision time increasing sharply compared to DDSA."),
    PaperClaim(2, "foraging_rate_per_min", "ddsa", "mdbsa_c", "≈ −24 % (Fig. 9)",
               f"In simulations with 16 or more robots, robots collect ≈24% fewer resources than DDSA "
               f"in {_C}.", min_cell=16),
    # ---- experiment 3 (Fig. 10)
    PaperClaim(3, "resources_per_robot", "ddsa", "mdbsa_c", "≈ −30.4 %",
               f"Lastly, Fig. 10 displays the results for Experiment 3. {_C} collects ≈30.4% fewer "
               "resources than DDSA."),
    PaperClaim(3, "resources_per_robot", "ddsa", "mdbsa_d", "≈ +60 % … +350 %", _EXP3_COLLECTION_QUOTE),
    PaperClaim(3, "collision_time_per_robot_s", "ddsa", "mdbsa_c", "> 0 (highest of the three)",
               f"{_C} displays an upward trend with decreasing momentum in the collision time as the "
               "number of resources increases. It contains the highest collision time per bot in "
               "comparison to the others."),
)
"""THE PAPER'S reported differences (quoted from mdbsa_spiral_search.md, Sec. VI), not ours."""


# --------------------------------------------------------------------------- run plans and the sweep


def _freeze(fields: dict[str, Any]) -> tuple[tuple[str, Any], ...]:
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
            f"collision {_fmt(row.get('collision_time_per_robot_s'))} s/robot")


def queue_plans(
    sizes: Sequence[int],
    strategies: Sequence[str] = QUEUE_STRATEGIES,
    *,
    duration: float | None = None,
    overrides: Sequence[str] = (),
) -> list[RunPlan]:
    """Every strategy at every swarm size (sizes outer, so a cut sweep has whole columns)."""
    plans = []
    for n in sizes:
        fields = scenario_fields(argparse.Namespace(robots=n, duration=duration))
        plans.extend(RunPlan(s, n, tuple(overrides), _freeze(fields)) for s in strategies)
    return plans


def resource_layout(count: int, layout: str = "powerlaw") -> tuple[str, ...]:
    """``--set`` overrides placing `count` resources in "clusters of different sizes".

    The MDBSA paper only says "randomly distributed [...] as clusters of various sizes".
    `powerlaw` (default): Hecker & Moses piles with `POWERLAW_LEVELS` = 3 (one pile of 16, four of
    4, sixteen of 1; 48 resources) and the rest scattered uniformly; the same piles for every
    count, so more resources means a closer-to-random layout, which is how the paper reads its
    experiment 3 ("the distribution of resources became closer to random"). Level 4 would need
    256 resources, more than most counts in the paper. `clustered`: equal square clusters with
    clusters * side^2 == count, the largest side of 5, 4, 3, 2, 1 that divides (5 x 5 for
    100-300 in steps of 50, ten 4 x 4 for 160): every resource in a cluster, but one size.
    """
    if layout == "powerlaw":
        return ("resources.distribution=powerlaw", f"resources.powerlaw_levels={POWERLAW_LEVELS}",
                f"resources.count={count}")
    if layout == "clustered":
        side = next(s for s in (5, 4, 3, 2, 1) if count % (s * s) == 0)
        return ("resources.distribution=clustered", f"resources.clusters={count // (side * side)}",
                f"resources.cluster_side={side}", f"resources.count={count}")
    raise ValueError(f"unknown resource layout {layout!r} (powerlaw or clustered)")


def spiral_plans(
    experiment: int,
    strategies: Sequence[str] = SPIRAL_STRATEGIES,
    *,
    values: Sequence[int] | None = None,
    layout: str = "powerlaw",
    duration: float | None = None,
    overrides: Sequence[str] = (),
) -> list[RunPlan]:
    """The paper's settings for `experiment` as overrides, one plan per strategy and cell."""
    exp = SPIRAL_EXPERIMENTS[experiment]
    extra = (("experiment", experiment), ("layout", layout))
    fields = _freeze({"sim__duration": duration})
    plans = []
    for value in values or exp.values:
        setting = {"robots": exp.robots, "resources": exp.resources, "regions": exp.regions, exp.vary: value}
        base = (
            f"robots.count={setting['robots']}",
            f"regions.count={setting['regions']}",
            f"sim.duration={exp.duration_s}",
            *resource_layout(setting["resources"], layout),
        )
        for s in strategies:
            if exp.vary == "regions" and s in REGION_FREE:
                continue
            plans.append(RunPlan(s, value, (*base, *overrides), fields, extra))
    if exp.vary == "regions":  # region-free strategies once, at the experiment's default regions
        base = (f"robots.count={exp.robots}", f"sim.duration={exp.duration_s}",
                *resource_layout(exp.resources, layout))
        plans.extend(RunPlan(s, None, (*base, *overrides), fields, extra)
                     for s in strategies if s in REGION_FREE)
    return plans


# --------------------------------------------------------------------------- statistics


@dataclass(frozen=True)
class Stats:
    n: int
    mean: float
    std: float
    """Sample standard deviation (ddof 1); nan below two values."""
    median: float


def describe(values: Sequence[float]) -> Stats:
    a = np.asarray(values, dtype=float)
    if a.size == 0:
        return Stats(0, math.nan, math.nan, math.nan)
    return Stats(a.size, float(a.mean()), float(a.std(ddof=1)) if a.size > 1 else math.nan, float(np.median(a)))


def values_of(rows: Iterable[dict], strategy: str, cell: int, metric: str) -> list[float]:
    """`metric` of `strategy`'s runs in `cell` (rows with cell None serve every cell); runs
    without a value (no delivery, so no drop-off time) are left out."""
    return [
        float(r[metric]) for r in rows
        if r.get("strategy") == strategy and r.get("cell") in (cell, None) and r.get(metric) is not None
    ]


def cells_of(rows: Iterable[dict]) -> list[int]:
    return sorted({r["cell"] for r in rows if r.get("cell") is not None})


def stars(p: float, ns: str = "ns") -> str:
    """Significance stars as in both papers: *** p<0.001, ** p<0.01, * p<0.05, else `ns`."""
    if p is None or not math.isfinite(p):
        return "n/a"
    return "***" if p < 0.001 else "**" if p < 0.01 else "*" if p < 0.05 else ns


@dataclass(frozen=True)
class PairTest:
    metric: str
    cell: int
    a: str
    b: str
    stats_a: Stats
    stats_b: Stats
    statistic: float
    p: float
    """nan when a group has fewer than two values (t) or none (U), or both are constant and equal."""


def pair_test(a: Sequence[float], b: Sequence[float], test: str) -> tuple[float, float]:
    """(statistic, p): `t` = scipy ttest_ind (the queue paper's), `u` = two-sided mannwhitneyu
    (the MDBSA paper's)."""
    from scipy import stats as st

    if (test == "t" and min(len(a), len(b)) < 2) or min(len(a), len(b)) < 1:
        return math.nan, math.nan
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)
        if test == "t":
            r = st.ttest_ind(a, b)
        elif test == "u":
            r = st.mannwhitneyu(a, b, alternative="two-sided")
        else:
            raise ValueError(f"unknown test {test!r}")
    return float(r.statistic), float(r.pvalue)


def pairwise_tests(
    rows: Sequence[dict],
    metric: str,
    cells: Sequence[int],
    pairs: Sequence[tuple[str, str]],
    test: str,
) -> list[PairTest]:
    out = []
    for cell in cells:
        for a, b in pairs:
            va, vb = values_of(rows, a, cell, metric), values_of(rows, b, cell, metric)
            statistic, p = pair_test(va, vb, test)
            out.append(PairTest(metric, cell, a, b, describe(va), describe(vb), statistic, p))
    return out


def all_pairs(strategies: Sequence[str]) -> list[tuple[str, str]]:
    return [(a, b) for i, a in enumerate(strategies) for b in strategies[i + 1:]]


def pct_change(a: float, b: float) -> float:
    """100 (b - a) / a; nan when a is 0 or missing."""
    return 100.0 * (b - a) / a if a and math.isfinite(a) and math.isfinite(b) else math.nan


# --------------------------------------------------------------------------- formatting


def _fmt(x: Any, digits: int = 2) -> str:
    if x is None or (isinstance(x, float) and not math.isfinite(x)):
        return "—"
    return f"{x:.{digits}f}"


def _fmt_p(p: float) -> str:
    if not math.isfinite(p):
        return "n/a"
    return f"{p:.2e}" if p < 0.001 else f"{p:.4f}"


def _fmt_pct(x: float) -> str:
    return "—" if not math.isfinite(x) else f"{x:+.1f} %"


def cell_text(s: Stats, digits: int = 2, median: bool = False) -> str:
    """``mean ± std (n=…)``, with the median when asked; ``—`` without data."""
    if s.n == 0:
        return "—"
    text = f"{_fmt(s.mean, digits)} ± {_fmt(s.std, digits)}"
    return f"{text} (median {_fmt(s.median, digits)}, n={s.n})" if median else f"{text} (n={s.n})"


def _table(header: Sequence[str], body: Iterable[Sequence[str]]) -> list[str]:
    lines = ["| " + " | ".join(header) + " |", "|" + "|".join("---" for _ in header) + "|"]
    lines += ["| " + " | ".join(row) + " |" for row in body]
    return lines


def _label(strategy: str, labels: dict[str, str]) -> str:
    return labels.get(strategy, strategy)


# --------------------------------------------------------------------------- box plots


def grouped_boxplot(
    ax: Any,
    rows: Sequence[dict],
    metric: str,
    cells: Sequence[int],
    strategies: Sequence[str],
    labels: dict[str, str],
    *,
    notch: bool = False,
) -> None:
    """Boxes grouped by cell (x axis), one colour per strategy, as in both papers' figures."""
    from matplotlib.patches import Patch

    colours = [f"C{i}" for i in range(len(strategies))]
    width = 0.8 / max(len(strategies), 1)
    for j, (s, colour) in enumerate(zip(strategies, colours)):
        data, pos = [], []
        for i, cell in enumerate(cells):
            v = values_of(rows, s, cell, metric)
            if v:
                data.append(v)
                pos.append(i - 0.4 + width * (j + 0.5))
        if data:
            box = ax.boxplot(data, positions=pos, widths=width * 0.85, notch=notch, patch_artist=True,
                             manage_ticks=False, flierprops={"markersize": 3},
                             medianprops={"color": "black"})
            for patch in box["boxes"]:
                patch.set(facecolor=colour, alpha=0.6)
    ax.set_xticks(range(len(cells)), [str(c) for c in cells])
    ax.set_xlim(-0.6, len(cells) - 0.4)
    ax.legend(handles=[Patch(facecolor=c, alpha=0.6, label=_label(s, labels)) for s, c in zip(strategies, colours)],
              fontsize="small")
    ax.grid(axis="y", alpha=0.3)


def _figure(panels: Sequence[tuple[str, str]], rows, cells, strategies, labels, xlabel, title, path,
            notch=False) -> Path:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, len(panels), figsize=(6.5 * len(panels), 4.5), squeeze=False)
    for ax, (metric, ylabel) in zip(axes[0], panels):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")  # notches wider than the box with few runs
            grouped_boxplot(ax, rows, metric, cells, strategies, labels, notch=notch)
        ax.set(xlabel=xlabel, ylabel=ylabel)
    fig.suptitle(title)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path


# --------------------------------------------------------------------------- queue report


def queue_table_md(rows: Sequence[dict], sizes: Sequence[int], strategies: Sequence[str]) -> str:
    """table.md: Table II layout (ours next to the paper's), then collision and drop-off times."""
    lines = ["# Queue paper comparison (Zaman et al.): tables", ""]
    n_runs = sorted({describe(values_of(rows, s, c, "resources_collected_pct")).n for s in strategies for c in sizes})
    lines += [f"Runs per cell: {', '.join(map(str, n_runs))} (the paper: 50). Cells: mean ± sample std (n).", ""]
    lines += ["## Resource collection [%] (Table II layout)", "",
              "`ours` = this simulator; `paper` = **the paper's Table II** (ARGoS, 50 runs), hard-coded "
              "reference data.", ""]
    header = ["Algorithm"] + [f"{c} {w}" for c in sizes for w in ("ours", "paper")]
    body = []
    for s in strategies:
        row = [_label(s, QUEUE_LABELS)]
        for c in sizes:
            row.append(cell_text(describe(values_of(rows, s, c, "resources_collected_pct"))))
            row.append(_fmt(PAPER_TABLE_II.get(s, {}).get(c)))
        body.append(row)
    lines += _table(header, body) + [""]
    lines += ["### The paper's Table II (reference, not our data)", ""]
    lines += _table(["Algorithm"] + [str(c) for c in QUEUE_SIZES],
                    [[_label(s, QUEUE_LABELS)] + [_fmt(PAPER_TABLE_II[s][c]) for c in QUEUE_SIZES]
                     for s in QUEUE_STRATEGIES]) + [""]
    lines += ["The paper's text (quoted):", ""] + [f"> {q}" for q in PAPER_QUEUE_QUOTES] + [""]
    for metric, title in (("collision_time_per_robot_s", "Collision time per robot [s] (Fig. 9)"),
                          ("dropoff_time_mean_s", "Resource drop-off time [s] (Fig. 10)")):
        lines += [f"## {title}", ""]
        if metric == "dropoff_time_mean_s":
            lines += ["Per run: the mean over its deliveries of the time from entering the perimeter "
                      "to the drop; runs without a delivery are left out of n.", ""]
        else:
            lines += ["The paper plots this in minutes without a table; ours in seconds.", ""]
        lines += _table(["Algorithm"] + [str(c) for c in sizes],
                        [[_label(s, QUEUE_LABELS)] + [cell_text(describe(values_of(rows, s, c, metric)))
                                                      for c in sizes] for s in strategies]) + [""]
    return "\n".join(lines)


def ordering(rows: Sequence[dict], cell: int, strategies: Sequence[str], metric: str) -> list[str]:
    """Strategies with data in `cell`, ascending by mean `metric`."""
    means = {s: describe(values_of(rows, s, cell, metric)).mean for s in strategies}
    return sorted((s for s in strategies if math.isfinite(means[s])), key=lambda s: means[s])


def queue_ttests_md(rows: Sequence[dict], sizes: Sequence[int], strategies: Sequence[str]) -> str:
    """ttests.md: scipy ttest_ind (equal variances, as its default) for every pair and size, and
    the ordering of the strategies by mean collection against the paper's."""
    from scipy.stats import kendalltau

    lines = ["# Queue paper comparison: independent two-sample t-tests", "",
             "scipy.stats.ttest_ind (default: equal variances, two-sided), as the paper. "
             "Stars: *** p<0.001, ** p<0.01, * p<0.05, ns otherwise; n/a: fewer than two runs "
             "or no variance.", ""]
    pairs = all_pairs(strategies)
    for metric, title in QUEUE_METRICS.items():
        lines += [f"## {title}", ""]
        for cell in sizes:
            lines += [f"### {cell} robots", ""]
            body = [[_label(t.a, QUEUE_LABELS), _label(t.b, QUEUE_LABELS), cell_text(t.stats_a),
                     cell_text(t.stats_b), _fmt(t.statistic, 3), _fmt_p(t.p), stars(t.p)]
                    for t in pairwise_tests(rows, metric, [cell], pairs, "t")]
            lines += _table(["A", "B", "A mean ± std", "B mean ± std", "t", "p", "sig"], body) + [""]
    lines += ["## ordering", "",
              "Strategies ascending by mean resources collected [%]: ours vs the paper's Table II. "
              "Kendall's tau over the strategies both have.", ""]
    body = []
    for cell in sizes:
        ours = ordering(rows, cell, strategies, "resources_collected_pct")
        paper = sorted((s for s in strategies if cell in PAPER_TABLE_II.get(s, {})),
                       key=lambda s: PAPER_TABLE_II[s][cell])
        common = [s for s in ours if s in paper]
        if len(common) >= 2:
            tau = kendalltau([ours.index(s) for s in common], [paper.index(s) for s in common]).statistic
            same = "yes" if [s for s in ours if s in paper] == [s for s in paper if s in ours] else "no"
        else:
            tau, same = math.nan, "—"
        body.append([str(cell), " < ".join(_label(s, QUEUE_LABELS) for s in ours) or "—",
                     " < ".join(_label(s, QUEUE_LABELS) for s in paper) or "— (size not in the paper)",
                     same, _fmt(tau)])
    lines += _table(["robots", "ours", "paper", "same order", "Kendall tau"], body) + [""]
    return "\n".join(lines)


def write_queue_report(rows: Sequence[dict], out: Path, sizes: Sequence[int] | None = None,
                       strategies: Sequence[str] = QUEUE_STRATEGIES) -> list[Path]:
    """table.md, ttests.md and the Fig. 8-10 box plots from result rows."""
    sizes = list(sizes or cells_of(rows))
    out.mkdir(parents=True, exist_ok=True)
    written = [out / "table.md", out / "ttests.md"]
    written[0].write_text(queue_table_md(rows, sizes, strategies))
    written[1].write_text(queue_ttests_md(rows, sizes, strategies))
    for name, metric, fig in (("collected.png", "resources_collected_pct", "Fig. 8"),
                              ("collision_time.png", "collision_time_per_robot_s", "Fig. 9"),
                              ("dropoff_time.png", "dropoff_time_mean_s", "Fig. 10")):
        written.append(_figure([(metric, QUEUE_METRICS[metric])], rows, sizes, strategies, QUEUE_LABELS,
                               "number of robots", f"{QUEUE_METRICS[metric]} (cf. queue paper {fig})",
                               out / name))
    return written


# --------------------------------------------------------------------------- spiral report


def spiral_tables_md(rows: Sequence[dict], experiment: int, cells: Sequence[int],
                     strategies: Sequence[str]) -> str:
    exp = SPIRAL_EXPERIMENTS[experiment]
    lines = [f"# MDBSA paper comparison (Lu & Luna 2023): experiment {experiment} ({exp.figures})", "",
             f"Swept: {exp.vary} = {', '.join(map(str, cells))}. Cells: mean ± sample std "
             "(median, n). The paper gives no tables (box plots of 100 runs only).", ""]
    layouts = sorted({str(r.get("layout")) for r in rows})
    lines += [f"Resource layout: {', '.join(layouts)} (see `swarm_sim.compare.resource_layout`).", ""]
    if exp.vary == "regions":
        lines += ["DDSA does not use regions: the same DDSA runs appear in every column.", ""]
    for metric, title in {**SPIRAL_METRICS, **SPIRAL_TABLE_EXTRA}.items():
        lines += [f"## {title}", ""]
        lines += _table([f"Algorithm \\ {exp.vary}"] + [str(c) for c in cells],
                        [[_label(s, SPIRAL_LABELS)] + [cell_text(describe(values_of(rows, s, c, metric)), median=True)
                                                       for c in cells] for s in strategies]) + [""]
    if experiment == 3:
        lines += [f"> {_EXP3_COLLECTION_QUOTE} (the paper, Fig. 10: compare MDBSA-D's collected %)", ""]
    lines += ["Figs 7 and 9 of the paper plot per-minute curves; our summaries hold only the whole-run "
              "rate (deliveries / run minutes), so `foraging_rate.png` shows that scalar.", ""]
    return "\n".join(lines)


def spiral_mannwhitney_md(rows: Sequence[dict], experiment: int, cells: Sequence[int],
                          strategies: Sequence[str]) -> str:
    exp = SPIRAL_EXPERIMENTS[experiment]
    claims = [c for c in PAPER_SPIRAL_CLAIMS if c.experiment == experiment]
    pairs = [(a, b) for a, b in SPIRAL_PAIRS if a in strategies and b in strategies]
    lines = [f"# MDBSA paper comparison: Mann-Whitney U, experiment {experiment}", "",
             "scipy.stats.mannwhitneyu, two-sided, between each pair per cell. Marks as in the paper: "
             "*** p<0.001, ** p<0.01, * p<0.05, - otherwise (n/a: a group is empty). "
             "`diff` = 100 (mean B − mean A) / mean A. `paper` = what **the paper** reports for that "
             "pair and cell (quotes below), not our data.", ""]
    if experiment == 3:
        lines += ["(The paper ran its tests for experiments 1 and 2 only.)", ""]
    for metric, title in SPIRAL_METRICS.items():
        lines += [f"## {title}", ""]
        body = []
        for t in pairwise_tests(rows, metric, cells, pairs, "u"):
            paper = "; ".join(c.paper for c in claims
                              if c.metric == metric and (c.a, c.b) == (t.a, t.b) and c.covers(t.cell))
            body.append([str(t.cell), _label(t.a, SPIRAL_LABELS), _label(t.b, SPIRAL_LABELS),
                         _fmt(t.stats_a.median), _fmt(t.stats_b.median),
                         _fmt_pct(pct_change(t.stats_a.mean, t.stats_b.mean)),
                         _fmt(t.statistic, 1), _fmt_p(t.p), stars(t.p, ns="-"), paper or ""])
        lines += _table([exp.vary, "A", "B", "median A", "median B", "diff", "U", "p", "sig", "paper"], body)
        lines += [""]
    lines += ["## The paper's reported differences, and ours", ""]
    for c in claims:
        covered = [cell for cell in cells if c.covers(cell)]
        ours = []
        for cell in covered:
            a = describe(values_of(rows, c.a, cell, c.metric)).mean
            b = describe(values_of(rows, c.b, cell, c.metric)).mean
            ours.append(pct_change(a, b))
        finite = [x for x in ours if math.isfinite(x)]
        per_cell = ", ".join(f"{cell}: {_fmt_pct(x)}" for cell, x in zip(covered, ours)) or "no cell covered"
        avg = f"; mean over these cells {_fmt_pct(float(np.mean(finite)))}" if len(finite) > 1 else ""
        lines += [f"- **{SPIRAL_METRICS.get(c.metric, c.metric)}, {_label(c.b, SPIRAL_LABELS)} vs "
                  f"{_label(c.a, SPIRAL_LABELS)}** — paper: {c.paper}; ours ({exp.vary}) {per_cell}{avg}.",
                  f"  > {c.quote}"]
    lines += [""]
    return "\n".join(lines)


def write_spiral_report(rows: Sequence[dict], out: Path, experiment: int, cells: Sequence[int] | None = None,
                        strategies: Sequence[str] = SPIRAL_STRATEGIES) -> list[Path]:
    """tables.md, mannwhitney.md and the Fig. 6-10 style box plots from result rows."""
    exp = SPIRAL_EXPERIMENTS[experiment]
    cells = list(cells or cells_of(rows))
    out.mkdir(parents=True, exist_ok=True)
    written = [out / "tables.md", out / "mannwhitney.md"]
    written[0].write_text(spiral_tables_md(rows, experiment, cells, strategies))
    written[1].write_text(spiral_mannwhitney_md(rows, experiment, cells, strategies))
    xlabel = f"number of {exp.vary}"
    panels = [(m, SPIRAL_METRICS[m]) for m in ("resources_per_robot", "collision_time_per_robot_s")]
    fig = {1: "Fig. 6", 2: "Fig. 8", 3: "Fig. 10"}[experiment]
    written.append(_figure(panels, rows, cells, strategies, SPIRAL_LABELS, xlabel,
                           f"Experiment {experiment} (cf. MDBSA paper {fig})", out / "resources_collision.png",
                           notch=True))
    written.append(_figure([("foraging_rate_per_min", SPIRAL_METRICS["foraging_rate_per_min"])], rows, cells,
                           strategies, SPIRAL_LABELS, xlabel, f"Experiment {experiment}: whole-run foraging rate",
                           out / "foraging_rate.png", notch=True))
    return written


# --------------------------------------------------------------------------- CLI


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


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog="swarm-compare", description=__doc__.splitlines()[0])
    sub = parser.add_subparsers(dest="command", required=True)
    q = sub.add_parser("queue", help="queue paper: Table II, Figs 8-10, t-tests")
    q.add_argument("--robots", type=int, nargs="+", default=list(QUEUE_SIZES),
                   help=f"swarm sizes (default: the paper's {' '.join(map(str, QUEUE_SIZES))})")
    _common(q, "results/queue")
    s = sub.add_parser("spiral", help="MDBSA paper: experiments 1-3, Figs 6-10, Mann-Whitney U")
    s.add_argument("--experiment", type=int, choices=sorted(SPIRAL_EXPERIMENTS), required=True)
    s.add_argument("--values", type=int, nargs="+",
                   help="the swept setting's values (default: the paper's; regions, robots or resources)")
    s.add_argument("--layout", choices=("powerlaw", "clustered"), default="powerlaw",
                   help="resource layout for 'clusters of different sizes' (default powerlaw)")
    _common(s, "results/spiral")
    return parser


def main(argv: list[str] | None = None, runner: Runner | None = None) -> int:
    """`runner` replaces `run_many` (tests); with the real runner every scenario is loaded first."""
    parser = build_parser()
    args = parser.parse_args(argv)
    if args.command == "queue":
        strategies = _strategies(args.strategies, QUEUE_STRATEGIES, parser)
        plans = queue_plans(args.robots, strategies, duration=args.duration, overrides=args.overrides)
        out = args.out
    else:
        strategies = _strategies(args.strategies, SPIRAL_STRATEGIES, parser)
        plans = spiral_plans(args.experiment, strategies, values=args.values, layout=args.layout,
                             duration=args.duration, overrides=args.overrides)
        out = args.out / f"exp{args.experiment}"
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
    if args.command == "queue":
        written = write_queue_report(rows, out, args.robots, strategies)
    else:
        exp = SPIRAL_EXPERIMENTS[args.experiment]
        written = write_spiral_report(rows, out, args.experiment, args.values or exp.values, strategies)
    print(f"{len(rows)} runs in {path}; wrote {', '.join(p.name for p in written)} in {out}")
    if failed:
        print(f"swarm-compare: {len(failed)} plans failed: {', '.join(failed)}", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())

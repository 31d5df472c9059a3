"""Statistics over result rows: per-cell summaries, the papers' pair tests and their stars."""

from __future__ import annotations

import math
import warnings
from collections.abc import Iterable, Sequence
from dataclasses import dataclass

import numpy as np


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


def mean_series(rows: Sequence[dict], strategy: str, cell: int, key: str) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(t [s], mean, std) of a time series field ([[t, value], ...]) over `strategy`'s runs in
    `cell` (rows with cell None serve every cell), on the times every run has."""
    series = [r[key] for r in rows
              if r.get("strategy") == strategy and r.get("cell") in (cell, None) and r.get(key)]
    if not series:
        return np.zeros(0), np.zeros(0), np.zeros(0)
    n = min(len(s) for s in series)
    values = np.array([[v for _, v in s[:n]] for s in series], dtype=float)
    times = np.array([t for t, _ in series[0][:n]], dtype=float)
    return times, values.mean(axis=0), values.std(axis=0, ddof=1) if len(series) > 1 else np.zeros(n)


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
    (the MDBSA paper's); NaN for both where the test is undefined (too few runs, or a t-test
    between two groups that do not vary), which the reports print as ``n/a``."""
    from scipy import stats as st

    if (test == "t" and min(len(a), len(b)) < 2) or min(len(a), len(b)) < 1:
        return math.nan, math.nan
    if test == "t" and max(a) == min(a) and max(b) == min(b):
        return math.nan, math.nan  # no variance in either group: t is undefined (scipy says p = 0)
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


def ordering(rows: Sequence[dict], cell: int, strategies: Sequence[str], metric: str) -> list[str]:
    """Strategies with data in `cell`, ascending by mean `metric`."""
    means = {s: describe(values_of(rows, s, cell, metric)).mean for s in strategies}
    return sorted((s for s in strategies if math.isfinite(means[s])), key=lambda s: means[s])

"""Claims as data and one verdict scale for every paper: what a reviewer would sign.

A paper's package declares its results as `Claim` records (`Comparison.claims`): a *level* (a
table cell or a number in the text: the paper's value of one measure for one strategy in one
cell), a *relation* (B against A, with the paper's stated size or range, in per cent of A) or a
*trend* (one strategy from the first to the last of its cells, in per cent of the first). This
module judges every claim the same way and names no paper.

The scale (`VERDICTS`), cell by cell:

- *holds*: the direction is right, the difference is significant and the size lies within the band;
- *direction only*: right and significant, the size outside the band;
- *not shown*: not significant; `CellVerdict.seeds` says how many runs per group a power
  calculation (two-sided, `ALPHA`, `POWER`, our spread) says would show the paper's effect (a
  level: would put the interval on one side of the band's nearer edge at our mean);
- *contradicts*: significant the other way;
- *n/a*: our runs cannot be tested (fewer than two runs of a group), with the reason.

A level has no direction: it *holds* when its 95 % interval lies within the band (equivalence,
two one-sided t-tests), *contradicts* when the interval lies wholly outside it (significantly off
the paper's number by more than the band), and is *not shown* in between. A "no difference"
relation (`Claim.sign` 0) holds when the difference is not significant and its 95 % interval lies
within the band, contradicts when it is significant. A claim over several cells takes its worst
cell (`SEVERITY`); a pooled claim ("on average") pools the runs of its cells first.

The band: the paper's own spread where it prints one (`Claim.band`), else ±`LEVEL_BAND` of a
level's value or of a relation's stated size; the paper's stated range for a relation.

The test is one for every claim: Welch's two-sample t-test, two-sided (for a level: the one-sample
t-test of our runs against the band's edges). Welch because every claim is about means (the papers
print means, and the sizes are ratios of means), it does not assume the equal spreads our
strategies do not have (a jammed baseline beside a flowing one), and its power has a closed form; a rank
test would judge a different quantity (stochastic order) from the size it is paired with. All the
p-values of one paper on one robot model are corrected together with Holm's step-down method
(`holm`). Every effect comes with a 95 % interval: a level's from the t distribution, a relation's
from a percentile bootstrap (`BOOTSTRAP` resamples, seeded from the claim's id: same runs, same
interval).

A claim that does not hold names its cause (`Cause`) with a grade: *measured* (one factor switched
alone, at least `MEASURED_SEEDS` seeds, the gap closes by at least half or the verdict flips; the
numbers in FACTORS.md), *partial* or *open*. A claim without one reads *open*.
"""

from __future__ import annotations

import math
import zlib
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass, field, replace

import numpy as np

HOLDS, DIRECTION, NOT_SHOWN, CONTRADICTS, NA = "holds", "direction only", "not shown", "contradicts", "n/a"
VERDICTS: tuple[str, ...] = (HOLDS, DIRECTION, NOT_SHOWN, CONTRADICTS, NA)
SEVERITY: tuple[str, ...] = (CONTRADICTS, NOT_SHOWN, DIRECTION, HOLDS)
"""Worst first: a claim over several cells takes the first of these any of its cells has."""
LEVEL, RELATION, TREND = "level", "relation", "trend"
KINDS: tuple[str, ...] = (LEVEL, RELATION, TREND)

ALPHA = 0.05
POWER = 0.8
LEVEL_BAND = 0.25
"""The band of a level (and of a relation's single stated size) without a printed spread: ±25 %."""
BOOTSTRAP = 2000
MEASURED_SEEDS = 10

MEASURED, CODE, PARTIAL, OPEN = "measured", "code", "partial", "open"
GRADES: dict[str, str] = {MEASURED: "one factor, measured", CODE: "the authors' code too", PARTIAL: "partial",
                          OPEN: "open"}


@dataclass(frozen=True)
class Cause:
    """Why a claim does not hold, graded. *measured* needs the factor switched alone, its seeds
    (at least `MEASURED_SEEDS`) and where FACTORS.md gives the numbers; *code*: the authors' own
    code, run here (``results/reference/<paper>``, at least `MEASURED_SEEDS` runs a cell), misses
    the claim too, which the report checks against their runs' verdict."""

    grade: str
    text: str
    factor: str = ""
    """The factor sweep (``results/factors/<group>/<factor>``) that measured it; *code*: the
    reference runs (``results/reference/<paper>``)."""
    seeds: int = 0

    def __post_init__(self) -> None:
        if self.grade not in GRADES:
            raise ValueError(f"cause grade {self.grade!r}: must be one of {', '.join(GRADES)}")
        if self.grade in (MEASURED, CODE) and (self.seeds < MEASURED_SEEDS or not self.factor):
            raise ValueError(f"a {GRADES[self.grade]} cause needs its runs and at least {MEASURED_SEEDS} seeds "
                             f"(got {self.factor!r}, {self.seeds})")


@dataclass(frozen=True)
class Claim:
    """One number or stated relation of a paper's results."""

    id: str
    """Unique within the paper, stable (the bootstrap's seed)."""
    kind: str
    text: str
    """The claim in the paper's words, short."""
    where: str
    """Where it stands in the paper (table, figure, section)."""
    measure: str
    """The result rows' field."""
    a: str
    """Strategy (level, trend) or the baseline A (relation)."""
    cells: tuple = (None,)
    """The cells the claim covers (a trend: its first and last)."""
    b: str = ""
    """Relation: the strategy compared with A."""
    value: float | None = None
    """Level: the paper's number, in the measure's unit times `scale`."""
    size: float | None = None
    """Relation, trend: the paper's single stated size [% of A]."""
    sizes: tuple[tuple[object, float], ...] = ()
    """Relation: the paper's size cell by cell [% of A] (a table's numbers), where it has one."""
    band: tuple[float, float] | None = None
    """The paper's own spread (level) or stated range [%] (relation, trend); else from
    `value` / `size` / `sizes` and `LEVEL_BAND`; a "no difference" claim without one:
    ±`LEVEL_BAND`; a direction without a stated size: any size that way."""
    sign: int = 1
    """Relation, trend: +1 B above A, -1 below, 0 no difference."""
    pooled: bool = False
    """The runs of all `cells` pooled ("on average") instead of cell by cell."""
    scale: float = 1.0
    """Factor from the rows' unit to the paper's."""
    unit: str = ""
    causes: tuple[tuple[str, Cause], ...] = ()
    """(robot model, cause) for the models on which it does not hold; model ``*``: any."""
    note: str = ""
    code_measure: str = ""
    """The rows' field holding `measure` as the authors' code counts it, where that count is not
    ours (a collision rule of their controller): the claim is put to their runs, and ours against
    them, on this field (`swarm_sim.compare.reference`); empty: `measure`."""

    def __post_init__(self) -> None:
        if self.kind not in KINDS:
            raise ValueError(f"claim {self.id}: kind {self.kind!r} must be one of {', '.join(KINDS)}")
        if self.kind == LEVEL and self.value is None and self.band is None:
            raise ValueError(f"claim {self.id}: a level needs the paper's value or band")
        if self.kind == RELATION and not self.b:
            raise ValueError(f"claim {self.id}: a relation needs B")
        if self.kind == TREND and len(self.cells) < 2:
            raise ValueError(f"claim {self.id}: a trend needs its first and last cell")
        if self.kind != LEVEL and self.sign not in (-1, 0, 1):
            raise ValueError(f"claim {self.id}: sign must be -1, 0 or 1")
        if self.kind != LEVEL and self.sign != 0 and self.size is not None and self.size * self.sign <= 0:
            raise ValueError(f"claim {self.id}: size {self.size} against its sign {self.sign}")

    def limits(self, cell: object = None) -> tuple[float, float]:
        """The band (in `cell`): the paper's spread or range, else ±`LEVEL_BAND` of its value or size."""
        if self.band is not None:
            return (min(self.band), max(self.band))
        centre = self.value if self.kind == LEVEL else dict(self.sizes).get(cell, self.size)
        if self.kind != LEVEL and self.sign == 0:
            half = 100.0 * LEVEL_BAND if centre is None else abs(centre)
            return (-half, half)
        if centre is None:  # a direction without a stated size
            return (0.0, math.inf) if self.sign > 0 else (-math.inf, 0.0)
        half = abs(centre) * LEVEL_BAND
        return (centre - half, centre + half)

    @property
    def stated(self) -> bool:
        """Whether the paper states a size (else only a direction)."""
        return self.kind == LEVEL or self.band is not None or self.size is not None or bool(self.sizes)

    def cause(self, model: str) -> Cause | None:
        return dict(self.causes).get(model) or dict(self.causes).get("*")

    def paper_text(self) -> str:
        lo, hi = self.limits()
        if self.kind == LEVEL:
            v = f"{self.value:.4g}" if self.value is not None else f"{lo:.4g}-{hi:.4g}"
            return v + (f" {self.unit}" if self.unit else "")
        if self.sign == 0:
            return f"no difference (within {lo:+.0f} … {hi:+.0f} %)"
        if self.sizes:
            return ", ".join(f"{c}: {v:+.1f} %" for c, v in self.sizes)
        if self.size is not None and self.band is None:
            return f"{self.size:+.1f} %"
        if not self.stated:
            return ("higher" if self.sign > 0 else "lower") + " (no size stated)"
        return f"{lo:+.1f} … {hi:+.1f} %"


@dataclass(frozen=True)
class CellVerdict:
    cell: object
    """The cell (``pooled`` for a pooled claim)."""
    n: tuple[int, int]
    """Runs of A and of B (a level: ours, 0)."""
    means: tuple[float, float]
    """A's and B's means (a level: ours, the paper's value or band centre)."""
    effect: float
    """Level: our mean; relation, trend: 100 (B - A) / A."""
    ci: tuple[float, float]
    p: float
    """Raw p-value (`holm` fills `p_adj`)."""
    p_adj: float = math.nan
    verdict: str = NA
    seeds: int | None = None
    """Not shown: runs per group that would show the paper's effect."""
    reason: str = ""


@dataclass(frozen=True)
class Verdict:
    claim: Claim
    verdict: str
    cells: tuple[CellVerdict, ...]


def values(rows: Iterable[dict], strategy: str, cell: object, measure: str, scale: float = 1.0) -> list[float]:
    """`measure` x `scale` of `strategy`'s runs in `cell` (rows with cell None serve every cell)."""
    return [float(r[measure]) * scale for r in rows
            if r.get("strategy") == strategy and r.get("cell") in (cell, None) and r.get(measure) is not None
            and math.isfinite(float(r[measure]))]


# ------------------------------------------------------------------ the statistics


def _mean_se_df(x: Sequence[float]) -> tuple[float, float, float]:
    a = np.asarray(x, dtype=float)
    return float(a.mean()), float(a.std(ddof=1) / math.sqrt(a.size)), float(a.size - 1)


def welch(a: Sequence[float], b: Sequence[float]) -> tuple[float, float, float]:
    """(B - A, its standard error, Welch's degrees of freedom)."""
    xa, xb = np.asarray(a, float), np.asarray(b, float)
    va, vb = xa.var(ddof=1) / xa.size, xb.var(ddof=1) / xb.size
    se = math.sqrt(va + vb)
    df = (va + vb) ** 2 / (va ** 2 / (xa.size - 1) + vb ** 2 / (xb.size - 1)) if se > 0 else math.inf
    return float(xb.mean() - xa.mean()), se, df


def _t_sf(t: float, df: float) -> float:
    from scipy import stats

    return float(stats.t.sf(t, df)) if math.isfinite(df) else float(stats.norm.sf(t))


def t_ppf(q: float, df: float) -> float:
    from scipy import stats

    return float(stats.t.ppf(q, df)) if math.isfinite(df) else float(stats.norm.ppf(q))


def two_sided_p(d: float, se: float, df: float) -> float:
    """Two-sided p of a difference `d` from 0 (Welch's t); a difference without spread is certain."""
    if se == 0:
        return 1.0 if d == 0 else 0.0
    return min(1.0, 2.0 * _t_sf(abs(d) / se, df))


def band_p(d: float, se: float, df: float, lo: float, hi: float) -> tuple[bool, float]:
    """(inside, p) of an estimate `d` against the band [lo, hi]: inside, p of the equivalence
    (2 x the larger of the two one-sided p-values, so p < 0.05 when the 95 % interval lies within);
    outside, 2 x the one-sided p that it lies beyond the nearer edge (p < 0.05 when the 95 %
    interval lies wholly outside). The same two-sided 95 % interval in both."""
    inside = lo <= d <= hi
    if se == 0:
        return inside, 0.0
    if inside:
        return True, min(1.0, 2.0 * max(_t_sf((d - lo) / se, df), _t_sf((hi - d) / se, df)))
    edge = hi if d > hi else lo
    return False, min(1.0, 2.0 * _t_sf(abs(d - edge) / se, df))


def runs_needed(sigma: float, delta: float, groups: int = 2) -> int | None:
    """Runs per group for a two-sided test at `ALPHA` to see `delta` with `POWER` at spread
    `sigma` (normal approximation; `groups` 1: a one-sample test)."""
    if not (math.isfinite(sigma) and math.isfinite(delta)) or delta == 0:
        return None
    z = t_ppf(1 - ALPHA / 2, math.inf) + t_ppf(POWER, math.inf)
    return max(2, math.ceil(groups * (z * sigma / abs(delta)) ** 2))


def bootstrap_pct(a: Sequence[float], b: Sequence[float], seed: int) -> tuple[float, float]:
    """95 % percentile interval of 100 (mean B - mean A) / mean A, each group resampled."""
    rng = np.random.default_rng(seed)
    xa, xb = np.asarray(a, float), np.asarray(b, float)
    ma = xa[rng.integers(0, xa.size, (BOOTSTRAP, xa.size))].mean(axis=1)
    mb = xb[rng.integers(0, xb.size, (BOOTSTRAP, xb.size))].mean(axis=1)
    with np.errstate(divide="ignore", invalid="ignore"):
        pct = 100.0 * (mb - ma) / ma
    pct = pct[np.isfinite(pct)]
    if not pct.size:
        return math.nan, math.nan
    return float(np.percentile(pct, 2.5)), float(np.percentile(pct, 97.5))


def holm(ps: Sequence[float]) -> list[float]:
    """Holm's step-down adjusted p-values (NaN stays NaN, and is not counted)."""
    order = sorted((p, i) for i, p in enumerate(ps) if math.isfinite(p))
    out = [math.nan] * len(ps)
    m, running = len(order), 0.0
    for k, (p, i) in enumerate(order):
        running = max(running, min(1.0, (m - k) * p))
        out[i] = running
    return out


# ------------------------------------------------------------------ one cell


def claim_seed(claim: Claim, cell: object) -> int:
    return zlib.crc32(f"{claim.id}|{cell}".encode())


def na_cell(cell: object, n: tuple[int, int], reason: str) -> CellVerdict:
    return CellVerdict(cell, n, (math.nan, math.nan), math.nan, (math.nan, math.nan), math.nan, reason=reason)


def level_cell(claim: Claim, ours: Sequence[float], cell: object, lo: float, hi: float) -> CellVerdict:
    """Our runs' mean against the band [lo, hi] (one-sample t)."""
    centre = claim.value if claim.value is not None else (lo + hi) / 2
    if len(ours) < 2:
        return na_cell(cell, (len(ours), 0), f"{len(ours)} run(s): no interval")
    mean, se, df = _mean_se_df(ours)
    half = t_ppf(1 - ALPHA / 2, df) * se
    inside, p = band_p(mean, se, df, lo, hi)
    return CellVerdict(cell, (len(ours), 0), (mean, centre), mean, (mean - half, mean + half), p,
                       reason="inside" if inside else "outside")


def relation_cell(claim: Claim, a: Sequence[float], b: Sequence[float], cell: object) -> CellVerdict:
    """B against A (Welch), the effect in % of A with its bootstrap interval."""
    if min(len(a), len(b)) < 2:
        return na_cell(cell, (len(a), len(b)), f"{len(a)} / {len(b)} runs: no test")
    d, se, df = welch(a, b)
    ma, mb = float(np.mean(a)), float(np.mean(b))
    if ma == 0:
        return na_cell(cell, (len(a), len(b)), "A's mean is 0: no per-cent size")
    effect = 100.0 * (mb - ma) / ma
    return CellVerdict(cell, (len(a), len(b)), (ma, mb), effect, bootstrap_pct(a, b, claim_seed(claim, cell)),
                       two_sided_p(d, se, df))


def judge(claim: Claim, c: CellVerdict, a: Sequence[float] = (), b: Sequence[float] = ()) -> CellVerdict:
    """The verdict of a cell once its p-value is adjusted (`c.p_adj`)."""
    if not math.isfinite(c.p_adj):
        return replace(c, verdict=NA)
    lo, hi = claim.limits(c.cell)
    significant = c.p_adj < ALPHA
    if claim.kind == LEVEL:
        if significant:
            return replace(c, verdict=HOLDS if c.reason == "inside" else CONTRADICTS)
        sigma = float(np.std(a, ddof=1)) if len(a) > 1 else math.nan
        edge = min(abs(c.effect - lo), abs(c.effect - hi))  # the interval must clear the nearer edge
        return replace(c, verdict=NOT_SHOWN, seeds=runs_needed(sigma, edge, groups=1))
    sigma = math.sqrt((np.var(a, ddof=1) + np.var(b, ddof=1)) / 2) if min(len(a), len(b)) > 1 else math.nan
    if claim.sign == 0:
        if significant:
            return replace(c, verdict=CONTRADICTS)
        if lo <= c.ci[0] and c.ci[1] <= hi:
            return replace(c, verdict=HOLDS)
        return replace(c, verdict=NOT_SHOWN, seeds=runs_needed(sigma, hi / 100.0 * abs(c.means[0])))
    right = c.effect * claim.sign > 0
    if not significant:
        paper = (lo + hi) / 2 if claim.stated else math.nan  # no stated size: no power to compute
        return replace(c, verdict=NOT_SHOWN, seeds=runs_needed(sigma, paper / 100.0 * abs(c.means[0])))
    if not right:
        return replace(c, verdict=CONTRADICTS)
    return replace(c, verdict=HOLDS if lo <= c.effect <= hi else DIRECTION)


# ------------------------------------------------------------------ claims


@dataclass
class _Pending:
    claim: Claim
    cells: list[CellVerdict] = field(default_factory=list)
    samples: list[tuple[list[float], list[float]]] = field(default_factory=list)


def _measure(claim: Claim, rows: Sequence[dict]) -> _Pending:
    out = _Pending(claim)
    lo, hi = claim.limits()
    if claim.kind == LEVEL:
        groups = [("pooled", [v for cell in claim.cells for v in values(rows, claim.a, cell, claim.measure,
                                                                         claim.scale)])] if claim.pooled else \
            [(cell, values(rows, claim.a, cell, claim.measure, claim.scale)) for cell in claim.cells]
        for cell, ours in groups:
            out.cells.append(level_cell(claim, ours, cell, lo, hi))
            out.samples.append((ours, []))
        return out
    if claim.kind == TREND:
        groups = [(claim.cells[0], values(rows, claim.a, claim.cells[0], claim.measure, claim.scale),
                   values(rows, claim.a, claim.cells[-1], claim.measure, claim.scale))]
        label = f"{claim.cells[0]} → {claim.cells[-1]}"
        groups = [(label, a, b) for _, a, b in groups]
    elif claim.pooled:
        a = [v for cell in claim.cells for v in values(rows, claim.a, cell, claim.measure, claim.scale)]
        b = [v for cell in claim.cells for v in values(rows, claim.b, cell, claim.measure, claim.scale)]
        groups = [("pooled", a, b)]
    else:
        groups = [(cell, values(rows, claim.a, cell, claim.measure, claim.scale),
                   values(rows, claim.b, cell, claim.measure, claim.scale)) for cell in claim.cells]
    for cell, a, b in groups:
        out.cells.append(relation_cell(claim, a, b, cell))
        out.samples.append((a, b))
    return out


def worst(verdicts: Iterable[str]) -> str:
    """A claim's verdict from its cells': the worst of `SEVERITY`, n/a only when every cell is."""
    seen = set(verdicts)
    return next((v for v in SEVERITY if v in seen), NA)


def evaluate(claims: Sequence[Claim], rows_of: Mapping[str, Sequence[dict]] | Sequence[dict]) -> list[Verdict]:
    """Every claim of one paper on one robot model, Holm-corrected together. `rows_of`: the rows
    (or claim id -> rows, when the paper's claims come from different sweeps)."""
    pending = [_measure(c, rows_of[c.id] if isinstance(rows_of, Mapping) else rows_of) for c in claims]
    flat = [cv.p for p in pending for cv in p.cells]
    adjusted = iter(holm(flat))
    out = []
    for p in pending:
        cells = []
        for cv, (a, b) in zip(p.cells, p.samples):
            cells.append(judge(p.claim, replace(cv, p_adj=next(adjusted)), a, b))
        out.append(Verdict(p.claim, worst(c.verdict for c in cells), tuple(cells)))
    return out


def counts(verdicts: Iterable[Verdict]) -> dict[str, int]:
    """Claims per verdict class, every class present."""
    out = dict.fromkeys(VERDICTS, 0)
    for v in verdicts:
        out[v.verdict] += 1
    return out


def level_marks(claims: Iterable[Claim], measure: str) -> dict[tuple[str, object], tuple[float, float, float]]:
    """(strategy, cell) -> (band low, the paper's value, band high) of every one-cell level of
    `measure`: what a comparison figure draws as the paper's (`swarm_sim.compare.report.paper_marks`)."""
    out = {}
    for c in claims:
        if c.kind == LEVEL and c.measure == measure and not c.pooled and c.value is not None:
            lo, hi = c.limits()
            for cell in c.cells:
                out[(c.a, cell)] = (lo, c.value, hi)
    return out


def relation_marks(claims: Iterable[Claim], measure: str, rows: Sequence[dict]
                   ) -> dict[tuple[str, object], tuple[float, float, float]]:
    """(B, cell) -> B's level the paper's stated difference implies from our A's mean in that cell
    (band low, centre, band high), for every relation of `measure` that states a size (the first
    claim about a box wins)."""
    out = {}
    for c in claims:
        if c.kind != RELATION or c.measure != measure or not (c.stated or c.sign == 0):
            continue
        for cell in c.cells:
            a = values(rows, c.a, cell, c.measure, c.scale)
            if not a:
                continue
            lo, hi = c.limits(cell)
            centre = dict(c.sizes).get(cell, c.size)
            centre = (lo + hi) / 2 if centre is None else centre
            base = float(np.mean(a))
            out.setdefault((c.b, cell), tuple(base * (1 + x / 100.0) for x in (lo, centre, hi)))
    return out

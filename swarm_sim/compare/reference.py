"""The authors' own code's runs beside ours: where they are kept, and ours judged against them.

``OUT/reference/<comparison>/**/results.jsonl`` holds runs of a paper's published code made on this
machine (`reference/`: rows of our results schema plus ``reference: true`` and their provenance).
They are the evidence of what produced the paper's numbers, so every claim is put to them twice:
the authors' code against the paper (does the code reproduce its own paper?) and ours against the
authors' code (do we do what the code does?), on the one scale of `swarm_sim.compare.verdicts`:

- a level cell: our mean against theirs, holding when the difference lies within ±`LEVEL_BAND` of
  their mean (Welch's two one-sided tests);
- a relation or trend cell: the size the authors' code shows takes the place of the paper's stated
  size (its band ±`LEVEL_BAND` of it, its direction), and a cell where their runs show no
  significant difference reads as a "no difference" claim (within ±`LEVEL_BAND` x 100 % of A).

Each family (a paper's level cells with reference runs; its relations) is Holm-corrected together,
as the paper's own claims are. Nothing here knows a paper.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import replace
from pathlib import Path

import numpy as np

from swarm_sim.compare.sweep import RESULTS, ResultsFileError, read_results
from swarm_sim.compare.verdicts import (
    ALPHA,
    CONTRADICTS,
    HOLDS,
    LEVEL,
    LEVEL_BAND,
    NA,
    NOT_SHOWN,
    TREND,
    CellVerdict,
    Claim,
    Verdict,
    band_p,
    bootstrap_pct,
    claim_seed,
    evaluate,
    holm,
    na_cell,
    values,
    welch,
    worst,
)

REFERENCE = "reference"
"""``OUT/reference/<comparison>/**/results.jsonl``: the authors' code's runs, if any (one file, or one per experiment)."""


def load_reference(out: Path, name: str) -> list[dict] | None:
    """The authors' code's runs of comparison `name`: every results file under
    ``OUT/reference/<name>/`` (one, or one per experiment as ``exp1/``, ``exp2/``); None when there
    is none; a file that cannot be read is left out, saying so in one line."""
    paths = sorted((out / REFERENCE / name).rglob(RESULTS))
    if not paths:
        return None
    rows = []
    for path in paths:
        try:
            rows += [r for r in read_results(path) if r.get(REFERENCE) is True]
        except ResultsFileError as exc:
            print(f"swarm-compare all: {exc}: the authors' code's runs in it left out")
    return rows


def matching(reference: Sequence[dict], extra: Mapping[str, object]) -> list[dict]:
    """The reference runs of one sweep: those carrying every field its plans share (``experiment``)."""
    return [x for x in reference if all(x.get(k) == v for k, v in extra.items())]


# ------------------------------------------------------------------ levels


def against_reference(claim: Claim, ours: Sequence[float], reference: Sequence[float], cell: object) -> CellVerdict:
    """Our runs against the authors' code's runs of the same cell, with a level's rule: the
    difference in % of the reference within ±`LEVEL_BAND` (Welch's two one-sided tests)."""
    if min(len(ours), len(reference)) < 2:
        means = tuple(float(np.mean(x)) if len(x) else math.nan for x in (ours, reference))
        return replace(na_cell(cell, (len(ours), len(reference)), f"{len(ours)} / {len(reference)} runs: no test"),
                       means=means)
    d, se, df = welch(reference, ours)
    ref = float(np.mean(reference))
    if ref == 0:
        return na_cell(cell, (len(ours), len(reference)), "reference mean is 0")
    half = abs(ref) * LEVEL_BAND
    inside, p = band_p(d, se, df, -half, half)
    return CellVerdict(cell, (len(ours), len(reference)), (float(np.mean(ours)), ref), 100.0 * d / ref,
                       bootstrap_pct(reference, ours, claim_seed(claim, f"ref|{cell}")), p,
                       reason="inside" if inside else "outside")


def on_code_measure(claims: Sequence[Claim]) -> list[Claim]:
    """`claims` on the field their authors' code counts them by (`Claim.code_measure`), so that
    both sides of a judgement against its runs count alike."""
    return [replace(c, measure=c.code_measure) if c.code_measure else c for c in claims]


def evaluate_reference(claims: Sequence[Claim], rows: Mapping[str, Sequence[dict]] | Sequence[dict],
                       reference: Sequence[dict]) -> dict[tuple[str, object], CellVerdict]:
    """(claim id, cell) -> our level cell judged against the authors' code's runs, Holm-corrected
    over the paper's level cells that have reference runs."""
    found = []
    for c in on_code_measure(claims):
        if c.kind != LEVEL:
            continue
        mine = rows[c.id] if isinstance(rows, Mapping) else rows
        for cell in c.cells:
            ref = values(reference, c.a, cell, c.measure, c.scale)
            if ref:
                ours = values(mine, c.a, cell, c.measure, c.scale)
                found.append(((c.id, cell), against_reference(c, ours, ref, cell)))
    adjusted = holm([cv.p for _, cv in found])
    out = {}
    for (key, cv), p in zip(found, adjusted):
        cv = replace(cv, p_adj=p)
        if not math.isfinite(p):
            out[key] = replace(cv, verdict=NA)
        else:
            out[key] = replace(cv, verdict=(HOLDS if cv.reason == "inside" else CONTRADICTS) if p < ALPHA
                               else NOT_SHOWN)
    return out


# ------------------------------------------------------------------ relations and trends


def as_shown_by(claim: Claim, cv: CellVerdict) -> Claim:
    """`claim` in one of its cells with the authors' code's runs in the paper's place: their size
    and direction where their difference is significant (`cv.p_adj`), else "no difference"."""
    sign = (1 if cv.effect > 0 else -1) if cv.p_adj < ALPHA else 0
    cells = claim.cells if claim.kind == TREND or claim.pooled else (cv.cell,)
    return replace(claim, id=f"{claim.id}@{REFERENCE}:{cv.cell}", cells=cells, size=cv.effect if sign else None,
                   sizes=(), band=None, sign=sign, causes=(), note="")


def evaluate_reference_relations(claims: Sequence[Claim], rows: Mapping[str, Sequence[dict]] | Sequence[dict],
                                 reference: Sequence[dict]) -> dict[str, tuple[Verdict, Verdict]]:
    """claim id -> (the authors' code's runs judged against the paper, ours judged against the
    authors' code's runs) for every relation and trend with a cell the reference runs cover; each
    verdict keeps only those cells, both sides on the claim's `Claim.code_measure`. Each of the two
    is one Holm family."""
    theirs = [v for v in evaluate([c for c in on_code_measure(claims) if c.kind != LEVEL], reference)
              if any(math.isfinite(cv.effect) for cv in v.cells)]
    theirs = [replace(v, cells=tuple(cv for cv in v.cells if math.isfinite(cv.effect))) for v in theirs]
    theirs = [replace(v, verdict=worst(cv.verdict for cv in v.cells)) for v in theirs]
    mirrored = [(v.claim, as_shown_by(v.claim, cv)) for v in theirs for cv in v.cells]
    rows_of = {m.id: (rows[c.id] if isinstance(rows, Mapping) else rows) for c, m in mirrored}
    ours: dict[str, list] = {}
    for (claim, _), v in zip(mirrored, evaluate([m for _, m in mirrored], rows_of)):
        ours.setdefault(claim.id, []).append(v.cells[0])
    return {v.claim.id: (v, Verdict(v.claim, worst(cv.verdict for cv in ours[v.claim.id]),
                                    tuple(ours[v.claim.id]))) for v in theirs}

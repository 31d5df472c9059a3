"""The verdict scale (`swarm_sim.compare.verdicts`) on hand-made samples: one test per verdict
class, each with a twin that must not get it, and the invariants (hypothesis)."""

from __future__ import annotations

import json
from dataclasses import replace

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from swarm_sim.compare.reference import evaluate_reference, evaluate_reference_relations
from swarm_sim.compare.report import reference_marks
from swarm_sim.compare.verdicts import (
    CODE,
    CONTRADICTS,
    DIRECTION,
    HOLDS,
    LEVEL,
    MEASURED,
    NA,
    NOT_SHOWN,
    RELATION,
    TREND,
    Cause,
    Claim,
    evaluate,
    holm,
    worst,
)


def rows(strategy: str, cell, values) -> list[dict]:
    return [{"strategy": strategy, "cell": cell, "m": float(v), "seed": i} for i, v in enumerate(values)]


def around(mean: float, spread: float = 1.0, n: int = 20, seed: int = 0) -> np.ndarray:
    """`n` values with exactly this mean and sample spread."""
    x = np.random.default_rng(seed).normal(size=n)
    return mean + spread * (x - x.mean()) / x.std(ddof=1)


def one(claim: Claim, data: list[dict]):
    return evaluate([claim], data)[0]


LEVEL_100 = Claim("lvl", LEVEL, "A is 100", "Table 1", "m", "A", (1,), value=100.0)
UP_50 = Claim("rel", RELATION, "B is 50 % above A", "Sec. 1", "m", "A", (1,), b="B", size=50.0)


# ------------------------------------------------------------------ holds, and what is not


def test_a_level_within_the_band_holds_and_one_26_percent_off_does_not():
    assert one(LEVEL_100, rows("A", 1, around(110.0))).verdict == HOLDS
    off = one(LEVEL_100, rows("A", 1, around(126.0, 0.5)))  # 26 % off, tight: outside ±25 %
    assert off.verdict == CONTRADICTS and off.cells[0].reason == "outside"
    near = one(LEVEL_100, rows("A", 1, around(124.0, 5.0)))  # inside, but its interval crosses 125
    assert near.verdict == NOT_SHOWN and near.cells[0].seeds > 20


def test_a_relation_right_significant_and_in_the_band_holds_its_twin_outside_is_direction_only():
    a = rows("A", 1, around(100.0, 5.0))
    assert one(UP_50, a + rows("B", 1, around(150.0, 5.0, seed=1))).verdict == HOLDS
    twin = one(UP_50, a + rows("B", 1, around(190.0, 5.0, seed=1)))  # +90 %: outside 37.5 … 62.5
    assert twin.verdict == DIRECTION and twin.cells[0].p_adj < 0.05


def test_a_right_sign_at_p_0_3_is_not_shown_with_the_runs_that_would_show_it():
    a = rows("A", 1, around(100.0, 40.0, n=10))
    b = rows("B", 1, around(112.0, 40.0, n=10, seed=1))  # right way, far from significant
    v = one(UP_50, a + b)
    assert v.verdict == NOT_SHOWN and v.cells[0].p_adj > 0.2
    # the paper's +50 % at sigma 40 on a mean of 100: 2 (2.80 x 40 / 50)^2 = 10.04 -> 11 runs per group
    assert v.cells[0].seeds == 11
    twin = one(UP_50, rows("A", 1, around(100.0, 4.0, n=10)) + rows("B", 1, around(150.0, 4.0, n=10, seed=1)))
    assert twin.verdict == HOLDS


def test_significant_the_other_way_contradicts_and_its_twin_the_right_way_does_not():
    a = rows("A", 1, around(100.0, 5.0))
    assert one(UP_50, a + rows("B", 1, around(70.0, 5.0, seed=1))).verdict == CONTRADICTS
    assert one(UP_50, a + rows("B", 1, around(130.0, 5.0, seed=1))).verdict != CONTRADICTS


def test_too_few_runs_is_na_with_the_reason_and_two_runs_are_tested():
    v = one(UP_50, rows("A", 1, [100.0]) + rows("B", 1, [150.0, 151.0]))
    assert v.verdict == NA and "1 / 2 runs" in v.cells[0].reason
    assert one(UP_50, rows("A", 1, [100.0, 101.0]) + rows("B", 1, [150.0, 151.0])).verdict != NA
    assert one(LEVEL_100, []).verdict == NA


def test_no_difference_holds_only_when_not_significant_and_the_interval_is_in_the_band():
    same = Claim("same", RELATION, "B as A", "Sec. 2", "m", "A", (1,), b="B", sign=0)
    a = rows("A", 1, around(100.0, 3.0))
    assert one(same, a + rows("B", 1, around(101.0, 3.0, seed=1))).verdict == HOLDS
    assert one(same, a + rows("B", 1, around(110.0, 3.0, seed=1))).verdict == CONTRADICTS  # significant
    wide = rows("A", 1, around(100.0, 60.0, n=5)) + rows("B", 1, around(101.0, 60.0, n=5, seed=1))
    assert one(same, wide).verdict == NOT_SHOWN  # nothing significant, but the interval reaches past ±25 %


def test_a_trend_compares_the_first_and_last_cell_of_one_strategy():
    falls = Claim("t", TREND, "A falls by 25 %", "Table", "m", "A", (48, 112), sign=-1, size=-25.0)
    data = rows("A", 48, around(40.0, 1.0)) + rows("A", 80, around(0.0)) + rows("A", 112, around(30.0, 1.0))
    v = one(falls, data)
    assert v.verdict == HOLDS and v.cells[0].effect == pytest.approx(-25.0)
    steep = rows("A", 48, around(40.0, 1.0)) + rows("A", 112, around(15.0, 1.0))  # -62.5 %
    assert one(falls, steep).verdict == DIRECTION


def test_a_claim_over_cells_takes_its_worst_cell_and_a_pooled_one_pools_them():
    claim = Claim("c", RELATION, "B above A", "Table", "m", "A", (1, 2), b="B", size=50.0)
    data = (rows("A", 1, around(100.0, 2.0)) + rows("B", 1, around(150.0, 2.0, seed=1))
            + rows("A", 2, around(100.0, 2.0)) + rows("B", 2, around(80.0, 2.0, seed=1)))
    v = one(claim, data)
    assert [c.verdict for c in v.cells] == [HOLDS, CONTRADICTS] and v.verdict == CONTRADICTS
    pooled = Claim("p", RELATION, "B above A on average", "Table", "m", "A", (1, 2), b="B", size=15.0, pooled=True)
    got = one(pooled, data)
    assert len(got.cells) == 1 and got.cells[0].effect == pytest.approx(15.0)
    assert worst([HOLDS, NOT_SHOWN, DIRECTION]) == NOT_SHOWN and worst([NA, HOLDS]) == HOLDS and worst([NA]) == NA


def test_holm_corrects_within_the_family_so_a_lone_p_0_03_fails_among_many():
    lone = rows("A", 1, around(100.0, 10.0, n=12)) + rows("B", 1, around(109.5, 10.0, n=12, seed=1))
    alone = one(UP_50, lone)
    assert 0.01 < alone.cells[0].p < 0.05 and alone.verdict == DIRECTION
    others = [Claim(f"x{i}", RELATION, "x", "x", "m", "A", (1,), b="B", size=50.0) for i in range(5)]
    together = evaluate([UP_50, *others], lone)
    assert together[0].cells[0].p_adj == pytest.approx(min(1.0, 6 * alone.cells[0].p))
    assert together[0].verdict == NOT_SHOWN


def test_a_cell_without_spread_is_judged_exactly():
    assert one(LEVEL_100, rows("A", 1, [100.0, 100.0, 100.0])).verdict == HOLDS
    assert one(LEVEL_100, rows("A", 1, [200.0, 200.0])).verdict == CONTRADICTS


def test_a_measured_cause_needs_its_factor_and_ten_seeds():
    with pytest.raises(ValueError, match="at least 10 seeds"):
        Cause(MEASURED, "the motion rule", "motion_generic", 4)
    assert Cause(MEASURED, "the motion rule", "motion_generic", 10).seeds == 10
    with pytest.raises(ValueError, match="grade"):
        Cause("likely", "x")
    with pytest.raises(ValueError, match="against its sign"):
        Claim("bad", RELATION, "x", "x", "m", "A", (1,), b="B", sign=-1, size=20.0)


def test_the_authors_code_runs_are_judged_as_a_level_against_ours():
    ref = [{**r, "reference": True} for r in rows("A", 1, around(100.0, 2.0, seed=3))]
    close = evaluate_reference([LEVEL_100], rows("A", 1, around(105.0, 2.0)), ref)[("lvl", 1)]
    assert close.verdict == HOLDS and close.effect == pytest.approx(5.0)
    far = evaluate_reference([LEVEL_100], rows("A", 1, around(140.0, 2.0)), ref)[("lvl", 1)]
    assert far.verdict == CONTRADICTS
    assert evaluate_reference([LEVEL_100], rows("A", 1, around(140.0)), []) == {}


def test_a_relation_is_judged_against_the_size_the_authors_code_shows():
    """The authors' code's runs take the paper's place: their size and direction (ours +50 % holds
    against their +60 %, not against their +120 %), and where their difference is not significant,
    "no difference" (ours +50 % then contradicts); their runs are also judged against the paper."""
    ours = rows("A", 1, around(100.0, 2.0)) + rows("B", 1, around(150.0, 2.0, seed=1))

    def against(b_mean):
        ref = rows("A", 1, around(100.0, 2.0, seed=2)) + rows("B", 1, around(b_mean, 2.0, seed=3))
        return evaluate_reference_relations([LEVEL_100, UP_50], ours, ref)

    theirs, mine = against(160.0)["rel"]
    assert (theirs.verdict, mine.verdict) == (HOLDS, HOLDS)
    assert theirs.cells[0].effect == pytest.approx(60.0)
    theirs, mine = against(220.0)["rel"]
    assert (theirs.verdict, mine.verdict) == (DIRECTION, DIRECTION)
    theirs, mine = against(100.0)["rel"]
    assert (theirs.verdict, mine.verdict) == (NOT_SHOWN, CONTRADICTS)
    assert evaluate_reference_relations([UP_50], ours, rows("C", 1, around(1.0))) == {}


def test_a_claim_their_code_counts_its_own_way_is_judged_on_their_count_on_both_sides():
    """Ours counts `m` by another rule than the authors' code; against their runs both sides are
    judged on their count (`code_measure`), never ours against theirs."""
    def counted(strategy, mine, theirs, seed):
        return [{**r, "m": 9.0 * r["m"], "theirs": t} for r, t in
                zip(rows(strategy, 1, mine), around(theirs, 2.0, seed=seed))]

    ours = counted("A", around(100.0, 2.0), 100.0, 4) + counted("B", around(150.0, 2.0, seed=1), 160.0, 5)
    ref = [{k: v for k, v in r.items() if k != "m"} for r in
           counted("A", around(100.0, 2.0, seed=2), 100.0, 6) + counted("B", around(150.0, 2.0, seed=3), 160.0, 7)]
    theirs, mine = evaluate_reference_relations([replace(UP_50, code_measure="theirs")], ours, ref)["rel"]
    assert theirs.cells[0].effect == pytest.approx(60.0) and mine.cells[0].effect == pytest.approx(60.0)
    assert (theirs.verdict, mine.verdict) == (HOLDS, HOLDS)
    assert evaluate_reference_relations([UP_50], ours, ref) == {}  # their rows hold no `m`
    level = replace(LEVEL_100, code_measure="theirs")
    assert evaluate_reference([level], ours, ref)[("lvl", 1)].means == pytest.approx((100.0, 100.0))


def test_the_authors_code_runs_are_drawn_with_their_interval():
    ref = rows("A", 1, around(100.0, 2.0)) + rows("A", 2, [7.0]) + rows("B", None, [3.0, 5.0])
    marks = reference_marks(ref, "m", ["A", "B"], [1, 2, 3])
    lo, mean, hi, n = marks[("A", 1)]
    assert (mean, n) == (pytest.approx(100.0), 20) and lo < 99.5 and hi > 100.5
    assert marks[("A", 2)] == (7.0, 7.0, 7.0, 1) and ("A", 3) not in marks
    assert marks[("B", 1)] == marks[("B", 2)] == marks[("B", 3)]  # a run of cell None serves every cell
    assert marks[("B", 1)][1::2] == (4.0, 2)


def test_the_bootstrap_interval_is_seeded():
    data = rows("A", 1, around(100.0, 9.0)) + rows("B", 1, around(150.0, 9.0, seed=1))
    assert one(UP_50, data).cells[0].ci == one(UP_50, data).cells[0].ci


# ------------------------------------------------------------------ invariants


@settings(max_examples=40, deadline=None)
@given(st.lists(st.floats(0, 1, allow_nan=False), min_size=1, max_size=30))
def test_holm_never_lowers_a_p_value_and_keeps_their_order(ps):
    adj = holm(ps)
    assert all(a >= p - 1e-12 and a <= 1.0 for p, a in zip(ps, adj))
    order = sorted(range(len(ps)), key=lambda i: ps[i])
    assert all(adj[order[k]] <= adj[order[k + 1]] + 1e-12 for k in range(len(ps) - 1))


@settings(max_examples=40, deadline=None)
@given(st.floats(50, 150), st.floats(0.5, 20), st.integers(3, 25), st.integers(0, 10**6))
def test_a_level_holds_only_inside_and_contradicts_only_outside_the_band(mean, spread, n, seed):
    v = one(LEVEL_100, rows("A", 1, around(mean, spread, n=n, seed=seed))).cells[0]
    lo, hi = LEVEL_100.limits()
    if v.verdict == HOLDS:
        assert lo <= v.ci[0] and v.ci[1] <= hi
    if v.verdict == CONTRADICTS:
        assert v.ci[1] < hi or v.ci[0] > lo
        assert not (lo <= v.effect <= hi)
    assert v.ci[0] <= v.effect <= v.ci[1]


@settings(max_examples=30, deadline=None)
@given(st.floats(-80, 80), st.floats(0.5, 30), st.integers(3, 20), st.integers(0, 10**6))
def test_swapping_a_relation_flips_its_sign_and_keeps_its_verdict_class(shift, spread, n, seed):
    """B above A (+1) on one sample is B below A (-1) on the swapped one, the verdict the same
    unless the size's band differs (only the direction classes are compared)."""
    a, b = around(100.0, spread, n=n, seed=seed), around(100.0 + shift, spread, n=n, seed=seed + 1)
    up = Claim("u", RELATION, "x", "x", "m", "A", (1,), b="B")
    down = Claim("d", RELATION, "x", "x", "m", "B", (1,), b="A", sign=-1)
    data = rows("A", 1, a) + rows("B", 1, b)
    vu, vd = one(up, data), one(down, data)
    assert vu.cells[0].p == pytest.approx(vd.cells[0].p)
    assert vu.verdict == vd.verdict
    assert vu.cells[0].effect * vd.cells[0].effect <= 0


def test_the_report_counts_every_claim_once_and_renders_the_reference_column(tmp_path):
    """`report_verdicts` on two fake sweeps of one comparison: counts per model, a level table with
    the authors' code's column once OUT/reference/<name>/results.jsonl exists."""
    from types import SimpleNamespace

    from swarm_sim.compare.verdict_report import report_verdicts

    comparison = SimpleNamespace(name="toy", help="a toy paper", rules=())
    data = rows("A", 1, around(110.0)) + rows("B", 1, around(165.0, seed=1))
    sweeps = [SimpleNamespace(comparison=comparison, claims=(LEVEL_100,), rows=data, extra={}),
              SimpleNamespace(comparison=comparison, claims=(UP_50,), rows=data, extra={})]
    lines = report_verdicts({"authors": sweeps}, tmp_path, {"authors": "authors' robots"})
    text = "\n".join(lines)
    assert "| toy | authors' robots | 2 | 0 | 0 | 0 | 0 | 2 |" in text
    assert "authors' code here" not in text
    ref = tmp_path / "reference" / "toy"
    ref.mkdir(parents=True)
    (ref / "results.jsonl").write_text("".join(json.dumps({**r, "reference": True, "repository": "x/y",
                                                           "commit": "0" * 40, "xml": "a.xml"}) + "\n"
                                               for r in rows("A", 1, around(108.0, seed=5))
                                               + rows("B", 1, around(160.0, seed=6))))
    text = "\n".join(report_verdicts({"authors": sweeps}, tmp_path, {"authors": "authors' robots"}))
    assert "authors' code here (authors' robots)" in text and "108 (n=20)" in text
    assert "| toy | authors' robots | 1 holds of 1 | 1 holds of 1 | 1 holds of 1 |" in text  # the second judgement
    assert "1: holds → holds" in text  # the relation's column: ours against their +48 %
    dup = [*sweeps, SimpleNamespace(comparison=comparison, claims=(LEVEL_100,), rows=data, extra={})]
    with pytest.raises(ValueError, match="repeat"):
        report_verdicts({"authors": dup}, tmp_path, {"authors": "authors' robots"})


def test_a_claim_that_fails_is_shown_beside_the_authors_codes_verdict_on_it(tmp_path):
    """The causes table says whether the authors' own code, run here, misses the claim too."""
    from types import SimpleNamespace

    from swarm_sim.compare.verdict_report import report_verdicts

    comparison = SimpleNamespace(name="toy", help="a toy paper", rules=())
    double = Claim("up100", RELATION, "B is twice A", "Sec. 2", "m", "A", (1,), b="B", size=100.0)
    sweeps = [SimpleNamespace(comparison=comparison, claims=(double,), extra={},
                              rows=rows("A", 1, around(100.0)) + rows("B", 1, around(150.0, seed=1)))]
    ref = tmp_path / "reference" / "toy"
    ref.mkdir(parents=True)
    for their_b, verdict in ((148.0, DIRECTION), (200.0, HOLDS)):
        (ref / "results.jsonl").write_text("".join(json.dumps({**r, "reference": True}) + "\n" for r in
                                                   rows("A", 1, around(100.0, seed=5))
                                                   + rows("B", 1, around(their_b, seed=6))))
        text = "\n".join(report_verdicts({"authors": sweeps}, tmp_path, {"authors": "authors' robots"}))
        assert f"| `up100` | direction only | {verdict} | *open*: no cause named |" in text
    # a cause graded "the authors' code too" is checked against their runs: here they hold
    code = Cause(CODE, "their code misses it too", "reference/toy", 20)
    sweeps[0].claims = (replace(double, causes=(("*", code),)),)
    with pytest.raises(ValueError, match="up100: its cause says the authors' code misses it too, but their runs"):
        report_verdicts({"authors": sweeps}, tmp_path, {"authors": "authors' robots"})
    with pytest.raises(ValueError, match="at least 10 seeds"):
        Cause(CODE, "their code misses it too", "reference/toy", 3)


def test_the_readme_states_the_reports_counts():
    """README's claim counts are REPORT.md's (both committed; `swarm-compare all --report-only`)."""
    import re
    from pathlib import Path

    root = Path(__file__).resolve().parents[1]
    report = (root / "results" / "REPORT.md").read_text()
    readme = (root / "README.md").read_text()
    found = re.findall(r"^\| \*\*all\*\* \| ([^|]+) \| \*\*(\d+)\*\* \| \*\*(\d+)\*\* \| \*\*(\d+)\*\* \| \*\*(\d+)\*\* "
                       r"\| \*\*(\d+)\*\* \|", report, re.M)
    assert len(found) == 2
    for model, holds, direction, not_shown, contradicts, na in found:
        text = (f"**{holds} hold**, {direction} direction only, {not_shown} not shown, {contradicts} contradict, "
                f"{na} n/a")
        assert text in " ".join(readme.split()), (model, text)

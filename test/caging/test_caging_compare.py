"""swarm-compare caging: the six cells of the paper's Tables 1 and 2 and the report next to the
paper's numbers (synthetic rows; the sweep itself is the batch runner's)."""

from __future__ import annotations

from swarm_controllers.caging.comparison import (
    CELLS,
    caging_plans,
    caging_tables_md,
    write_caging_report,
)
from swarm_sim.compare import comparisons
from swarm_sim.scenario import load_scenario


def test_the_plans_cover_both_tables_and_load():
    plans = caging_plans()
    assert [p.cell for p in plans] == [0, 1, 2, 3, 4, 5]
    settings = {(c.step, c.robots, c.radius, c.mass) for c in CELLS}
    assert settings == {(0.5, 8, 0.3, 0.3), (1.0, 8, 0.3, 0.3), (0.5, 6, 0.3, 0.3), (0.5, 7, 0.3, 0.3),
                        (0.5, 8, 0.4, 0.7), (0.5, 8, 0.45, 1.0)}
    for plan in plans:
        s = load_scenario(plan.strategy, plan.overrides, **dict(plan.fields))
        assert s.sim.stop_when_finished and s.sim.duration == 2400.0
    assert comparisons()["caging"].strategies == ("caging",)


def _row(cell: int, seed: int, **values) -> dict:
    base = {"strategy": "caging", "cell": cell, "seed": seed, "search_time_s": 100.0 + seed,
            "recruitment_time_s": 150.0, "transport_time_s": 200.0, "total_time_s": 450.0 + seed,
            "planned_path_m": 10.0, "object_path_m": 9.0, "trajectory_error_m": 1.0, "trajectory_error_pct": 10.0,
            "cage_held": True, "max_path_deviation_m": 0.08}
    return {**base, **values}


def test_the_report_puts_our_cells_next_to_the_papers_numbers(tmp_path):
    rows = [_row(c.number, s) for c in CELLS for s in range(3)]
    rows.append(_row(0, 3, transport_time_s=None, total_time_s=None, cage_held=False, planned_path_m=None,
                     object_path_m=None, trajectory_error_m=None, trajectory_error_pct=None))
    text = caging_tables_md(rows)
    assert "| Search | 0.5 | 101.50 ± 1.29 (median 101.50, n=4) | 222.165 |" in text
    assert "| Recruitment | 1 | 150.00 ± 0.00 (median 150.00, n=3) | 164.481 |" in text
    assert "| 6 | 10.00 ± 0.00 (median 10.00, n=3) |" in text and "| 4.3284 | 0.1778 | 4.1 | 215.07 |" in text
    assert "3/4 transported, cage held in 3" in text  # the run that never delivered counts
    assert "(paper: about 3.8 %)" in text
    written = write_caging_report(rows, tmp_path)
    assert [p.name for p in written] == ["tables.md", "times.png", "path.png", "error.png"]


def test_every_number_of_both_tables_is_a_claim_judged_on_our_cells():
    from swarm_controllers.caging.claims import CAGING_CLAIMS
    from swarm_controllers.caging.comparison import PAPER_TABLE1, PAPER_TABLE2
    from swarm_sim.compare.verdicts import HOLDS, LEVEL, NOT_SHOWN, evaluate

    levels = [c for c in CAGING_CLAIMS if c.kind == LEVEL]
    assert len(levels) == len(PAPER_TABLE1) + 3 * len(PAPER_TABLE2) + 1  # and the 3.8 %
    assert len({c.id for c in CAGING_CLAIMS}) == len(CAGING_CLAIMS)
    printed = {v for v in PAPER_TABLE1.values()} | {v for t in PAPER_TABLE2.values() for v in t}
    assert printed <= {c.value for c in levels}
    rows = [_row(c.number, s) for c in CELLS for s in range(4)]
    rows += [_row(1, 4 + s, search_time_s=10.0) for s in range(4)]  # the coarse grid searches faster
    found = {v.claim.id: v for v in evaluate(CAGING_CLAIMS, rows)}
    assert found["step.recruitment"].verdict == HOLDS  # 150 s at both steps
    assert found["T1.recruitment.0.5"].verdict == HOLDS  # 150 s against 164.5 s, no spread
    assert found["error.pct"].verdict != HOLDS  # 10 % against 3.8 %
    assert found["step.search"].verdict in (HOLDS, NOT_SHOWN) and found["step.search"].cells[0].effect < 0

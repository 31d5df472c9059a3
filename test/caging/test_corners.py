"""The caging path error's corner analysis (`swarm_controllers.caging.corners`) on hand-made paths."""

from __future__ import annotations

import numpy as np
import pytest

from swarm_controllers.caging.corners import corner_counts, corners, corners_md


def test_corners_of_a_hand_made_plan_and_how_close_the_object_came():
    # straight, a 45 deg turn, a repeated landmark, a 90 deg turn, then straight back (180 deg)
    plan = np.array([[0, 0], [1, 0], [2, 1], [2, 1], [2, 2], [2, 3], [2, 2]], dtype=float)
    path = np.array([[0, 0], [0.98, 0.0], [2.0, 1.05], [1.9, 2.0], [2.0, 2.9], [2.0, 2.2]])
    found = corners(plan, path)
    assert [round(d) for d, _ in found] == [45, 45, 180]  # (1,0) and (2,1); (2,2) is no corner
    assert [round(c, 3) for _, c in found] == [0.02, 0.05, 0.1]
    assert corner_counts(found) == [2, 0, 0, 1]
    assert corners(plan[:2], path) == [] and corner_counts([(90.0, 0.1), (20.0, 0.0)]) == [0, 1, 0, 0]


def test_the_report_fits_the_length_lost_per_corner():
    """Losses of 0.1 m per run, 0.1 m per 90 deg corner and 0.3 m per 180 deg one: the fit
    recovers all three exactly; the straight run reports its own error."""
    rows = [{"cell": 0, "seed": 0, "model": "khepera3", "delivered": True, "planned_m": 10.0, "object_m": 9.4,
             "error_pct": 5.0, "corners": [(90.0, 0.08), (180.0, 0.1), (90.0, 0.06)]},
            {"cell": 0, "seed": 1, "model": "khepera3", "delivered": True, "planned_m": 5.0, "object_m": 4.5,
             "error_pct": 8.0, "corners": [(90.0, 0.07), (180.0, 0.12)]},
            {"cell": 0, "seed": 2, "model": "khepera3", "delivered": True, "planned_m": 3.0, "object_m": 2.9,
             "error_pct": 3.3, "corners": []},
            {"cell": 0, "seed": 3, "model": "khepera3", "delivered": False}]
    text = corners_md(rows)
    assert "| none (per run: the two ends) | 3 | 0.100 | — |" in text
    assert "| 90 | 3 | 0.100 | 0.070 |" in text and "| 180 | 2 | 0.300 | 0.110 |" in text
    assert "Runs whose plan has no corner: error 3.3 %" in text
    assert "| 45 | 0 | — | — |" in text  # no corner of that kind: nothing fitted
    assert "residual rms 0.000 m" in text


@pytest.mark.parametrize("rows", [[], [{"cell": 0, "seed": 0, "model": "x", "delivered": False}]])
def test_no_delivered_run_is_said_not_fitted(rows):
    assert "No delivered run." in corners_md(rows)

"""The queue claims' measured steps are the committed runs: the factor sweeps (results/factors) and
the authors' code run here (results/reference/queue), recomputed; a rerun or an edit that moves a
number shows here."""

import json
from collections import defaultdict
from pathlib import Path

import numpy as np
import pytest

from swarm_controllers.queue import claims
from swarm_sim.compare.verdicts import MEASURED, PARTIAL

RESULTS = Path(__file__).resolve().parents[2] / "results"


def _mean(path: Path, strategy: str, robots: int, seeds: int | None = 10) -> float:
    runs = defaultdict(list)
    for line in path.read_text().splitlines():
        row = json.loads(line)
        if seeds is None or row["seed"] < seeds:
            runs[(row["strategy"], row["robots"])].append(row["resources_collected_pct"])
    return float(np.mean(runs[(strategy, robots)]))


def _group(strategy: str, robots: int) -> Path:
    return RESULTS / "factors" / f"{strategy.removeprefix('queue_')}{robots}"


@pytest.mark.parametrize("step", claims.LINE_MOTION_STEPS, ids=lambda s: f"{s[0]}-{s[1]}")
def test_the_line_motion_steps_are_the_committed_runs(step):
    s, n, base, cont, ref = step
    group = _group(s, n)
    assert _mean(group / "baseline" / "results.jsonl", s, n) == pytest.approx(base, abs=0.051)
    assert _mean(group / "queued_motion_continuous" / "results.jsonl", s, n) == pytest.approx(cont, abs=0.051)
    assert _mean(RESULTS / "reference" / "queue" / "results.jsonl", s, n, None) == pytest.approx(ref, abs=0.051)


@pytest.mark.parametrize("step", claims.WHOLE_MOTION_STEPS, ids=lambda s: f"{s[0]}-{s[1]}")
def test_the_whole_motion_steps_are_the_committed_runs_and_grade_the_levels(step):
    s, n, base, steps = step
    group = _group(s, n)
    assert _mean(group / "baseline" / "results.jsonl", s, n) == pytest.approx(base, abs=0.0051)
    for factor, value in steps:
        assert _mean(group / factor / "results.jsonl", s, n) == pytest.approx(value, abs=0.0051)
    (claim,) = [c for c in claims.QUEUE_CLAIMS if c.id == f"T2.{claims.QUEUE_LABELS[s]}.{n}"]
    (model, cause), = claim.causes
    paper = claims.PAPER_TABLE_II[s][n]
    closing = [f for f, v in steps if abs(v - paper) <= abs(base - paper) / 2]
    assert model == "authors" and cause.factor == f"{group.name}/{(closing or [steps[0][0]])[0]}"
    assert cause.grade == (MEASURED if closing else PARTIAL)

"""The caging paper's evaluation (Cardoso, Nedjah & Mourelle; caging_transport.md sec. 5):
Table 1 (search and recruitment time for landmark steps 0.5 and 1 m) and Table 2 (case 1: 6, 7
and 8 robots with r = 0.3 m, M = 0.3 kg; case 2: 8 robots with (r, M) = (0.3, 0.3), (0.4, 0.7),
(0.45, 1.0)), our runs next to the paper's numbers.

Six distinct settings ("cells") cover both tables: the paper's default (step 0.5 m, 8 robots,
r = 0.3 m, M = 0.3 kg) is Table 1's step 0.5 row, case 1's rho = 8 row and case 2's first row.
"""

from __future__ import annotations

import argparse
from collections.abc import Sequence
from pathlib import Path

from swarm_controllers.caging.claims import (
    CAGING_CLAIMS,
    CELLS,
    PAPER_NORMALISED_ERROR_PCT,
    PAPER_TABLE1,
    PAPER_TABLE2,
    STRATEGY,
)
from swarm_sim.compare.comparison import Comparison
from swarm_sim.compare.report import boxplot_figure, cell_text, fmt, md_table
from swarm_sim.compare.stats import Stats, describe, values_of
from swarm_sim.compare.sweep import RunPlan, frozen_fields
from swarm_sim.compare.verdicts import level_marks

DURATION_S = 2400.0
"""Sim seconds a run may last: the transport follows the recruiter's whole random walk reversed,
so a long search means a long transport (our longest runs end after ~1400 s). Runs end as soon as
every robot is done (``sim.stop_when_finished``)."""

TABLE2_METRICS: dict[str, str] = {
    "planned_path_m": "planned path [m]",
    "object_path_m": "object's path [m]",
    "trajectory_error_m": "error [m]",
    "trajectory_error_pct": "error [%]",
    "transport_time_s": "transport time [s]",
    "total_time_s": "total time [s]",
}


def caging_plans(cells: Sequence[int] | None = None, duration: float | None = None,
                 overrides: Sequence[str] = ()) -> list[RunPlan]:
    """One plan per cell (every seed of a cell is a run of the `caging` scenario)."""
    fields = frozen_fields({"sim__duration": duration if duration is not None else DURATION_S,
                            "sim__stop_when_finished": True})
    return [RunPlan(STRATEGY, c.number, (*c.overrides, *overrides), fields,
                    (("step", c.step), ("rho", c.robots), ("radius", c.radius), ("mass", c.mass)))
            for c in CELLS if cells is None or c.number in cells]


def _cell(rows: Sequence[dict], number: int, metric: str) -> str:
    return cell_text(describe(values_of(rows, STRATEGY, number, metric)), digits=2, median=True)


def _done(rows: Sequence[dict], number: int) -> str:
    runs = [r for r in rows if r.get("cell") == number]
    finished = sum(1 for r in runs if r.get("transport_time_s") is not None)
    held = sum(1 for r in runs if r.get("cage_held") is True)
    return f"{finished}/{len(runs)} transported, cage held in {held}"


def _over_all_runs(rows: Sequence[dict], metric: str) -> Stats:
    """`metric` described over every run that has it, whatever its cell."""
    return describe([float(r[metric]) for r in rows if r.get(metric) is not None])


def caging_tables_md(rows: Sequence[dict]) -> str:
    lines = ["# Caging paper comparison (Cardoso, Nedjah & Mourelle, sec. 5)", "",
             "Our runs: the `caging` scenario with the cell's settings, seeds 0..n-1, batch runner. "
             "Cells: mean ± sample std (median, n); search times, and with them path lengths and "
             "transport times, are heavy-tailed. The paper's numbers are single averages (its run count is not "
             "stated). Times are sim seconds. Runs whose transport did not finish within the run have no "
             "transport time, path or error.", "",
             "Cells (the box plots' x axis): " + "; ".join(f"{c.number} = {c.name}" for c in CELLS) + ".", ""]
    lines += ["## Table 1: search and recruitment (8 robots, r = 0.3 m, M = 0.3 kg)", ""]
    body = []
    for metric, stage in (("search_time_s", "Search"), ("recruitment_time_s", "Recruitment")):
        for number, step in ((0, 0.5), (1, 1.0)):
            body.append([stage, f"{step:g}", _cell(rows, number, metric), fmt(PAPER_TABLE1[(metric, step)], 3)])
    lines += md_table(["stage", "step [m]", "ours [s]", "paper [s]"], body) + [""]
    lines += ["## Table 2: transport", ""]
    for title, numbers, key in (("Case 1: r = 0.3 m, M = 0.3 kg, step 0.5 m", (2, 3, 0), "rho"),
                                ("Case 2: 8 robots, step 0.5 m", (0, 4, 5), "r, M")):
        lines += [f"### {title}", ""]
        body = []
        for number in numbers:
            c = CELLS[number]
            setting = f"{c.robots}" if key == "rho" else f"{c.radius:g} m, {c.mass:g} kg"
            paper = PAPER_TABLE2[number]
            body.append([setting, *(_cell(rows, number, m) for m in TABLE2_METRICS),
                         fmt(paper[0], 4), fmt(paper[1], 4), fmt(100 * paper[1] / paper[0], 1), fmt(paper[2], 2),
                         _done(rows, number)])
        lines += md_table([key, *TABLE2_METRICS.values(), "paper length [m]", "paper error [m]",
                           "paper error [%]", "paper time [s]", "runs"], body) + [""]
    errors = _over_all_runs(rows, "trajectory_error_pct")
    lines += [f"Normalised error over every run: {cell_text(errors, digits=2)} % "
              f"(paper: about {PAPER_NORMALISED_ERROR_PCT} %).", ""]
    deviation = _over_all_runs(rows, "max_path_deviation_m")
    lines += [f"Largest deviation of the object's centre from the planned path: {cell_text(deviation, digits=3)} m.",
              ""]
    return "\n".join(lines)


def write_caging_report(rows: Sequence[dict], out: Path) -> list[Path]:
    """tables.md and the box plots by cell, the paper's numbers (Tables 1-2, sec. 5) drawn on them."""

    out.mkdir(parents=True, exist_ok=True)
    tables = out / "tables.md"
    tables.write_text(caging_tables_md(rows))
    cells = [c.number for c in CELLS]
    labels = {STRATEGY: "ours"}
    marks = {m: level_marks(CAGING_CLAIMS, m) for m in ("search_time_s", "recruitment_time_s", "transport_time_s",
                                                         "planned_path_m", "trajectory_error_m")}
    text = "paper (Tables 1-2) and its ±25 % band"
    written = [tables]
    written.append(boxplot_figure(
        [("search_time_s", "search time [s]"), ("recruitment_time_s", "recruitment time [s]"),
         ("transport_time_s", "transport time [s]")], rows, cells, [STRATEGY], labels,
        "cell (see tables.md)", "Stage times by cell", out / "times.png", paper=marks, paper_text=text))
    written.append(boxplot_figure(
        [("planned_path_m", "planned path length [m]"), ("trajectory_error_m", "trajectory error [m]")], rows, cells,
        [STRATEGY], labels, "cell (see tables.md)", "Path length and error by cell (Table 2)", out / "path.png",
        paper=marks, paper_text=text))
    written.append(boxplot_figure(
        [("trajectory_error_pct", "trajectory error [% of the planned path]"),
         ("max_path_deviation_m", "largest deviation from the planned path [m]")], rows, cells, [STRATEGY], labels,
        "cell (see tables.md)", "Transport accuracy by cell", out / "error.png",
        references={"trajectory_error_pct": (PAPER_NORMALISED_ERROR_PCT,
                                             f"paper: around {PAPER_NORMALISED_ERROR_PCT} % (sec. 5)")}))
    return written


def _add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--cells", type=int, nargs="+", choices=[c.number for c in CELLS],
                        help="a subset of the cells: " + "; ".join(f"{c.number} = {c.name}" for c in CELLS))


def _plans(args: argparse.Namespace, strategies: list[str]) -> list[RunPlan]:
    return caging_plans(args.cells, args.duration, args.overrides)


def _write_report(rows: Sequence[dict], out: Path, args: argparse.Namespace, strategies: list[str]) -> list[Path]:
    return write_caging_report(rows, out)


def _claims(args: argparse.Namespace) -> tuple:
    return CAGING_CLAIMS


CAGING_COMPARISON = Comparison(
    name="caging",
    help="caging paper: Tables 1 and 2 (stage times, path error) over landmark step, swarm size and object",
    default_out="results/caging",
    strategies=(STRATEGY,),
    add_arguments=_add_arguments,
    plans=_plans,
    write_report=_write_report,
    claims=_claims,
)

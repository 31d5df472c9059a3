"""The caging paper's results as claims (`swarm_sim.compare.verdicts`): Table 1's four stage times,
Table 2's path length, error [m] and time of its five settings, sec. 5's "around 3.8 %" error, and
the step's effect on the stages (Table 1: the search faster with the coarser grid, the recruitment
independent of it).

Cells are `CELLS`' numbers. Table 2's rho = 8 row of case 1 and its (0.3 m, 0.3 kg) row of case 2 are
one run (cell 0): one claim each measure. Sec. 5's "average execution time is 247.5 s" is the mean of
Table 2's times, not a further number. The paper prints no spread and no run count: every band is
±25 %.
"""

from __future__ import annotations

from dataclasses import dataclass

from swarm_sim.compare.verdicts import LEVEL, MEASURED, OPEN, PARTIAL, TREND, Cause, Claim

STRATEGY = "caging"


@dataclass(frozen=True)
class Cell:
    number: int
    step: float
    """Landmark grid step [m]."""
    robots: int
    radius: float
    """r [m]."""
    mass: float
    """M [kg]."""

    @property
    def overrides(self) -> tuple[str, ...]:
        return (f"transport.landmarks.step={self.step}", f"robots.count={self.robots}",
                f"transport.object.radius={self.radius}", f"transport.object.mass={self.mass}")

    @property
    def name(self) -> str:
        return f"step {self.step:g} m, rho {self.robots}, r {self.radius:g} m, M {self.mass:g} kg"


CELLS: tuple[Cell, ...] = (
    Cell(0, 0.5, 8, 0.3, 0.3), Cell(1, 1.0, 8, 0.3, 0.3), Cell(2, 0.5, 6, 0.3, 0.3),
    Cell(3, 0.5, 7, 0.3, 0.3), Cell(4, 0.5, 8, 0.4, 0.7), Cell(5, 0.5, 8, 0.45, 1.0),
)

PAPER_TABLE1: dict[tuple[str, float], float] = {
    ("search_time_s", 0.5): 222.165, ("search_time_s", 1.0): 197.535,
    ("recruitment_time_s", 0.5): 164.481, ("recruitment_time_s", 1.0): 164.481,
}
"""THE PAPER'S Table 1: mean time [s] by stage and landmark step (rho not stated)."""
PAPER_TABLE2: dict[int, tuple[float, float, float]] = {
    2: (4.3284, 0.1778, 215.07), 3: (4.7426, 0.1894, 239.35), 0: (3.9142, 0.1526, 244.79),
    4: (4.3284, 0.1686, 282.47), 5: (4.7426, 0.1474, 258.62),
}
"""THE PAPER'S Table 2 by our cell: (path length [m], error [m], time [s]). The paper's rho = 8
row of case 1 and its (0.3, 0.3) row of case 2 are the same run."""
PAPER_NORMALISED_ERROR_PCT = 3.8
"""Sec. 5: "For all cases, the average error in the trajectory is around 3.8%"."""

_SEARCH = Cause(PARTIAL, "our searches end sooner than the paper's (102-130 s against 198-222 s at steps 1 and 0.5 "
                         "m). The swarm's distance from the object, read from Table 2's 7-step plans (robots start "
                         ">= 2.8 m from it, transport.swarm_distance=2.8; 20 seeds a cell) lengthens them by 13-35 s, "
                         "the same way in all five cells but not significantly in any (p 0.17-0.19; cell 0: 130 -> "
                         "160 s): what else makes ours shorter is not measured",
                "cagingdistance/distance_2.8", 20)
_PLAN = "cagingplan/plan_shortest"
_WALK = Cause(MEASURED, "the length of our recruiters' walks: with the plan a shortest grid path between the same two "
                        "ends (controller.caging.plan=shortest) the planned path is 3.2-3.6 m (default 15-22 m, the "
                        "paper 3.9-4.7 m) and the error 0.17-0.19 m (default 2.2-3.7 m, the paper 0.15-0.19 m); "
                        "ending at T_r*'s first landmark as Alg. 6's loop does (plan_search) takes off only 2.2-2.6 "
                        "m. The paper's plans are walks of 7 steps (CAUSES.md); ours are longer. With the robots "
                        "also starting as far from the object as Table 2's plans say (transport.swarm_distance=2.8, "
                        "cagingdistance/distance_2.8_shortest, 20 seeds) the plans are 4.1-4.4 m, every cell within "
                        "25 % of the paper's, errors 0.17-0.20 m",
              _PLAN, 20)
_PCT = Cause(MEASURED, "the length of our recruiters' walks (their corners): with a shortest grid path between the "
                       "same ends (controller.caging.plan=shortest) the error falls from 11.2 to 6.7 % of the plan; "
                       "what remains is about 0.12 m lost per run at the plan's ends (corners.md) over shorter plans",
             _PLAN, 20)
_ON_KHEPERA = " (switched on the Khepera III only, not on the generic robot)"


def _measured(cause: Cause) -> tuple[tuple[str, Cause], ...]:
    """A cause measured on the authors' robot: measured there, partial on the generic robot."""
    return ("authors", cause), ("generic", Cause(PARTIAL, cause.text + _ON_KHEPERA))


_TIME = Cause(PARTIAL, "Table 2's time is not our transport stage alone: sec. 5 ties it to 'the distance between the "
                       "swarm and the object at the moment that recruitment begins'. With 7-step-like plans "
                       "(plan_shortest, 20 seeds) our transport takes 29-39 s, our recruitment plus transport "
                       "154-211 s (the paper 215-282 s), with the robots also starting >= 2.8 m from the object "
                       "33-49 s and 159-219 s (cagingdistance); which stages the column counts is not switched")

TABLE2_MEASURES: tuple[tuple[str, int, str, str], ...] = (
    ("planned_path_m", 0, "m", "length"), ("trajectory_error_m", 1, "m", "error"), ("transport_time_s", 2, "s", "time"),
)
"""(our field, index in `PAPER_TABLE2`'s tuples, unit, the paper's column)."""


def _levels() -> list[Claim]:
    out = []
    for (metric, step), value in PAPER_TABLE1.items():
        cell = 0 if step == 0.5 else 1
        stage = "search" if metric == "search_time_s" else "recruitment"
        out.append(Claim(f"T1.{stage}.{step:g}", LEVEL, f"{stage} takes {value} s with a {step:g} m step", "Table 1",
                         metric, STRATEGY, (cell,), value=value, unit="s",
                         causes=(("*", _SEARCH if stage == "search" else Cause(OPEN, "not measured")),)))
    for cell, paper in sorted(PAPER_TABLE2.items()):
        c = CELLS[cell]
        for metric, index, unit, column in TABLE2_MEASURES:
            causes = (("*", _TIME),) if metric == "transport_time_s" else _measured(_WALK)
            out.append(Claim(f"T2.{column}.{cell}", LEVEL, f"{column} {paper[index]} {unit} ({c.name})", "Table 2",
                             metric, STRATEGY, (cell,), value=paper[index], unit=unit, causes=causes))
    out.append(Claim("error.pct", LEVEL, f"the error is around {PAPER_NORMALISED_ERROR_PCT} % of the path in all cases",
                     "Sec. 5", "trajectory_error_pct", STRATEGY, tuple(sorted(PAPER_TABLE2)), pooled=True,
                     value=PAPER_NORMALISED_ERROR_PCT, unit="%", causes=_measured(_PCT)))
    return out


def _step() -> list[Claim]:
    search = round(100 * (PAPER_TABLE1[("search_time_s", 1.0)] - PAPER_TABLE1[("search_time_s", 0.5)])
                   / PAPER_TABLE1[("search_time_s", 0.5)], 1)
    return [
        Claim("step.search", TREND, "the search is faster with a 1 m step than with 0.5 m", "Table 1, Sec. 5",
              "search_time_s", STRATEGY, (0, 1), sign=-1, size=search, unit="s", causes=(("*", _SEARCH),)),
        Claim("step.recruitment", TREND, "the recruitment does not depend on the step", "Table 1, Sec. 5",
              "recruitment_time_s", STRATEGY, (0, 1), sign=0, unit="s"),
    ]


CAGING_CLAIMS: tuple[Claim, ...] = (*_levels(), *_step())

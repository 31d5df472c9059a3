"""The DRTM paper's comparison (Pang et al. 2023, drtm_task_allocation.md): DRTM vs ARTM in the
comparison experiment (Sec. 3.1) and the four variations of Sec. 4, our runs next to the paper's
V_f, E_e, M_T, M_v, F_t and net food, the two-sample t-tests of Tables 2 and 4, and the net food
and OAEs over time of Figs. 5-6 (and 10-17).

A condition is a shipped scenario: ``drtm`` for Sec. 3.1 and one variation file per subsection
of Sec. 4; DRTM runs ``drtm.yaml``, ARTM ``artm.yaml``, each with the keys in which the
condition's file differs from ``drtm.yaml`` as overrides, so a condition is written down once.
"""

from __future__ import annotations

import argparse
import json
import math
from collections.abc import Sequence
from pathlib import Path
from typing import Any

from swarm_controllers.drtm.claims import (
    DRTM_CLAIMS,
    DRTM_CONDITIONS,
    DRTM_LABELS,
    DRTM_METRICS,
    DRTM_STRATEGIES,
    PAPER,
    PAPER_TTESTS,
    Condition,
)
from swarm_controllers.drtm.config import NestConfig
from swarm_sim.compare.comparison import Comparison
from swarm_sim.compare.report import cell_text, fmt, fmt_p, md_table, save_figure
from swarm_sim.compare.stats import describe, mean_series, pair_test, stars, values_of
from swarm_sim.compare.sweep import RunPlan, frozen_fields
from swarm_sim.compare.verdicts import level_marks
from swarm_sim.scenario import load_scenario, scenario_to_dict

SERIES: dict[str, str] = {
    "nest_food_series": "net food in the nest F(t) [tokens]",
    "oae_series": "obstacle-avoidance events so far",
    "active_robots_series": "robots foraging (N_r - N_W)",
}


def condition_overrides(condition: Condition) -> tuple[str, ...]:
    """``key=value`` overrides that turn ``drtm.yaml`` into the condition's scenario (every leaf
    in which the two files differ, but the name and the behaviour). Both are compared on the
    generic robot, whose values are the files' own: a platform model derives some (the foot-bot's
    light range is the arena's diagonal), and those must not become overrides of another model."""
    def leaves(data: Any, prefix: str = "") -> dict[str, Any]:
        if isinstance(data, dict):
            return {k: v for key, value in data.items() for k, v in leaves(value, f"{prefix}{key}.").items()}
        return {prefix[:-1]: data}

    base = leaves(scenario_to_dict(load_scenario("drtm", ["robots.model=generic"])))
    mine = leaves(scenario_to_dict(load_scenario(condition.scenario, ["robots.model=generic"])))
    skip = {"name", "controller.behaviour"}
    return tuple(f"{k}={json.dumps(v)}" for k, v in sorted(mine.items()) if k not in skip and base.get(k) != v)


def drtm_plans(conditions: Sequence[int], strategies: Sequence[str] = DRTM_STRATEGIES, *,
               duration: float | None = None, overrides: Sequence[str] = ()) -> list[RunPlan]:
    """Both models in every condition (conditions outer, so a cut sweep has whole conditions)."""
    fields = frozen_fields({"sim__duration": duration})
    plans = []
    for cell in conditions:
        c = DRTM_CONDITIONS[cell]
        own = condition_overrides(c)
        plans.extend(RunPlan(s, cell, (*own, *overrides), fields, (("condition", c.section),)) for s in strategies)
    return plans


def _paper_value(section: str, strategy: str, metric: str) -> float | None:
    return PAPER.get(section, {}).get(strategy, {}).get(metric)


def _ours(rows: Sequence[dict], strategy: str, cell: int, metric: str) -> list[float]:
    return [v * DRTM_METRICS[metric][2] for v in values_of(rows, strategy, cell, metric)]


def drtm_table_md(rows: Sequence[dict], conditions: Sequence[int], strategies: Sequence[str]) -> str:
    """table.md: per condition, every measure of Sec. 2.4 for both models, ours next to the paper's,
    and whether DRTM vs ARTM goes the paper's way."""
    lines = ["# DRTM paper comparison (Pang et al. 2023): tables", "",
             "`ours` = this simulator, mean ± sample std (n runs); `paper` = **the paper's numbers** (ARGoS, "
             "50 runs), hard-coded reference data. E_e in %. `same way` says whether DRTM vs ARTM differ in "
             "the paper's direction (better for DRTM: lower V_f, M_T, M_v; higher E_e, F(T)).", ""]
    for cell in conditions:
        c = DRTM_CONDITIONS[cell]
        lines += [f"## Sec. {c.section}: {c.what} (scenario `{c.scenario}`)", ""]
        header = ["measure"] + [f"{DRTM_LABELS[s]} {w}" for s in strategies for w in ("ours", "paper")]
        if set(strategies) == set(DRTM_STRATEGIES):
            header.append("same way")
        body = []
        for metric, (symbol, meaning, _) in DRTM_METRICS.items():
            row = [f"{symbol}: {meaning}"]
            means = {}
            for s in strategies:
                st = describe(_ours(rows, s, cell, metric))
                means[s] = st.mean
                row += [cell_text(st), fmt(_paper_value(c.section, s, metric))]
            if len(header) > 1 + 2 * len(strategies):
                paper = [_paper_value(c.section, s, metric) for s in DRTM_STRATEGIES]
                ours = [means[s] for s in DRTM_STRATEGIES]
                if None in paper or not all(math.isfinite(x) for x in ours) or metric == "food_collected":
                    row.append("—")  # the paper has F_t higher for ARTM in 3 of 5 conditions: no direction
                else:
                    row.append("yes" if (ours[0] < ours[1]) == (paper[0] < paper[1]) else "no")
            body.append(row)
        lines += md_table(header, body) + [""]
        if set(strategies) == set(DRTM_STRATEGIES):
            lines += [_efficiency_split(rows, cell, c.section), ""]
    return "\n".join(lines)


def _efficiency_split(rows: Sequence[dict], cell: int, section: str) -> str:
    """E_e = F(T) / F_t (eq. (9)), so DRTM's E_e over ARTM's is the product of two ratios of the
    means: F(T)'s and F_t's inverse. Which of the two carries the gap says whether E_e differs
    for the food left in the nest at T or for the energy the swarm spent (F_t = F(T) - F(0) +
    everything consumed)."""
    def split(final: dict[str, float], collected: dict[str, float]) -> str:
        f, e = final["drtm"] / final["artm"], collected["artm"] / collected["drtm"]
        text = f"F(T) x{f:.2f}, 1 / F_t x{e:.2f}"
        if all(math.isfinite(v) and v > 0 for v in (f, e)) and (f - 1) * (e - 1) > 0:
            text += f" (F(T) carries {100 * math.log(f) / math.log(f * e):.0f} % of it)"
        return text

    measures = ("nest_food_final", "food_collected")
    ours = {m: {s: describe(_ours(rows, s, cell, m)).mean for s in DRTM_STRATEGIES} for m in measures}
    paper = {m: {s: _paper_value(section, s, m) for s in DRTM_STRATEGIES} for m in measures}
    line = f"E_e = F(T) / F_t, so DRTM's E_e over ARTM's is, on the means: ours {split(*ours.values())}"
    if all(v for d in paper.values() for v in d.values()):
        line += f"; paper {split(*paper.values())}"
    return line + "."


def drtm_ttests_md(rows: Sequence[dict], conditions: Sequence[int]) -> str:
    """ttests.md: Tables 2 and 4, two-sample t-tests (scipy ttest_ind, equal variances) of DRTM
    against ARTM on F_t and M_T, ours next to the paper's."""
    lines = ["# DRTM paper comparison: two-sample t-tests on F_t and M_T (Tables 2 and 4)", "",
             "scipy.stats.ttest_ind(DRTM, ARTM), equal variances, two-sided, as the paper (50 + 50 runs, 98 "
             "d.o.f.). Our t is signed (negative: DRTM's mean is lower); the paper's t are all positive and "
             "it gives no sign convention. `significant`: *** p<0.001, ** p<0.01, * p<0.05, else no.", ""]
    body = []
    for cell in conditions:
        c = DRTM_CONDITIONS[cell]
        for metric in ("food_collected", "oae_total"):
            a, b = values_of(rows, "drtm", cell, metric), values_of(rows, "artm", cell, metric)
            t, p = pair_test(a, b, "t")
            paper_t, paper_p = PAPER_TTESTS[c.section][metric]
            body.append([f"{c.section}" + (f" (Table 4: {c.table4})" if c.table4 else " (Table 2)"),
                         DRTM_METRICS[metric][0], cell_text(describe(a)), cell_text(describe(b)),
                         f"{len(a) + len(b) - 2}", fmt(t, 3), fmt_p(p), stars(p, "no"),
                         fmt(paper_t, 4), fmt_p(paper_p)])
    lines += md_table(["Sec.", "compare", "DRTM ours", "ARTM ours", "d.o.f.", "t ours", "p ours", "significant",
                       "t paper", "p paper"], body) + [""]
    return "\n".join(lines)


def series_figure(rows: Sequence[dict], conditions: Sequence[int], strategies: Sequence[str], key: str,
                  path: Path, desired: dict[int, float] | None = None,
                  paper: tuple[str, dict] | None = None) -> Path:
    """One panel per condition: the mean of `key` over the seeds with a ±1 std band, one colour
    per model, F_d dashed where given (Figs. 5-6, 10-17); `paper`: (name, (strategy, cell) ->
    (band low, value, band high)) of the paper's number at the run's end (M_T, F(T)), drawn as a
    diamond with its band in the model's colour at the last time."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, len(conditions), figsize=(4.2 * len(conditions), 3.6), squeeze=False, sharey=True)
    for ax, cell in zip(axes[0], conditions):
        c = DRTM_CONDITIONS[cell]
        for j, s in enumerate(strategies):
            t, mean, std = mean_series(rows, s, cell, key)
            if len(t):
                n = sum(1 for r in rows if r.get("strategy") == s and r.get("cell") == cell and r.get(key))
                ax.plot(t / 60.0, mean, color=f"C{j}", label=f"{DRTM_LABELS.get(s, s)} (n={n})")
                ax.fill_between(t / 60.0, mean - std, mean + std, color=f"C{j}", alpha=0.2)
        if desired and cell in desired:
            ax.axhline(desired[cell], color="black", linestyle="--", linewidth=1, label="F_d")
        end = max((t for r in rows if r.get("cell") == cell for t, _ in (r.get(key) or [])[-1:]), default=None)
        for j, s in enumerate(strategies):
            mark = paper[1].get((s, cell)) if paper and end is not None else None
            if mark:
                lo, value, hi = mark
                x = end / 60.0 + 0.4 * j  # the models side by side at the end
                ax.plot([x] * 2, [lo, hi], color=f"C{j}", lw=1.5, alpha=0.8)
                ax.plot([x], [value], marker="D", markersize=6, color=f"C{j}", markeredgecolor="black",
                        ls="none", label=f"paper {paper[0]} ({DRTM_LABELS.get(s, s)}) ±25 %")
        ax.set(title=f"Sec. {c.section}: {c.what.split(' (')[0]}", xlabel="time [min]")
        ax.grid(alpha=0.3)
        ax.legend(fontsize="small")
    axes[0][0].set_ylabel(SERIES[key])
    fig.tight_layout()
    save_figure(fig, path)
    plt.close(fig)
    return path


def write_drtm_report(rows: Sequence[dict], out: Path, conditions: Sequence[int] | None = None,
                      strategies: Sequence[str] = DRTM_STRATEGIES) -> list[Path]:
    """table.md, ttests.md and the time-series figures from result rows."""
    conditions = sorted({r["cell"] for r in rows if r.get("cell") is not None}) if conditions is None else conditions
    out.mkdir(parents=True, exist_ok=True)
    written = [out / "table.md", out / "ttests.md"]
    written[0].write_text(drtm_table_md(rows, conditions, strategies))
    written[1].write_text(drtm_ttests_md(rows, conditions))
    desired = {c: NestConfig.of(load_scenario(DRTM_CONDITIONS[c].scenario)).desired_food for c in conditions}

    paper = {"nest_food_series": ("F(T)", level_marks(DRTM_CLAIMS, "nest_food_final")),
             "oae_series": ("M_T", level_marks(DRTM_CLAIMS, "oae_total"))}
    for name, key in (("food.png", "nest_food_series"), ("oae.png", "oae_series"),
                      ("active.png", "active_robots_series")):
        written.append(series_figure(rows, conditions, strategies, key, out / name,
                                     desired if key == "nest_food_series" else None, paper.get(key)))
    return written


def _sections(text: Sequence[str] | None) -> list[int]:
    known = [c.section for c in DRTM_CONDITIONS]
    if not text:
        return list(range(len(known)))
    unknown = [s for s in text if s not in known]
    if unknown:
        raise SystemExit(f"swarm-compare drtm: unknown condition {unknown[0]!r} (known: {', '.join(known)})")
    return [known.index(s) for s in known if s in text]


def _add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--conditions", nargs="+", metavar="SEC",
                        help="sections to run (default all: " + " ".join(c.section for c in DRTM_CONDITIONS) + ")")


def _plans(args: argparse.Namespace, strategies: list[str]) -> list[RunPlan]:
    return drtm_plans(_sections(args.conditions), strategies, duration=args.duration, overrides=args.overrides)


def _write_report(rows: Sequence[dict], out: Path, args: argparse.Namespace, strategies: list[str]) -> list[Path]:
    return write_drtm_report(rows, out, _sections(args.conditions), strategies)


def _claims(args: argparse.Namespace) -> tuple:
    return DRTM_CLAIMS


DRTM_COMPARISON = Comparison(
    name="drtm",
    help="DRTM paper: DRTM vs ARTM in Secs. 3.1 and 4.1-4.4, tables, t-tests (Tables 2, 4), Figs. 5-6",
    default_out="results/drtm",
    strategies=DRTM_STRATEGIES,
    add_arguments=_add_arguments,
    plans=_plans,
    write_report=_write_report,
    claims=_claims,
)

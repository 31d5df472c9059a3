"""Our ``drtm_example`` runs against the ARGoS foraging example run here (``drtm_argos.py``): the
same rule on both sides, so what differs is the robot, the world and our port.

Prints a markdown table (CAUSES.md, DRTM): each of the DRTM paper's measures plus the robots
foraging, ARGoS's runs (each range-and-bearing setting) beside ours, judged on REPORT's scale for
a level against the authors' code (`swarm_sim.compare.reference.against_reference`: our mean within
±25 % of theirs, Welch's two one-sided tests, Holm over the table's cells).
"""
from __future__ import annotations

import argparse
import json
import math
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))  # our package
from swarm_sim.compare.reference import against_reference  # noqa: E402
from swarm_sim.compare.verdicts import ALPHA, CONTRADICTS, HOLDS, LEVEL, NOT_SHOWN, Claim, holm  # noqa: E402

MEASURES = (("food_collected", "F_t [tokens]", 1.0), ("oae_total", "M_T [events]", 1.0),
            ("oae_per_robot", "M_v [events/robot]", 1.0), ("food_deviation", "V_f [tokens]", 1.0),
            ("energy_efficiency", "E_e [%]", 100.0), ("nest_food_final", "F(T) [tokens]", 1.0),
            ("robots_foraging", "robots foraging (mean over t)", 1.0))


def value(row: dict, measure: str, scale: float) -> float:
    """A row's measure; robots foraging is the mean of its 5-s series (both sides sample it alike)."""
    if measure == "robots_foraging":
        series = row["active_robots_series"]
        return sum(v for _, v in series) / len(series)
    return float(row[measure]) * scale


def table(ours: list[dict], reference: dict[str, list[dict]]) -> list[str]:
    """The markdown lines: one row per measure, a column per reference setting, ours, and ours
    against the setting named last."""
    names = list(reference)
    judged = names[-1]
    cells = []
    for measure, label, scale in MEASURES:
        mine = [value(r, measure, scale) for r in ours]
        theirs = [value(r, measure, scale) for r in reference[judged]]
        # against_reference reads a claim only for its bootstrap's seed (its id); value is unused
        claim = Claim(f"drtm_example.{measure}", LEVEL, label, "reference", measure, "foraging_example", value=0.0)
        cells.append((label, measure, scale, mine, against_reference(claim, mine, theirs, 0)))
    adjusted = holm([cv.p for *_, cv in cells])
    out = [f"| measure | {' | '.join(f'ARGoS, {n} ({len(reference[n])} runs)' for n in names)} | "
           f"ours ({len(ours)} runs) | ours vs ARGoS, {judged} [95 % CI] | verdict |",
           "|---|" + "---|" * (len(names) + 3)]
    for (label, measure, scale, mine, cv), p in zip(cells, adjusted):
        refs = [_fmt([value(r, measure, scale) for r in reference[n]]) for n in names]
        verdict = (HOLDS if cv.reason == "inside" else CONTRADICTS) if p < ALPHA else NOT_SHOWN
        ci = f"[{cv.ci[0]:+.0f}, {cv.ci[1]:+.0f}]" if all(map(math.isfinite, cv.ci)) else ""
        out.append(f"| {label} | {' | '.join(refs)} | {_fmt(mine)} | {cv.effect:+.1f} % {ci}, p = {p:.2g} | "
                   f"{verdict} |")
    return out


PANELS = (("active_robots_series", "robots foraging"), ("nest_food_series", "F(t) [tokens]"),
          ("oae_series", "OAEs so far [events]"))


def figure(ours: list[dict], reference: dict[str, list[dict]], path: Path) -> None:
    """Time series, mean and one standard deviation over runs (each series every 5 s): robots
    foraging, F(t) and OAEs so far; ARGoS's settings beside ours."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import numpy as np

    fig, axes = plt.subplots(1, len(PANELS), figsize=(15, 4.2))
    runs = [*(f"ARGoS, {n}" for n in reference), "ours"]
    styles = {"ARGoS, occlusions on": ("0.55", "--"), "ARGoS, occlusions off": ("tab:blue", "-"),
              "ours": ("tab:orange", "-")}
    for ax, (key, label) in zip(axes, PANELS):
        for name, rows in zip(runs, [*reference.values(), ours]):
            n = min(len(r[key]) for r in rows)
            t = np.array([p[0] for p in rows[0][key][:n]])
            y = np.array([[p[1] for p in r[key][:n]] for r in rows], dtype=float)
            colour, line = styles.get(name, ("k", ":"))
            ax.plot(t, y.mean(axis=0), color=colour, linestyle=line, label=f"{name} ({len(rows)} runs)")
            ax.fill_between(t, y.mean(axis=0) - y.std(axis=0), y.mean(axis=0) + y.std(axis=0), color=colour,
                            alpha=0.15, linewidth=0)
        ax.set(xlabel="t [s]", ylabel=label, xlim=(0, None))
        ax.grid(alpha=0.3)
    axes[0].legend(loc="lower right", fontsize=8)
    fig.suptitle("The ARGoS foraging example's rule in the DRTM paper's arena (Sec. 3.1): ARGoS against ours "
                 "(mean ± sd)", fontsize=10)
    fig.tight_layout()
    fig.savefig(path, dpi=100)
    plt.close(fig)


def _fmt(xs: list[float]) -> str:
    mean = sum(xs) / len(xs)
    sd = math.sqrt(sum((x - mean) ** 2 for x in xs) / (len(xs) - 1)) if len(xs) > 1 else 0.0
    return f"{mean:.0f} ± {sd:.0f}" if abs(mean) >= 100 else f"{mean:.3g} ± {sd:.2g}"


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--ours", type=Path, default=Path("results/authors/drtm_example/results.jsonl"))
    p.add_argument("--reference", type=Path, default=Path("results/reference/drtm_example/results.jsonl"))
    p.add_argument("--figure", type=Path, help="also draw the time series to this PNG")
    a = p.parse_args(argv)
    try:
        ours = [json.loads(line) for line in a.ours.read_text().splitlines() if line.strip()]
        reference: dict[str, list[dict]] = {}
        for line in a.reference.read_text().splitlines():
            if line.strip():
                r = json.loads(line)
                occluded = json.loads(r["settings"])["rab_occlusions"]
                reference.setdefault("occlusions on" if occluded else "occlusions off", []).append(r)
        if not ours or not reference:
            raise ValueError("no runs to compare")
        reference = dict(sorted(reference.items(), reverse=True))
        print("\n".join(table(ours, reference)))
        if a.figure:
            figure(ours, reference, a.figure)
    except (OSError, ValueError, KeyError) as e:
        print(f"drtm_versus: {e}", file=sys.stderr)
        return 2
    return 0


if __name__ == "__main__":
    sys.exit(main())

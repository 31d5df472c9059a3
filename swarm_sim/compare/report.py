"""Report building blocks shared by the paper comparisons: number formatting, markdown tables,
grouped box plots, the line under every figure that says which robots ran (`caption`), and the
authors' code's runs drawn beside our boxes (`reference_runs`)."""

from __future__ import annotations

import json
import math
import warnings
from collections.abc import Callable, Iterable, Iterator, Sequence
from contextlib import contextmanager
from contextvars import ContextVar
from pathlib import Path
from typing import Any

import numpy as np

from swarm_sim.compare.stats import Stats, values_of
from swarm_sim.compare.verdicts import ALPHA, t_ppf


def fmt(x: Any, digits: int = 2) -> str:
    """`x` with `digits` decimals; ``—`` for missing or non-finite values."""
    if x is None or (isinstance(x, float) and not math.isfinite(x)):
        return "—"
    return f"{x:.{digits}f}"


def fmt_p(p: float) -> str:
    """A p-value: scientific below 0.001, else four decimals; ``n/a`` when the test could not run."""
    if not math.isfinite(p):
        return "n/a"
    return f"{p:.2e}" if p < 0.001 else f"{p:.4f}"


def note_cut_runs(paths: Sequence[Path], duration: float | None) -> None:
    """Say at the top of each markdown report that its runs were cut to `duration` sim seconds
    by ``--duration`` (None: the paper's run lengths, nothing to say)."""
    if duration is None:
        return
    note = (f"> **Runs cut short**: every run here was limited to {duration:g} s of sim time by "
            "`--duration`, not the paper's run length; its numbers are not the paper's conditions.\n\n")
    for path in paths:
        if path.suffix == ".md" and path.is_file():
            path.write_text(note + path.read_text())


def fmt_pct(x: float) -> str:
    """A signed percentage change (``+12.3 %``)."""
    return "—" if not math.isfinite(x) else f"{x:+.1f} %"


def cell_text(s: Stats, digits: int = 2, median: bool = False) -> str:
    """``mean ± std (n=…)``, with the median when asked; ``—`` without data."""
    if s.n == 0:
        return "—"
    text = f"{fmt(s.mean, digits)} ± {fmt(s.std, digits)}"
    return f"{text} (median {fmt(s.median, digits)}, n={s.n})" if median else f"{text} (n={s.n})"


def md_table(header: Sequence[str], body: Iterable[Sequence[str]]) -> list[str]:
    """Lines of a markdown table."""
    lines = ["| " + " | ".join(header) + " |", "|" + "|".join("---" for _ in header) + "|"]
    lines += ["| " + " | ".join(row) + " |" for row in body]
    return lines


def label(strategy: str, labels: dict[str, str]) -> str:
    """The paper's name for a strategy, or its scenario name when the paper has none."""
    return labels.get(strategy, strategy)


def grouped_boxplot(
    ax: Any,
    rows: Sequence[dict],
    metric: str,
    cells: Sequence[int],
    strategies: Sequence[str],
    labels: dict[str, str],
    *,
    notch: bool = False,
) -> None:
    """Boxes grouped by cell (x axis), one colour per strategy, as in both papers' figures."""
    from matplotlib.patches import Patch

    colours = [f"C{i}" for i in range(len(strategies))]
    width = 0.8 / max(len(strategies), 1)
    for j, (s, colour) in enumerate(zip(strategies, colours)):
        data, pos = [], []
        for i, cell in enumerate(cells):
            v = values_of(rows, s, cell, metric)
            if v:
                data.append(v)
                pos.append(i - 0.4 + width * (j + 0.5))
        if data:
            box = ax.boxplot(data, positions=pos, widths=width * 0.85, notch=notch, patch_artist=True,
                             manage_ticks=False, flierprops={"markersize": 3},
                             medianprops={"color": "black"})
            for patch in box["boxes"]:
                patch.set(facecolor=colour, alpha=0.6)
    ax.set_xticks(range(len(cells)), [str(c) for c in cells])
    ax.set_xlim(-0.6, len(cells) - 0.4)
    ax.legend(handles=[Patch(facecolor=c, alpha=0.6, label=label(s, labels)) for s, c in zip(strategies, colours)],
              fontsize="small")
    ax.grid(axis="y", alpha=0.3)


PaperMarks = dict[tuple[str, Any], tuple[float, float, float]]
"""(strategy, cell) -> (low, value, high) of a paper's number: its band, drawn at that box."""
PAPER_LABEL = "paper"
REFERENCE_LABEL = "authors' code here"
"""The authors' own code run on this machine (`swarm_sim.compare.reference`)."""


def paper_marks(ax: Any, marks: PaperMarks, cells: Sequence[Any], strategies: Sequence[str],
                text: str = PAPER_LABEL) -> Any:
    """The paper's numbers on a `grouped_boxplot`: a black diamond beside each (strategy, cell) box
    with an error bar over its band (a stated range, or the ±25 % a verdict allows); returns the
    legend handle."""
    width = 0.8 / max(len(strategies), 1)
    handle = None
    for (s, cell), (lo, mid, hi) in marks.items():
        if s not in strategies or cell not in cells:
            continue
        x = cells.index(cell) - 0.4 + width * (strategies.index(s) + 0.85)  # beside its box, not on its whiskers
        handle = ax.errorbar([x], [mid], yerr=[[mid - lo], [hi - mid]], fmt="D", color="black", markersize=4,
                             capsize=3, elinewidth=1.0, zorder=6, label=text)
    return handle


def reference_marks(reference: Sequence[dict], metric: str, strategies: Sequence[str], cells: Sequence[object]
                    ) -> dict[tuple[str, object], tuple[float, float, float, int]]:
    """(strategy, cell) -> (low, mean, high, n) of the authors' code's runs of `metric`: the mean with
    its 95 % t interval (low = high = mean for a single run), for a figure beside our box; a run of
    cell None serves every cell (a strategy without the cells' factor, as in `values_of`)."""
    out = {}
    for s in strategies:
        for cell in cells:
            v = [float(r[metric]) for r in reference if r.get("strategy") == s and r.get("cell") in (cell, None)
                 and isinstance(r.get(metric), (int, float)) and math.isfinite(float(r[metric]))]
            if not v:
                continue
            mean = float(np.mean(v))
            half = 0.0 if len(v) < 2 else t_ppf(1 - ALPHA / 2, len(v) - 1) * float(np.std(v, ddof=1)) / math.sqrt(len(v))
            out[(s, cell)] = (mean - half, mean, mean + half, len(v))
    return out


def code_marks(ax: Any, reference: Sequence[dict], metric: str, cells: Sequence[Any],
               strategies: Sequence[str]) -> Any:
    """The authors' code's runs on a `grouped_boxplot`: a hollow square at their mean with its 95 %
    interval, on the other side of each box from the paper's diamond; returns the legend handle."""
    width = 0.8 / max(len(strategies), 1)
    handle = None
    for (s, cell), (lo, mid, hi, n) in reference_marks(reference, metric, strategies, cells).items():
        x = cells.index(cell) - 0.4 + width * (strategies.index(s) + 0.15)
        handle = ax.errorbar([x], [mid], yerr=[[mid - lo], [hi - mid]], fmt="s", color="0.25", mfc="white",
                             markersize=4.5, capsize=3, elinewidth=1.0, zorder=6, label=REFERENCE_LABEL)
    return handle


_REFERENCE: ContextVar[Sequence[dict]] = ContextVar("reference", default=())


@contextmanager
def reference_runs(rows: Sequence[dict]) -> Iterator[None]:
    """Every `boxplot_figure` drawn inside this block shows `rows`, the authors' code's runs of the
    same strategies and cells (`code_marks`), beside ours and the paper's."""
    token = _REFERENCE.set(rows)
    try:
        yield
    finally:
        _REFERENCE.reset(token)


def reference_rows() -> Sequence[dict]:
    """The authors' code's runs of the current `reference_runs` block (none outside one), for a
    comparison that derives its figures' fields from its rows (a unit) on theirs too."""
    return _REFERENCE.get()


def boxplot_figure(
    panels: Sequence[tuple[str, str]],
    rows: Sequence[dict],
    cells: Sequence[int],
    strategies: Sequence[str],
    labels: dict[str, str],
    xlabel: str,
    title: str,
    path: Path,
    notch: bool = False,
    references: dict[str, tuple[float, str]] | None = None,
    paper: dict[str, PaperMarks] | None = None,
    paper_text: str = PAPER_LABEL,
) -> Path:
    """A PNG at `path` with one `grouped_boxplot` per (metric, y label) panel, side by side;
    `references`: metric -> (value, label) of a paper's single number, drawn across its panel;
    `paper`: metric -> the paper's numbers per box (`paper_marks`, labelled `paper_text`); the
    authors' code's runs of `reference_runs`, if any, beside each box (`code_marks`)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, len(panels), figsize=(6.5 * len(panels), 4.5), squeeze=False)
    legend: dict[str, Any] = {}  # label -> handle, over every panel
    for ax, (metric, ylabel) in zip(axes[0], panels):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")  # notches wider than the box with few runs
            grouped_boxplot(ax, rows, metric, cells, strategies, labels, notch=notch)
        ax.set(xlabel=xlabel, ylabel=ylabel)
        extra = []
        if references and metric in references:
            value, text = references[metric]
            extra.append(ax.axhline(value, color="black", ls="--", lw=1.0, label=text))
        if paper and metric in paper:
            handle = paper_marks(ax, paper[metric], list(cells), list(strategies), paper_text)
            extra += [handle] if handle else []
        handle = code_marks(ax, _REFERENCE.get(), metric, list(cells), list(strategies))
        extra += [handle] if handle else []
        boxes = ax.get_legend()  # grouped_boxplot's strategies, then the paper's and the authors' marks
        for handle in [*(boxes.legend_handles if boxes else []), *extra]:
            legend.setdefault(handle.get_label(), handle)
        if boxes:
            boxes.remove()
    fig.suptitle(title)
    # One legend for the figure, under the panels: inside an axes, it hid the first cells' boxes.
    ncol = min(len(legend), 3 * len(panels))
    rows = -(-len(legend) // max(ncol, 1))
    if legend:
        # Anchored in figure coordinates: anchored to the figure's box, a tight save (`save_figure`
        # with a caption) would move it down onto the caption.
        fig.legend(handles=list(legend.values()), fontsize="small", loc="lower center", ncol=ncol, frameon=False,
                   bbox_to_anchor=(0.5, 0.0), bbox_transform=fig.transFigure)
    fig.tight_layout(rect=(0, 0.07 * rows, 1, 1))
    save_figure(fig, path, dpi=110)
    plt.close(fig)
    return path


_CAPTION: ContextVar[str] = ContextVar("caption", default="")


@contextmanager
def caption(text: str) -> Iterator[None]:
    """Every figure `save_figure` writes inside this block carries `text` under it."""
    token = _CAPTION.set(text)
    try:
        yield
    finally:
        _CAPTION.reset(token)


def save_figure(fig: Any, path: Path, dpi: int = 100) -> None:
    """`fig` as a PNG at `path`, with the current `caption` (if any) as a small line under it: a
    printed box plot says which robot made it."""
    text = _CAPTION.get()
    if text:
        from matplotlib.transforms import offset_copy

        # Just below the figure (a legend under the panels reaches down to its bottom edge).
        fig.text(0.005, 0.0, text, fontsize=7, color="0.3", ha="left", va="top",
                 transform=offset_copy(fig.transFigure, fig=fig, y=-4, units="points"))
    fig.savefig(path, dpi=dpi, bbox_inches="tight" if text else None, pad_inches=0.08)


def runs_caption(rows: Sequence[dict], overrides: Sequence[str], model_of: Callable[[Any], str]) -> str:
    """"robot: <model>[, ...]; --set ..." for a sweep's `rows`: the model each run's settings name
    (``robots.model=``) or else its scenario's own (`model_of(strategy)`), and the sweep's ``--set``
    `overrides`."""
    models = set()
    for r in rows:
        try:
            given = json.loads(r.get("settings") or "{}").get("overrides", [])
        except (ValueError, AttributeError):
            given = []
        named = [o.split("=", 1)[1] for o in given if isinstance(o, str) and o.startswith("robots.model=")]
        models.add(named[-1] if named else model_of(r.get("strategy")))
    text = "robot: " + ", ".join(sorted(str(m) for m in models))
    if overrides:
        text += "; --set " + " ".join(overrides)
    return text

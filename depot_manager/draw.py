"""Draw a queue layout to PNG for checking by eye against the paper's Figs. 3, 4, 6 and 7.

    python -m depot_manager.draw --layout single|multi --out FILE.png
"""

from __future__ import annotations

import argparse
import math
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
from matplotlib.patches import Circle  # noqa: E402

from depot_manager.geometry import (  # noqa: E402
    DepotGeometryConfig,
    QueueLayout,
    make_layout,
)

_ENTRY_COLOURS = ("tab:orange", "tab:green", "tab:purple", "tab:brown", "tab:pink", "tab:olive")


def draw_on(ax, layout: QueueLayout, *, detail: bool = True) -> None:
    """The layout on a matplotlib axis [m], each kind of part labelled once for a legend: the
    depot (black), the perimeter (red), the inner region (purple, dashed), the entry lines (one
    colour each) and their slots, the exit lines (blue), the inner queues (cyan), the docks
    (green squares, numbered), the entry (black) and exit (blue) points. `detail` adds the
    sectors' borders and the lines' crossings (the paper's figures); without it the layout is
    drawn lighter, under a run's trajectories."""
    cfg = layout.config
    cx, cy = cfg.depot_center
    alpha = 1.0 if detail else 0.55
    ax.add_patch(Circle((cx, cy), cfg.depot_radius, color="black", zorder=1, alpha=alpha, label="depot"))
    ax.add_patch(Circle((cx, cy), cfg.perimeter_radius, fill=False, color="red", lw=2 if detail else 1,
                        label="perimeter", alpha=alpha))
    ax.add_patch(Circle((cx, cy), layout.inner_radius, fill=False, color="purple", lw=1.5 if detail else 0.8,
                        ls="--", label="inner region", alpha=alpha))
    if detail:
        for a, _ in layout.sectors:
            r = cfg.perimeter_radius
            ax.plot([cx + cfg.depot_radius * math.cos(a), cx + r * math.cos(a)],
                    [cy + cfg.depot_radius * math.sin(a), cy + r * math.sin(a)], color="grey", lw=0.8, ls=":")
    pitch = cfg.pitch
    slot_size = (72 * 8 / 4.6 * cfg.robot_diameter) ** 2 / 4 if detail else 4
    for i, ln in enumerate(layout.entry_lines):
        col = _ENTRY_COLOURS[i % len(_ENTRY_COLOURS)]
        ax.plot(ln.points[:, 0], ln.points[:, 1], color=col, lw=1.2, label=ln.name.replace("_", " "), alpha=alpha)
        sl = ln.slots(pitch)
        ax.scatter(sl[:, 0], sl[:, 1], s=slot_size, facecolors="none", edgecolors=col, lw=0.5, alpha=alpha)
    for k, ln in enumerate(layout.exit_lines):
        ax.plot(ln.points[:, 0], ln.points[:, 1], color="tab:blue", lw=1.5, alpha=alpha,
                label="exit lines" if k == 0 else None)
        sl = ln.slots(pitch)
        ax.scatter(sl[:, 0], sl[:, 1], s=6 if detail else 2, color="tab:blue", alpha=alpha)
    for k, ln in enumerate(layout.inner_queues):
        ax.plot(ln.points[:, 0], ln.points[:, 1], color="tab:cyan", lw=1.0, alpha=0.8 * alpha,
                label="inner queues" if k == 0 else None)
    for k, d in enumerate(layout.docks):
        ax.scatter(*d.position, marker="s", s=80 if detail else 30, color="limegreen", edgecolors="k", zorder=5,
                   label="docks" if k == 0 else None)
        if detail:
            ax.annotate(str(d.index), d.position, color="white", ha="center", va="center", fontsize=7, zorder=6)
    if detail:
        for c in layout.crossings:
            ax.scatter(*c.point, marker="x", s=30, color="magenta", zorder=6)
    ep, xp = layout.entry_points, layout.exit_points
    ax.scatter(ep[:, 0], ep[:, 1], s=70 if detail else 20, color="black", zorder=7, label="entry point")
    ax.scatter(xp[:, 0], xp[:, 1], s=70 if detail else 20, color="blue", zorder=7, label="exit point")
    if layout.inner_entry_point is not None:
        ax.scatter(*layout.inner_entry_point, s=50 if detail else 15, color="black", zorder=7)
        ax.scatter(*layout.inner_exit_point, s=50 if detail else 15, color="blue", zorder=7)


def draw_layout(layout: QueueLayout, path_png: str | Path) -> Path:
    """The layout alone (`draw_on` in full detail), titled with its numbers, as a PNG."""
    cfg = layout.config
    cx, cy = cfg.depot_center
    fig, ax = plt.subplots(figsize=(8, 8))
    draw_on(ax, layout)
    ax.set_title(
        f"{layout.kind}-queue wrapping: K={cfg.docks}, lane {cfg.lane_spacing} m, "
        f"capacity {layout.capacity} robots, {len(layout.crossings)} crossings"
    )
    lim = cfg.perimeter_radius * 1.08
    ax.set_xlim(cx - lim, cx + lim)
    ax.set_ylim(cy - lim, cy + lim)
    ax.set_aspect("equal")
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    ax.legend(loc="upper right", fontsize=7)
    out = Path(path_png)
    fig.savefig(out, dpi=120, bbox_inches="tight")
    plt.close(fig)
    return out


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--layout", choices=("single", "multi"), default="single")
    p.add_argument("--out", required=True)
    p.add_argument("--depot-radius", type=float, default=DepotGeometryConfig.depot_radius)
    p.add_argument("--perimeter-radius", type=float,
                   default=DepotGeometryConfig.perimeter_radius)
    p.add_argument("--docks", type=int, default=DepotGeometryConfig.docks)
    p.add_argument("--lane-spacing", type=float, default=DepotGeometryConfig.lane_spacing)
    a = p.parse_args(argv)
    cfg = DepotGeometryConfig(
        depot_radius=a.depot_radius, perimeter_radius=a.perimeter_radius, docks=a.docks,
        lane_spacing=a.lane_spacing,
    )
    try:
        layout = make_layout(a.layout, cfg)
    except ValueError as e:
        p.error(str(e))
    out = draw_layout(layout, a.out)
    print(f"{out}: {layout.kind} layout, capacity {layout.capacity} robots")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())

"""A replay video's frame (`swarm_sim.analysis.video`): the arena on the left with a scale bar,
the legend beside it, fixed from the first frame (every state the algorithm's record lists, in
far-apart colours; every server overlay by namespace, from the server's core drawn once; what the
world task placed and its bodies), the robots coloured by state, the sim clock and the algorithm's
progress in the title. One matplotlib figure whose artists are updated per frame."""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from swarm_msgs_py import odometry
from swarm_msgs_py.types import BehaviourStatus
from swarm_sim import registry
from swarm_sim.outputs import outputs_of
from swarm_sim.protocol import Lines
from swarm_sim.scenario import Scenario
from swarm_sim.sites import drop_zones

SIZE_PX = 720
"""Frame height [px], and the arena's square (a multiple of 16, as H.264 wants)."""
LEGEND_PX = 240
"""The legend's column beside the arena [px]."""
WIDTH_PX = SIZE_PX + LEGEND_PX
_DPI = 100
PALETTE = ("tab:blue", "tab:orange", "tab:green", "tab:red", "tab:purple", "tab:brown", "tab:pink", "tab:olive",
           "tab:cyan", "#000075", "#f032e6", "#9a6324", "#469990", "#e6beff", "#800000", "#aaffc3")
"""Robot state colours, far apart (tab10 without its grey, then Trubetskoy's distinct colours);
beyond 16 states they repeat."""
NO_STATUS = ("#d0d0d0", "no status yet")
BODY_COLOUR = (0.84, 0.15, 0.16, 0.55)


@dataclass
class FrameState:
    """What the frame at the current sim time shows (folded from the bag by
    `swarm_sim.analysis.video`)."""

    odom: dict[int, bytes] = field(default_factory=dict)
    """Robot index -> its last odometry message (decoded only when a frame is drawn)."""
    status: dict[str, BehaviourStatus] = field(default_factory=dict)
    """Robot -> its last reported status."""
    carrying: set[str] = field(default_factory=set)
    resources: np.ndarray = field(default_factory=lambda: np.zeros((0, 2)))
    delivered: int = 0
    lines: dict[tuple[str, str], list[tuple[np.ndarray, tuple[float, ...], float]]] = field(default_factory=dict)
    """Servers' line strips by (topic, namespace): (points [m], RGBA, width [m]) each."""
    points: dict[tuple[str, str], tuple[np.ndarray, tuple[float, ...], float, str]] = field(default_factory=dict)
    """Servers' point lists by (topic, namespace): (points [m], RGBA, size [m], matplotlib marker)."""
    placed: dict[str, tuple[np.ndarray, tuple[float, ...]]] = field(default_factory=dict)
    """What the world task placed besides resources (the caging landmarks), by name: (points
    [m], RGBA), from ``/world/markers``."""
    bodies: dict[str, tuple[float, float]] = field(default_factory=dict)
    """The task's bodies at their last state-topic position [m] (the caging object), by field."""

def overlays(scenario: Scenario) -> list[tuple[str, Lines | object]]:
    """(server name, drawing item) of every server of the scenario's algorithm, its core drawn
    once from the scenario (stamp 0): what the legend names before any marker is read."""
    out = []
    cores = registry.make_servers(scenario)
    for spec in registry.of(scenario).servers:
        markers = outputs_of(spec).markers
        if markers is not None:
            out += [(spec.channel, item) for item in markers.draw(cores[spec.channel], 0)]
    return out


def scale_bar_m(arena: float) -> float:
    """A round length (1, 2 or 5 times a power of ten) of about a fifth of the arena [m]."""
    power = 10 ** math.floor(math.log10(arena / 5))
    return max(step * power for step in (1, 2, 5) if step * power <= arena / 4 or step == 1)


class Canvas:
    """One matplotlib figure whose artists are updated per frame: the arena on the left, the
    legend beside it."""

    def __init__(self, scenario: Scenario, robots: int, bodies: dict[str, float]) -> None:
        """`bodies`: the task's bodies drawn to scale, name -> diameter [m] (`TaskSpec.bodies`)."""
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        from matplotlib.collections import EllipseCollection, LineCollection

        self.scenario = scenario
        algorithm = registry.of(scenario)
        self._progress = registry.resolve(algorithm.progress) if algorithm.progress else None
        self.fig = plt.figure(figsize=(WIDTH_PX / _DPI, SIZE_PX / _DPI), dpi=_DPI)
        arena_share = SIZE_PX / WIDTH_PX
        self.ax = ax = self.fig.add_axes((0.01 * arena_share, 0.01, 0.98 * arena_share, 0.93))
        self.key = self.fig.add_axes((arena_share, 0.0, 1.0 - arena_share, 1.0))
        self.key.axis("off")
        half = scenario.arena.size / 2
        ax.plot([-half, half, half, -half, -half], [-half, -half, half, half, -half], color="black", lw=1.5)
        zones = drop_zones(scenario) if scenario.resources.count else ()
        for zone in zones:
            ax.add_patch(plt.Circle(zone.center, zone.radius, color="tab:green", alpha=0.25, lw=0))
        for ob in scenario.obstacles:
            w, h = ob.size
            ax.add_patch(plt.Rectangle((ob.center[0] - w / 2, ob.center[1] - h / 2), w, h, color="tab:brown",
                                       alpha=0.7))
        margin = 0.08 * scenario.arena.size
        ax.set(xlim=(-half - margin, half + margin), ylim=(-half - margin, half + margin), aspect="equal",
               xticks=[], yticks=[])
        for side in ax.spines.values():
            side.set_visible(False)
        self._scale_bar(half, margin)
        self.server_lines = LineCollection([], linewidths=0.8, zorder=1)
        ax.add_collection(self.server_lines)
        self.server_points: dict[tuple[str, str], object] = {}
        """A scatter per server point list: markers drawn at the size [m] the server gave them."""
        self.resources = ax.scatter([], [], s=4, color="goldenrod", zorder=3, lw=0)
        self.placed: dict[str, object] = {}
        """A scatter per point set the task placed (landmarks), made when first seen."""
        self.bodies = {name: EllipseCollection([d], [d], [0.0], units="xy", offsets=[(1e6, 1e6)],
                                               offset_transform=ax.transData, facecolors=[BODY_COLOUR],
                                               edgecolors="black", linewidths=0.5, zorder=3)
                       for name, d in bodies.items()}
        for artist in self.bodies.values():
            ax.add_collection(artist)
        d = scenario.robots.diameter
        self.robots = EllipseCollection(np.full(robots, d), np.full(robots, d), np.zeros(robots), units="xy",
                                        offsets=np.zeros((robots, 2)), offset_transform=ax.transData,
                                        edgecolors="black", linewidths=0.3, zorder=4)
        ax.add_collection(self.robots)
        self.headings = LineCollection([], colors="black", linewidths=0.6, zorder=5)
        ax.add_collection(self.headings)
        self.carried = ax.scatter([], [], s=6, color="gold", edgecolors="black", linewidths=0.2, zorder=6)
        self.title = ax.set_title(f"{scenario.name}  t = 0.0 s", fontsize=10, family="monospace")
        self.states: list[str] = list(algorithm.states)
        """Every state in the legend, in colour order: the record's, then any other a robot reports."""
        self._overlays = overlays(scenario)
        self._paths = [] if self._overlays or not algorithm.paths else registry.resolve(algorithm.paths)(scenario)
        """The algorithm's planned paths, drawn when no server draws what it plans (DDSA's spirals)."""
        if self._paths:
            ax.add_collection(LineCollection(self._paths, colors="0.8", linewidths=0.6, zorder=0))
        self._legend()
        self._pt_per_m = ax.transData.get_matrix()[0, 0] * 72.0 / _DPI
        """Points per metre at this figure's scale (a scatter's size is in points squared)."""

    def _scale_bar(self, half: float, margin: float) -> None:
        length = scale_bar_m(2 * half)
        y = -half - 0.55 * margin
        self.ax.plot([-half, -half + length], [y, y], color="black", lw=3, solid_capstyle="butt")
        self.ax.text(-half + length + 0.02 * half, y, f"{length:g} m", va="center", fontsize=9)

    def _colour(self, state: str) -> str:
        if state not in self.states:  # a state the record does not list: added, the legend redrawn
            self.states.append(state)
            self._legend()
        return PALETTE[self.states.index(state) % len(PALETTE)]

    def _legend(self) -> None:
        from matplotlib.lines import Line2D
        from matplotlib.patches import Patch

        def dot(colour, label, marker="o", size=7):
            return Line2D([], [], ls="", marker=marker, ms=size, markerfacecolor=colour, markeredgecolor="black",
                          markeredgewidth=0.3, label=label)

        self.key.clear()
        self.key.axis("off")
        robots = [dot(PALETTE[i % len(PALETTE)], s.lower().replace("_", " ")) for i, s in enumerate(self.states)]
        robots.append(dot(NO_STATUS[0], NO_STATUS[1]))
        world = []
        if self.scenario.resources.count:
            world += [dot("goldenrod", "resource", size=4), dot("gold", "carried resource", size=5),
                      Patch(color="tab:green", alpha=0.25, label="drop zone")]
        if self.scenario.obstacles:
            world.append(Patch(color="tab:brown", alpha=0.7, label="obstacle"))
        if self._paths:
            world.append(Line2D([], [], color="0.8", lw=1.5, label="planned paths"))
        world += [dot(BODY_COLOUR, name.replace("_", " "), size=9) for name in self.bodies]
        world += [dot(artist.get_facecolor()[0], name.replace("_", " "), size=3) for name, artist in self.placed.items()]
        for server, item in self._overlays:
            label = f"{server}: {item.ns.replace('_', ' ')}"
            if isinstance(item, Lines):
                world.append(Line2D([], [], color=item.color[:3], alpha=item.color[3], lw=1.5, label=label))
            else:
                world.append(dot(item.color[:3], label, marker="s" if item.cubes else "o", size=5))
        top = self.key.legend(handles=robots, title="robot state", loc="upper left", fontsize=8, title_fontsize=9,
                              frameon=False, bbox_to_anchor=(0.0, 0.97))
        self.key.add_artist(top)
        if world:
            self.key.legend(handles=world, title="world", loc="lower left", fontsize=8, title_fontsize=9,
                            frameon=False, bbox_to_anchor=(0.0, 0.02))

    def draw(self, state: FrameState, t: float, robot_names: list[str]) -> np.ndarray:
        segments, colours = [], []
        for key in sorted(state.lines):
            for xy, rgba, _ in state.lines[key]:
                segments.append(xy)
                colours.append(rgba)
        self.server_lines.set_segments(segments)
        self.server_lines.set_color(colours)
        for key, artist in self.server_points.items():
            if key not in state.points:
                artist.set_offsets(np.zeros((0, 2)))
        for key in sorted(state.points):
            xy, rgba, size, shape = state.points[key]
            if key not in self.server_points:
                self.server_points[key] = self.ax.scatter([], [], marker=shape, zorder=2, lw=0)
            artist = self.server_points[key]
            artist.set_offsets(xy if len(xy) else np.zeros((0, 2)))
            artist.set_sizes([max(1.0, (size * self._pt_per_m) ** 2)])
            artist.set_color([rgba])
        self.resources.set_offsets(state.resources if len(state.resources) else np.zeros((0, 2)))
        for name, (xy, rgba) in state.placed.items():
            if name in self.bodies:
                continue  # drawn to scale from its state topic
            if name not in self.placed:
                self.placed[name] = self.ax.scatter([], [], s=3, color=[rgba], zorder=1, lw=0)
                self._legend()
            self.placed[name].set_offsets(xy if len(xy) else np.zeros((0, 2)))
        for name, xy in state.bodies.items():
            if name in self.bodies:
                self.bodies[name].set_offsets([xy])
        poses = np.full((len(robot_names), 3), np.nan)
        for i, data in state.odom.items():
            _, pose, _, _ = odometry.decode_odometry(data)
            poses[i] = (pose.x, pose.y, pose.yaw)
        seen = ~np.isnan(poses[:, 0])
        xy = np.where(seen[:, None], poses[:, :2], 1e6)  # robots not seen yet: off the canvas
        self.robots.set_offsets(xy)
        self.robots.set_facecolor([self._colour(state.status[r].state) if r in state.status else NO_STATUS[0]
                                   for r in robot_names])
        reach = self.scenario.robots.diameter * 0.6
        tips = xy + reach * np.column_stack([np.cos(np.nan_to_num(poses[:, 2])), np.sin(np.nan_to_num(poses[:, 2]))])
        self.headings.set_segments([np.array([a, b]) for a, b, s in zip(xy, tips, seen) if s])
        carriers = [i for i, r in enumerate(robot_names) if r in state.carrying and seen[i]]
        self.carried.set_offsets(xy[carriers] if carriers else np.zeros((0, 2)))
        doing = self._progress(state.status) if self._progress else f"delivered {state.delivered}"
        self.title.set_text(f"{self.scenario.name}  t = {t:7.1f} s  {doing}")
        self.fig.canvas.draw()
        return np.asarray(self.fig.canvas.buffer_rgba())[..., :3].copy()

    def close(self) -> None:
        import matplotlib.pyplot as plt

        plt.close(self.fig)

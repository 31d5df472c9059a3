"""A run's replay video from its bag alone (``swarm-analyze BAG --video out.mp4|out.gif``).

One pass over the bag in log-time order keeps the state a frame needs and draws a frame whenever
the sim clock passes the next frame time, so memory stays flat however long the run:

- arena walls, drop zones and obstacles from the scenario in the bag's metadata;
- every server's overlay (any recorded ``visualization_msgs/MarkerArray`` topic but the world's,
  e.g. a depot's lines and docks or a center's regions and planned paths), its line strips and
  point lists in the colours and sizes the server gave them, as it last published them;
- resources lying on the ground: the world's last ``/world/markers`` set, minus the pick-ups
  (``/world/events``) since, matched by position;
- robots at their recorded odometry, true size, with a heading tick, coloured by the behaviour
  state they last reported (``/<robot>/status``), with a resource drawn on each carrier (between
  its pick-up and drop events);
- the sim clock and the deliveries so far (or what the algorithm's record makes of the robots'
  statuses, `swarm_sim.registry.Algorithm.progress`: the caging stage);
- the algorithm's planned paths when no server draws what it plans (DDSA's spirals);
- a scale bar, and beside the arena a legend fixed from the first frame: every state the
  algorithm's record lists (`Algorithm.states`), each in its own colour, and every server overlay
  by namespace, in the server's colours (its core drawn once from the scenario).

Frames are taken every ``speedup / fps`` sim seconds between `start` and `end`, rendered with
matplotlib and encoded with imageio (its ffmpeg plugin for .mp4, Pillow for .gif), with a
progress bar on a terminal. Markers are decoded with rosbags' Jazzy typestore; our own topics with
the `swarm_msgs_py` codecs.
"""

from __future__ import annotations

import json
import math
from collections.abc import Iterator
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from tqdm import tqdm

from swarm_msgs_py import diagnostics, odometry, topics
from swarm_msgs_py.server_outputs import outputs_of
from swarm_sim import registry
from swarm_sim.protocol import Lines
from swarm_sim.recording import BagError, bag_info, read_bag
from swarm_sim.scenario import Scenario, scenario_from_dict
from swarm_sim.sites import drop_zones
from swarm_sim.types import NS_PER_S, BehaviourStatus, DropEvent, PickupEvent

FORMATS = (".mp4", ".gif")
SIZE_PX = 720
"""Frame height [px], and the arena's square (a multiple of 16, as H.264 wants)."""
LEGEND_PX = 240
"""The legend's column beside the arena [px]."""
WIDTH_PX = SIZE_PX + LEGEND_PX
_DPI = 100
_PALETTE = ("tab:blue", "tab:orange", "tab:green", "tab:red", "tab:purple", "tab:brown", "tab:pink", "tab:olive",
            "tab:cyan", "#000075", "#f032e6", "#9a6324", "#469990", "#e6beff", "#800000", "#aaffc3")
"""Robot state colours, far apart (tab10 without its grey, then Trubetskoy's distinct colours);
beyond 16 states they repeat."""
NO_STATUS = ("#d0d0d0", "no status yet")
_MARKER_TYPES = "visualization_msgs/msg/MarkerArray"
_LINE_STRIP, _CUBE_LIST, _SPHERE_LIST = 4, 6, 7
"""visualization_msgs/Marker types drawn from the servers' markers."""
_NOT_PLACED = frozenset({"walls", "drop_zones", "obstacles", "robots", "resources"})
"""``/world/markers`` namespaces that are not a task's placed point sets."""
BODY_COLOUR = (0.84, 0.15, 0.16, 0.55)


@dataclass(frozen=True)
class _Watch:
    """What the bag's messages are read for besides robots, events and the world's markers."""

    robots: dict[str, int]
    overlays: frozenset[str]
    """The servers' marker topics."""
    bodies: dict[str, object]
    """State topic -> its `StateTopic`, for the task's bodies (`TaskSpec.bodies`)."""


@dataclass
class _State:
    """What the frame at the current sim time shows."""

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


@dataclass(frozen=True)
class VideoInfo:
    path: Path
    frames: int
    start_s: float
    end_s: float


def _markers(data: bytes) -> list:
    from rosbags.typesys import Stores, get_typestore

    global _STORE
    if _STORE is None:
        _STORE = get_typestore(Stores.ROS2_JAZZY)
    return _STORE.deserialize_cdr(data, _MARKER_TYPES).markers


_STORE = None


def resource_points(data: bytes) -> np.ndarray:
    """(n, 2) the resources lying on the ground in a ``/world/markers`` message [m]."""
    return next((_xy(m) for m in _markers(data) if m.ns == "resources"), np.zeros((0, 2)))


def _xy(marker) -> np.ndarray:
    return np.array([(p.x, p.y) for p in marker.points], dtype=float).reshape(-1, 2)


def _rgba(marker) -> tuple[float, ...]:
    c = marker.color
    return tuple(min(max(float(v), 0.0), 1.0) if math.isfinite(v) else 0.5 for v in (c.r, c.g, c.b, c.a))


def _apply(state: _State, topic: str, data: bytes, watch: _Watch) -> None:
    """Fold one recorded message into the state."""
    robots = watch.robots
    if topic.endswith("/" + topics.ODOM):
        i = robots.get(topic[1:].partition("/")[0])
        if i is not None:
            state.odom[i] = data
    elif topic.endswith("/" + topics.STATUS):
        status = diagnostics.decode_status(data)
        if status.robot in robots:
            state.status[status.robot] = status
    elif topic == topics.WORLD_EVENTS:
        for event in diagnostics.decode_events(data)[1]:
            if isinstance(event, PickupEvent):
                state.carrying.add(event.robot)
                if len(state.resources):
                    gone = np.argmin(np.hypot(*(state.resources - (event.x, event.y)).T))
                    state.resources = np.delete(state.resources, gone, axis=0)
            elif isinstance(event, DropEvent):
                state.carrying.discard(event.robot)
                state.delivered += 1
    elif topic == topics.WORLD_MARKERS:
        for m in _markers(data):
            if m.ns == "resources":
                state.resources = _xy(m)
            elif m.ns not in _NOT_PLACED and m.type == _SPHERE_LIST:
                state.placed[m.ns] = (_xy(m), _rgba(m))
    elif topic in watch.bodies:
        st = watch.bodies[topic]
        _, (x, y) = st.decode(data)
        state.bodies[st.field] = (float(x), float(y))
    elif topic in watch.overlays:
        lines: dict[tuple[str, str], list] = {}
        for m in _markers(data):
            if m.type == _LINE_STRIP:
                lines.setdefault((topic, m.ns), []).append((_xy(m), _rgba(m), float(m.scale.x)))
            elif m.type in (_CUBE_LIST, _SPHERE_LIST):
                state.points[(topic, m.ns)] = (_xy(m), _rgba(m), float(m.scale.x), "s" if m.type == _CUBE_LIST else "o")
        state.lines.update(lines)


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


class _Canvas:
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
        return _PALETTE[self.states.index(state) % len(_PALETTE)]

    def _legend(self) -> None:
        from matplotlib.lines import Line2D
        from matplotlib.patches import Patch

        def dot(colour, label, marker="o", size=7):
            return Line2D([], [], ls="", marker=marker, ms=size, markerfacecolor=colour, markeredgecolor="black",
                          markeredgewidth=0.3, label=label)

        self.key.clear()
        self.key.axis("off")
        robots = [dot(_PALETTE[i % len(_PALETTE)], s.lower().replace("_", " ")) for i, s in enumerate(self.states)]
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

    def draw(self, state: _State, t: float, robot_names: list[str]) -> np.ndarray:
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


def _writer(out: Path, fps: float):
    import imageio.v2 as imageio

    if out.suffix == ".gif":
        return imageio.get_writer(out, format="GIF", mode="I", duration=1000.0 / fps, loop=0)
    return imageio.get_writer(out, format="FFMPEG", fps=fps, codec="libx264", pixelformat="yuv420p",
                              macro_block_size=16, ffmpeg_log_level="error")


def _window(info, start: float, end: float | None, speedup: float, fps: float) -> np.ndarray:
    last = info.end_ns / NS_PER_S
    end = last if end is None else min(end, last)
    if not 0 <= start <= end:
        raise ValueError(f"time window [{start:g}, {end:g}] s is empty (the bag covers 0-{last:g} s)")
    step = speedup / fps
    return start + step * np.arange(int(math.floor((end - start) / step + 1e-9)) + 1)


def frames(bag: Path | str, times: np.ndarray) -> Iterator[np.ndarray]:
    """The replay's frame (an RGB array) at each sim time in `times` (ascending) [s]."""
    bag = Path(bag)
    info = bag_info(bag)
    if "scenario" not in info.metadata:
        raise BagError(f"{bag}: no swarmforage scenario in the bag's metadata (not a swarm-run bag?)")
    scenario = scenario_from_dict(json.loads(info.metadata["scenario"]))
    names = list(scenario.robot_names)
    task = registry.task(registry.of(scenario).task)
    sizes = registry.resolve(task.bodies)(scenario) if task.bodies else {}
    watch = _Watch(
        robots={r: i for i, r in enumerate(names)},
        overlays=frozenset(t for t, i in info.topics.items() if i.type_name == _MARKER_TYPES and t != topics.WORLD_MARKERS),
        bodies={st.topic: st for st in (registry.resolve(task.state) if task.state else ()) if st.field in sizes},
    )
    state = _State()
    canvas = _Canvas(scenario, len(names), sizes)
    done = 0
    try:
        for m in read_bag(bag):
            while done < len(times) and m.stamp_ns > times[done] * NS_PER_S:
                yield canvas.draw(state, times[done], names)
                done += 1
            if done == len(times):
                return
            try:
                _apply(state, m.topic, m.data, watch)
            except (ValueError, TypeError, AttributeError):
                continue  # a malformed recorded message: swarm-analyze's metrics count these
        for t in times[done:]:
            yield canvas.draw(state, t, names)
    finally:
        canvas.close()


def render_video(bag: Path | str, out: Path | str, *, speedup: float = 10.0, fps: float = 10.0,
                 start: float = 0.0, end: float | None = None, max_frames: int | None = None,
                 progress: bool | None = None) -> VideoInfo:
    """Render the run in `bag` to `out` (.mp4 or .gif): `speedup` sim seconds per video second,
    `fps` frames per video second, sim times [`start`, `end`] [s] (default: the whole run),
    at most `max_frames` frames, with a progress bar on standard error (`progress` None: when it
    is a terminal). Raises BagError / ValueError naming what is wrong."""
    bag, out = Path(bag), Path(out)
    if out.suffix not in FORMATS:
        raise ValueError(f"--video {out}: expected a file ending in {' or '.join(FORMATS)}")
    if not (speedup > 0 and fps > 0 and math.isfinite(speedup) and math.isfinite(fps)):
        raise ValueError("--speedup and --fps must be positive numbers")
    times = _window(bag_info(bag), start, end, speedup, fps)[:max_frames]
    count = 0
    with _writer(out, fps) as writer, tqdm(total=len(times), unit="frame", desc=f"rendering {out.name}",
                                            disable=None if progress is None else not progress, leave=False) as bar:
        for frame in frames(bag, times):
            writer.append_data(frame)
            count += 1
            bar.update()
    return VideoInfo(out, count, float(times[0]), float(times[-1]))


def save_frame(bag: Path | str, t: float, out: Path | str) -> Path:
    """One frame of the replay, at sim time `t` [s], as a PNG (the README's picture)."""
    import imageio.v2 as imageio

    (frame,) = frames(bag, np.array([float(t)]))
    imageio.imwrite(out, frame)
    return Path(out)

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

The frame itself is drawn by `swarm_sim.analysis.video_canvas`. Frames are taken every
``speedup / fps`` sim seconds between `start` and `end`, rendered with
matplotlib and encoded with imageio (its ffmpeg plugin for .mp4, Pillow for .gif), with a
progress bar on a terminal. Markers are decoded with rosbags' Jazzy typestore; our own topics with
the `swarm_msgs_py` codecs.
"""

from __future__ import annotations

import json
import math
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from tqdm import tqdm

from swarm_msgs_py import diagnostics, topics
from swarm_msgs_py.types import NS_PER_S, DropEvent, PickupEvent
from swarm_sim import registry
from swarm_sim.analysis.video_canvas import SIZE_PX, WIDTH_PX, Canvas, FrameState
from swarm_sim.recording import BagError, bag_info, read_bag
from swarm_sim.scenario import scenario_from_dict

__all__ = ("FORMATS", "SIZE_PX", "WIDTH_PX", "VideoInfo", "frames", "render_video", "resource_points", "save_frame")

FORMATS = (".mp4", ".gif")
_MARKER_TYPES = "visualization_msgs/msg/MarkerArray"
_LINE_STRIP, _CUBE_LIST, _SPHERE_LIST = 4, 6, 7
"""visualization_msgs/Marker types drawn from the servers' markers."""
_NOT_PLACED = frozenset({"walls", "drop_zones", "obstacles", "robots", "resources"})
"""``/world/markers`` namespaces that are not a task's placed point sets."""


@dataclass(frozen=True)
class _Watch:
    """What the bag's messages are read for besides robots, events and the world's markers."""

    robots: dict[str, int]
    overlays: frozenset[str]
    """The servers' marker topics."""
    bodies: dict[str, object]
    """State topic -> its `StateTopic`, for the task's bodies (`TaskSpec.bodies`)."""


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


def _apply(state: FrameState, topic: str, data: bytes, watch: _Watch) -> None:
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
    state = FrameState()
    canvas = Canvas(scenario, len(names), sizes)
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
    """One frame of the replay, at sim time `t` [s], as a PNG (docs/replay_frame.png is one)."""
    import imageio.v2 as imageio

    (frame,) = frames(bag, np.array([float(t)]))
    imageio.imwrite(out, frame)
    return Path(out)

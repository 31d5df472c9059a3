"""What a server puts on the graph besides its family's messages, and the series read from it.

A registered server (`swarm_sim.registry.ServerSpec`) declares its `ServerOutputs` once, as a
world task declares its `swarm_msgs_py.sensing.StateTopic` values, and every reader follows the
declaration:

- `ServerState`: a value of the core's ``state()`` on a latched topic, published whenever it
  changed since the last tick (`StateWatch`: the same rule on the graph and in batch runs);
- `ServerMarkers`: what the core draws (`swarm_sim.protocol.Lines` / `Points`, ROS-free), as a
  MarkerArray on a latched topic: once when the node starts, or after a state change at most
  once per period of sim time;
- `Series`: run-trace time series (``RunTrace.series``) read off what the server publishes, a
  state topic or a topic of its message family: the batch runner reads the values the cores
  give (`SeriesLog.published`, `SeriesLog.sent`), a bag replay the same values decoded from the
  recorded bytes (`SeriesLog.replay`). Round trips are exact (the conformance check), so both
  give the same series.

ROS-free: the generic server node (`swarm_sim.nodes.server_node`) turns drawings into markers.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Mapping, Sequence
from dataclasses import dataclass
from typing import Any

from swarm_msgs_py.types import NS_PER_S
from swarm_sim import registry
from swarm_sim.protocol import Drawing

MARKER_ARRAY = "visualization_msgs/msg/MarkerArray"


@dataclass(frozen=True)
class ServerState:
    """One value of a server core's ``state()`` on a latched topic, published when it changes."""

    topic: str
    """Absolute topic name (``/depot/state``)."""
    type_name: str
    """ROS type string: standard types only."""
    field: str
    """The key of the value in the core's ``state()``."""
    encode: Callable[[int, Any], bytes]
    """(stamp_ns, value) -> CDR bytes."""
    decode: Callable[[bytes], tuple[int, Any]]
    """CDR bytes -> (stamp_ns, value) with ``value == state()[field]`` exactly; raises a
    ValueError on malformed bytes."""


@dataclass(frozen=True)
class ServerMarkers:
    """What a server core draws, as visualization_msgs/msg/MarkerArray on a latched topic."""

    topic: str
    draw: Callable[[Any, int], Drawing]
    """(core, stamp_ns) -> the drawing."""
    period: float | None = None
    """None: drawn once, when the node starts (stamp 0); otherwise redrawn after a tick at which
    the core's state changed, at most once per `period` sim seconds."""


@dataclass(frozen=True)
class Series:
    """Run-trace time series read off one topic the server publishes or hears."""

    topic: str
    """One of the server's `ServerState` topics (values: the state) or a topic of its message
    family (values: each message on it)."""
    points: Callable[[Any], Mapping[str, Any]]
    """A value -> {series name: point value}; the point's time is the value's stamp."""
    on_change: bool = False
    """Keep a point only when it differs from its series' last one (a state's step function)
    instead of one point per value."""

    def record(self, series: dict[str, list[tuple[float, Any]]], stamp_ns: int, value: Any) -> None:
        t = stamp_ns / NS_PER_S
        for name, v in self.points(value).items():
            points = series.setdefault(name, [])
            if not (self.on_change and points and points[-1][1] == v):
                points.append((t, v))


@dataclass(frozen=True)
class LivePlot:
    """A plot of what a server publishes, in the shipped live layouts
    (`swarm_sim.nodes.foxglove_layout`): Foxglove's plots read no numbers from strings, so a user
    script (TypeScript, run inside Foxglove or Lichtblick) turns the server's state into numbers."""

    key: str
    """The script's key, and the last part of its output topic."""
    name: str
    title: str
    """The plot's title, with its unit."""
    script: str
    """The TypeScript source; ``{prefix}`` stands for where its output topic must start
    (Foxglove's and Lichtblick's differ), literal braces are doubled."""
    series: tuple[tuple[str, str], ...]
    """(field of the script's output, legend label) per line."""


@dataclass(frozen=True)
class ServerOutputs:
    state: tuple[ServerState, ...] = ()
    markers: ServerMarkers | None = None
    series: tuple[Series, ...] = ()
    live: tuple[LivePlot, ...] = ()


NO_OUTPUTS = ServerOutputs()


def outputs_of(spec: registry.ServerSpec) -> ServerOutputs:
    """The outputs a server's registry record declares."""
    return registry.resolve(spec.outputs) if spec.outputs else NO_OUTPUTS


_NOTHING = object()


class StateWatch:
    """Which state values to publish after a tick: those that differ from the last published
    (all of them at the first tick)."""

    def __init__(self, states: Sequence[ServerState]) -> None:
        self.states = tuple(states)
        self._last: dict[str, Any] = {}

    def changed(self, values: Mapping[str, Any]) -> list[tuple[ServerState, Any]]:
        out = []
        for st in self.states:
            value = values[st.field]
            last = self._last.get(st.field, _NOTHING)
            if last is not value and (last is _NOTHING or last != value):
                self._last[st.field] = value
                out.append((st, value))
        return out


class SeriesLog:
    """The series of a run's servers, into `series` (``RunTrace.series``), from the values they
    publish (batch runs) or from their recorded bytes (bag replays); see the module docstring."""

    def __init__(self, specs: Iterable[registry.ServerSpec], series: dict[str, list[tuple[float, Any]]]) -> None:
        self.series = series
        self._states: dict[str, tuple[ServerState, tuple[Series, ...]]] = {}
        self._messages: dict[str, tuple[Any, tuple[Series, ...]]] = {}
        self._by_class: dict[type, tuple[Series, ...]] = {}
        self.reads_state: set[str] = set()
        """Channels of the servers whose state values a series reads."""
        for spec in specs:
            outputs, family = outputs_of(spec), registry.resolve(spec.family)
            states = {st.topic: st for st in outputs.state}
            for topic in dict.fromkeys(s.topic for s in outputs.series):
                readers = tuple(s for s in outputs.series if s.topic == topic)
                if topic in states:
                    self._states[topic] = (states[topic], readers)
                    self.reads_state.add(spec.channel)
                elif topic in family.topics.values():
                    self._messages[topic] = (family, readers)
                    self._by_class.update((cls, readers) for cls, t in family.topics.items() if t == topic)
                else:
                    raise ValueError(f"server {spec.channel}: a series reads {topic}, which it neither "
                                     "publishes as its state nor exchanges as its family's messages")

    @property
    def topics(self) -> frozenset[str]:
        return frozenset((*self._states, *self._messages))

    def sent(self, messages: Iterable[object]) -> None:
        """Messages published (a batch runner's robots' or servers' of one tick)."""
        by_class = self._by_class
        if not by_class:
            return
        for m in messages:
            readers = by_class.get(type(m))
            if readers:
                for s in readers:
                    s.record(self.series, m.stamp_ns, m)

    def published(self, stamp_ns: int, states: Iterable[tuple[ServerState, Any]]) -> None:
        """State values published at `stamp_ns` (`StateWatch.changed`)."""
        for st, value in states:
            if st.topic in self._states:
                for s in self._states[st.topic][1]:
                    s.record(self.series, stamp_ns, value)

    def replay(self, topic: str, data: bytes) -> None:
        """A message recorded on `topic` (ValueError if it does not decode)."""
        if topic in self._states:
            st, readers = self._states[topic]
            stamp_ns, value = st.decode(data)
            for s in readers:
                s.record(self.series, stamp_ns, value)
        elif topic in self._messages:
            family, readers = self._messages[topic]
            for m in family.decode(data):
                if self._by_class.get(type(m)) is readers:
                    for s in readers:
                        s.record(self.series, m.stamp_ns, m)

"""A run's trace from its bag alone (no ROS running, no rclpy needed).

``load_run(bag) -> RunTrace`` decodes the world's events and counters and the behaviours'
status messages with the `swarm_msgs_py` codecs; the metric functions of
`swarm_sim.analysis.metrics` then compute exactly what the batch runner computes.

A bag is untrusted input, and analysis trusts no more than the live graph did: what the run
refused was recorded apart (`swarm_msgs_py.topics.refused` channels) and is not read; the
messages of other nodes are checked by the rules the live nodes apply (`swarm_sim.inbound`:
robots of this run, coordinates within the arena, not stamped after they were recorded), a
status only counts on its own robot's topic and with counts a run of this length can reach.
What fails is skipped and counted (``malformed_messages``).
"""

from __future__ import annotations

import json
import warnings
from pathlib import Path
from typing import Any

import numpy as np

from swarm_msgs_py import clock as clock_codec
from swarm_msgs_py import diagnostics, odometry, scan, topics
from swarm_msgs_py.types import NS_PER_S, DropEvent, NodeDownEvent, PickupEvent, robot_index
from swarm_sim import registry
from swarm_sim.analysis.metrics import RunTrace
from swarm_sim.analysis.state_rules import RuleLog, StatusLog
from swarm_sim.inbound import Bounds, Inbound, Rejections
from swarm_sim.messaging import delivery_order
from swarm_sim.outputs import SeriesLog
from swarm_sim.recording import BagError, bag_info, read_bag
from swarm_sim.scenario import scenario_from_dict


class MalformedMessageWarning(UserWarning):
    """A bag holds messages that do not decode (e.g. published by a faulty or hostile node);
    they are skipped and counted in `RunTrace.malformed`, everything else is analysed."""


def load_run(path: Path | str) -> RunTrace:
    """Build the trace of a recorded run; raises BagError naming what is missing."""
    path = Path(path)
    info = bag_info(path)
    meta = info.metadata
    if "scenario" not in meta:
        raise BagError(f"{path}: no swarmforage scenario in the bag's metadata (not a swarm-run bag?)")
    scenario = scenario_from_dict(json.loads(meta["scenario"]))
    trace = RunTrace(
        scenario=scenario.name, seed=scenario.seed, robots=tuple(scenario.robot_names),
        sim_seconds=float(meta.get("sim_seconds", 0.0)), wall_seconds=float(meta.get("wall_seconds", 0.0)),
        total_resources=scenario.resources.count, mode=meta.get("mode", "lockstep"), config=scenario,
    )
    trace.server_stale = _server_stale(path, str(meta.get("server_stale_ticks", "{}")))
    trace.commands = _commands(path, str(meta.get("commands_by_robot", "{}")), trace.robots)
    algorithm = registry.of(scenario)
    servers = SeriesLog(algorithm.servers, trace.series)  # the servers' series, as the batch runner reads them
    server_topics = servers.topics
    spec = registry.task(algorithm.task).state
    state = {st.topic: st for st in (registry.resolve(spec) if spec else ())}
    peers = {}  # topic -> message family, for algorithms whose metrics read the protocol
    for name in algorithm.peers if algorithm.trace_peers else ():
        family = registry.resolve(name)
        peers.update(dict.fromkeys(family.topics.values(), family))
    index = {r: i for i, r in enumerate(trace.robots)}
    positions: dict[int, np.ndarray] = {}  # stamp -> (robots, 2) odometry positions
    statuses = StatusLog(trace.robots)
    rings = _Rings(scenario) if algorithm.collision_rule else None  # the scans whose ring reads something
    last_clock = 0
    gate = Inbound(trace.robots, scenario.dt_ns, Rejections(), lambda line: None, Bounds.of(scenario))
    families = {t: registry.resolve(spec.family) for spec in algorithm.servers
                for t in registry.resolve(spec.family).topics.values()}
    trace.foreign = _strings(path, "foreign_publishers", str(meta.get("foreign_publishers", "[]")))
    for m in read_bag(path):
        if m.topic.endswith("/" + topics.REFUSED):  # what the run refused, recorded apart
            continue
        try:
            if m.topic in families or m.topic in peers:  # another node's messages: the live rules
                gate.now_ns = m.stamp_ns
                messages = (families.get(m.topic) or peers[m.topic]).decode(m.data)
                if not all([gate.admit(m.topic, x) for x in messages]):
                    raise ValueError(f"refused by the live rules: {_last_refusal(gate)}")
            if m.topic.endswith("/" + topics.ODOM):
                robot = m.topic[1:].partition("/")[0]
                if robot in index:
                    stamp, pose, _, _ = odometry.decode_odometry(m.data)
                    if stamp not in positions:
                        positions[stamp] = np.full((len(index), 2), np.nan)
                    positions[stamp][index[robot]] = (pose.x, pose.y)
            elif m.topic == topics.CLOCK:
                last_clock = max(last_clock, clock_codec.decode_clock(m.data))
            elif m.topic == topics.WORLD_EVENTS:
                for event in diagnostics.decode_events(m.data)[1]:
                    if isinstance(event, DropEvent):
                        trace.drops.append(event)
                    elif isinstance(event, PickupEvent):
                        trace.pickups.append(event)
                    elif isinstance(event, NodeDownEvent):
                        trace.down.append(event)
            elif m.topic == topics.DIAGNOSTICS:
                trace.rejected.update(diagnostics.decode_rejections(m.data)[1])
            elif m.topic == topics.WORLD_ROBOT_STATS:
                trace.stats = diagnostics.decode_robot_stats(m.data)[1]
            elif m.topic.endswith("/" + topics.STATUS):
                status = diagnostics.decode_status(m.data)
                if m.topic != topics.robot_topic(status.robot, topics.STATUS) or status.robot not in index:
                    raise ValueError(f"a status of {status.robot[:40]!r} on {m.topic}")
                if max(status.obstacle_avoidance_events, status.trips) > scenario.ticks:
                    raise ValueError(f"counts beyond one a tick ({status.obstacle_avoidance_events} OAE, "
                                     f"{status.trips} trips in {scenario.ticks} ticks)")
                trace.status[status.robot] = status
                statuses.published(status)
            elif rings is not None and m.topic.endswith("/" + topics.SCAN):
                robot = m.topic[1:].partition("/")[0]
                if robot in index:
                    rings.add(index[robot], *scan.decode_scan(m.data))
            elif m.topic in state:
                st = state[m.topic]
                stamp, value = st.decode(m.data)
                trace.series.setdefault(st.field, []).append((stamp / NS_PER_S, value))
            elif m.topic in peers:
                trace.messages.extend(peers[m.topic].decode(m.data))
            elif m.topic in server_topics:
                servers.replay(m.topic, m.data)
        except (ValueError, ArithmeticError) as exc:  # a malformed message on the bus was recorded as sent
            trace.malformed[m.topic] = trace.malformed.get(m.topic, 0) + 1
            if trace.malformed[m.topic] == 1:
                warnings.warn(f"{path}: skipping malformed messages on {m.topic}: {exc}", MalformedMessageWarning,
                              stacklevel=2)
    trace.messages.sort(key=delivery_order)
    if "ended" in meta:
        trace.ended = str(meta["ended"])[:200]
    elif "sim_seconds" not in meta:  # the world died before it wrote its totals: the data ends where it ends
        trace.ended = "cut off"
        trace.sim_seconds = last_clock / NS_PER_S
    trace.probes = _probes(trace, positions)
    trace.lost = list(info.lost)
    if trace.lost and trace.ended == "complete":  # what is missing may be anything: never "complete"
        trace.ended = "incomplete bag"
    if algorithm.trace_status:
        trace.status_log = statuses.log
    if rings is not None:
        log = RuleLog(trace.robots, registry.resolve(algorithm.collision_rule)(scenario), scenario.sim.dt)
        rings.replay(log, statuses)
        trace.rule_collision_s = log.seconds()
    return trace


def _last_refusal(gate: Inbound) -> str:
    where, reason = next(reversed(gate.rejections.details))
    return f"{reason}: {gate.rejections.details[(where, reason)]}"


def _strings(path: Path, key: str, text: str) -> list[str]:
    """A JSON list of strings in the bag's metadata; anything else is reported and ignored."""
    try:
        value = json.loads(text)
        if isinstance(value, list) and all(isinstance(v, str) for v in value):
            return value
    except ValueError:
        pass
    warnings.warn(f"{path}: ignoring malformed {key} metadata {text[:80]!r}", MalformedMessageWarning, stacklevel=3)
    return []



class _Rings:
    """The recorded scans on which a robot's proximity ring reads something, for the state rules
    (`swarm_sim.analysis.state_rules`): its vectors computed as the batch runner computes them."""

    def __init__(self, scenario) -> None:
        # lazy: loads the world (pybullet); only state-rule replays need it
        from swarm_sim.world.proximity import ProximityRing

        self._ring = ProximityRing(scenario)
        self._reach = scenario.robots.diameter / 2 + scenario.sensors.proximity_ring.range
        self._rows: list[tuple[int, int, np.ndarray]] = []  # (stamp, robot index, ranges)

    def add(self, i: int, stamp_ns: int, ranges: np.ndarray) -> None:
        if ranges.size and float(ranges.min()) - self._reach <= 1e-9:
            self._rows.append((stamp_ns, i, ranges))

    def replay(self, log: RuleLog, statuses: StatusLog) -> None:
        if not self._rows:
            return
        self._rows.sort(key=lambda row: row[:2])
        x, y = self._ring.vectors(np.stack([r for _, _, r in self._rows]))
        robots = log.robots
        for (stamp, i, _), xi, yi in zip(self._rows, x.tolist(), y.tolist()):
            log.add(i, xi, yi, statuses.at(robots[i], stamp))


def _server_stale(path: Path, text: str) -> dict[str, int]:
    """The bag's ``server_stale_ticks`` metadata ({channel: ticks}); anything else is reported
    and ignored (a bag is untrusted input)."""
    try:
        value = json.loads(text)
        if isinstance(value, dict) and all(isinstance(k, str) and type(v) is int for k, v in value.items()):
            return value
    except ValueError:
        pass
    warnings.warn(f"{path}: ignoring malformed server_stale_ticks metadata {text[:80]!r}", MalformedMessageWarning,
                  stacklevel=3)
    return {}


def _commands(path: Path, text: str, robots: tuple[str, ...]) -> dict[str, dict]:
    """The bag's ``commands_by_robot`` metadata (`swarm_sim.nodes.command_watch`): {robot: {count:
    int, "stops": [[ns, ns, ns], ...]}} for robots of the run; anything else is reported and ignored."""
    try:
        value = json.loads(text)
        if isinstance(value, dict) and set(value) <= set(robots) and all(
                isinstance(c, dict) and all(type(n) is int for k, n in c.items() if k != "stops")
                and all(isinstance(s, list) and len(s) == 3 and all(type(t) is int for t in s)
                        for s in c.get("stops", [])) for c in value.values()):
            return value
    except ValueError:
        pass
    warnings.warn(f"{path}: ignoring malformed commands_by_robot metadata {text[:80]!r}", MalformedMessageWarning,
                  stacklevel=3)
    return {}


def _probes(trace: RunTrace, positions: dict[int, np.ndarray]) -> dict[str, Any]:
    """Replay the recorded odometry through the probes the batch runner feeds live
    (`swarm_sim.registry.Probe`; a robot missing from a tick keeps its previous position)."""
    observers = {p.name: registry.resolve(p.observer)(trace.config, trace.robots)
                 for p in registry.probes(trace.config)}
    previous = np.full((len(trace.robots), 2), np.inf)
    for stamp in sorted(positions):
        xy = positions[stamp]
        missing = np.isnan(xy[:, 0])
        xy[missing] = previous[missing]
        for observer in observers.values():
            observer.update(stamp / NS_PER_S, xy)
        previous = xy
    return {name: observer.result() for name, observer in observers.items()}


def load_odometry(path: Path | str) -> dict[str, np.ndarray]:
    """Per robot, the (ticks, 4) array of odometry (t [s], x, y, yaw) the controllers received."""
    rows: dict[str, list[tuple[float, float, float, float]]] = {}
    for m in read_bag(Path(path)):
        if m.topic.endswith("/" + topics.ODOM):
            robot = m.topic.strip("/").split("/")[0]
            stamp, pose, _, _ = odometry.decode_odometry(m.data)
            rows.setdefault(robot, []).append((stamp / NS_PER_S, pose.x, pose.y, pose.yaw))
    return {r: np.array(v) for r, v in sorted(rows.items(), key=lambda kv: robot_index(kv[0]))}

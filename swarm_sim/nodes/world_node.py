"""The world node: puts the `World` core on the ROS graph, owns sim time, records the run.

Lockstep (default): for each tick k it publishes ``/clock`` and every robot's observations
stamped k, waits until every live controller has answered with a ``cmd_vel`` stamped k and
every server the scenario needs (center, depot manager) with a ``/lockstep/ack`` stamped k (a
controller silent for `tick_timeout` wall seconds is counted stale and keeps its last command),
then steps the core. A node stale `dead_after` ticks in a row is declared dead for good
(`swarm_sim.nodes.lockstep`), with a ``node_down`` event on ``/world/events``: a dead robot
stands still to the end and the servers free what it held; a dead server ends the run there
(the bag says ``ended: server <channel> died``). Free-running (`realtime`): steps every dt / real_time_factor wall
seconds with whatever commands have arrived.

Observations (and the world task's state topics, e.g. the caging object's pose) are encoded
straight to CDR bytes, published raw and written to the bag as the same bytes. Topics published by other nodes are discovered and recorded too (like
``ros2 bag record -a``), stamped with the sim time at which they arrive.
"""

from __future__ import annotations

import argparse
import json
import signal
import sys
import time
from dataclasses import dataclass
from pathlib import Path

import rclpy
from rclpy.executors import Executor, ExternalShutdownException
from rclpy.node import Node
from rclpy.signals import SignalHandlerOptions

from swarm_msgs_py import ack as ack_codec
from swarm_msgs_py import clock as clock_codec
from swarm_msgs_py import diagnostics, markers, odometry, scan, topics, twist
from swarm_msgs_py.executor import make_executor
from swarm_msgs_py.params import declare_config
from swarm_msgs_py.qos import EVENTS, SENSOR_LOCKSTEP, STATE_LATCHED
from swarm_msgs_py.sensing import Sensing
from swarm_sim import registry
from swarm_sim.cli import number
from swarm_sim.inbound import Inbound, Reason, Rejections
from swarm_sim.nodes.lockstep import LockstepBarrier
from swarm_sim.nodes.recorder import Recorder
from swarm_sim.scenario import (
    DEFAULT_SCENARIO,
    Scenario,
    load_scenario,
    scenario_to_dict,
)
from swarm_sim.types import NS_PER_S, Command, NodeDownEvent, Observation, RobotId
from swarm_sim.world import World


_IMPORTED = time.monotonic()
"""When this module's imports were done (start-up lines count from here)."""


class Interrupted(Exception):
    """SIGINT or SIGTERM arrived: stop at the next safe point and close the bag."""


@dataclass(frozen=True)
class WorldNodeConfig:
    scenario: str = DEFAULT_SCENARIO
    """Scenario name or YAML path."""
    overrides: tuple[str, ...] = ()
    """``a.b=VALUE`` scenario overrides."""
    seed: int = 0
    mode: str = "lockstep"
    """`lockstep` or `realtime`."""
    tick_timeout: float = 2.0
    """Lockstep: wall seconds to wait for a controller's answer before counting it stale."""
    resend_period: float = 0.25
    """Lockstep: wall seconds after which a tick's observations are re-sent to controllers
    that have not answered (they answer a repeated tick with their cached command)."""
    dead_after: int = 3
    """Lockstep: stale ticks in a row after which a node (controller or server) is declared
    dead: with the default tick timeout, 6 s of silence."""
    real_time_factor: float = 1.0
    """Realtime mode: target sim seconds per wall second."""
    bag: str = ""
    """Bag directory to record to ('' records nothing)."""
    startup_timeout: float = 120.0
    """Wall seconds to wait for every controller to connect before starting anyway."""
    progress_period: float = 2.0
    """Wall seconds between progress lines."""
    stats_period: float = 1.0
    """Sim seconds between ``/world/robot_stats`` messages."""
    markers_period: float = 5.0
    """Sim seconds between ``/world/markers`` messages."""
    foxglove_port: int = -1
    """Serve the run live over the Foxglove WebSocket protocol on this port (0: any free port;
    -1: no live view), `swarm_sim.nodes.live_view`."""
    foxglove_host: str = "127.0.0.1"
    """Address the live view binds (loopback unless asked otherwise)."""


class WorldNode(Node):
    def __init__(self, config: WorldNodeConfig | None = None, **kwargs) -> None:
        super().__init__("world", **kwargs)
        self.config = cfg = declare_config(self, WorldNodeConfig, config)
        if cfg.mode not in ("lockstep", "realtime"):
            raise ValueError(f"mode: expected 'lockstep' or 'realtime', got {cfg.mode!r}")
        self.scenario: Scenario = load_scenario(cfg.scenario, cfg.overrides, seed=cfg.seed)
        self.world = World(self.scenario, cfg.seed)
        self.robots: tuple[RobotId, ...] = self.world.robots
        self.recorder = self._open_recorder(cfg.bag) if cfg.bag or cfg.foxglove_port >= 0 else None

        self._clock_pub = self._publisher(topics.CLOCK, SENSOR_LOCKSTEP)
        self._events_pub = self._publisher(topics.WORLD_EVENTS, EVENTS)
        self._stats_pub = self._publisher(topics.WORLD_ROBOT_STATS, STATE_LATCHED)
        self._markers_pub = self._publisher(topics.WORLD_MARKERS, STATE_LATCHED)
        algorithm = registry.of(self.scenario)
        self.sensing: Sensing = registry.resolve(registry.task(algorithm.task).sensing)
        """The task's sense topics, published next to odometry and scan."""
        obs_types = {topics.ODOM: topics.ROBOT_TOPIC_TYPES[topics.ODOM],
                     topics.SCAN: topics.ROBOT_TOPIC_TYPES[topics.SCAN],
                     **{t.name: t.type_name for t in self.sensing.topics}}
        state = registry.task(algorithm.task).state
        self.state_topics = registry.resolve(state) if state else ()
        """The task's world-level state topics (`swarm_msgs_py.sensing.StateTopic`), every tick."""
        self._state_pubs = [self._publisher(st.topic, SENSOR_LOCKSTEP, st.type_name) for st in self.state_topics]
        self._obs_pubs = {
            r: {
                name: self._publisher(topics.robot_topic(r, name), SENSOR_LOCKSTEP, type_name)
                for name, type_name in obs_types.items()
            }
            for r in self.robots
        }
        self._commands: dict[RobotId, Command] = {}
        self._sent: dict[RobotId, dict[str, bytes]] = {}
        """This tick's encoded observations per robot, to re-send if an answer is late."""
        self.servers: tuple[str, ...] = tuple(spec.channel for spec in algorithm.servers)
        """Server channels (center, depot) the barrier waits for besides the robots."""
        self.server_stale_ticks = dict.fromkeys(self.servers, 0)
        """Lockstep ticks each server (by channel) did not acknowledge in time."""
        self.rejections = Rejections()
        """Commands and acks dropped: malformed, for another tick, from a dead or unknown node."""
        self._published_rejections: dict = {}
        # Latched and not recorded by the world itself: every node publishes its counts here and
        # the recorder records them all (its own included) through one subscription.
        self._diagnostics_pub = self.create_publisher(
            topics.type_of(topics.DIAGNOSTICS), topics.DIAGNOSTICS, STATE_LATCHED)
        self.barrier = LockstepBarrier((*self.robots, *self.servers), cfg.dead_after)
        self.down: list[NodeDownEvent] = []
        """Nodes declared dead, in order."""
        self._down_events: list[NodeDownEvent] = []
        self.ended = "complete"
        """How the run ended: ``complete``, ``interrupted`` or ``server <channel> died``."""
        self._cmd_topic = {topics.robot_topic(r, topics.CMD_VEL): r for r in self.robots}
        self._cmd_subs = {}
        for topic, robot in self._cmd_topic.items():
            self._record_topic(topic, topics.type_string(topic))
            self._cmd_subs[robot] = self.create_subscription(
                topics.type_of(topic), topic, lambda data, r=robot: self._on_cmd(r, data),
                SENSOR_LOCKSTEP, raw=True,
            )
        if self.servers:
            self._record_topic(topics.LOCKSTEP_ACK, topics.type_string(topics.LOCKSTEP_ACK))
            self._ack_sub = self.create_subscription(
                topics.type_of(topics.LOCKSTEP_ACK), topics.LOCKSTEP_ACK, self._on_ack,
                SENSOR_LOCKSTEP, raw=True,
            )
        self.inbound = Inbound(self.robots, self.scenario.dt_ns, self.rejections, self.get_logger().warning)
        self._relays = {}
        """Peer topic -> publisher on ``heard(topic)``: the world relays what robots send each
        other, like a radio medium (`_on_peer`)."""
        self._relayed: list[tuple[str, bytes]] = []
        for topic, family in registry.peer_topics(algorithm).items():
            msg_type = topics.import_type(family.type_name)
            self._record_topic(topic, family.type_name)
            if self.recorder is not None:
                self.recorder.skipped.add(topics.heard(topic))  # the relay's copies: recorded once, as sent
            self._relays[topic] = self.create_publisher(msg_type, topics.heard(topic), EVENTS)
            self.create_subscription(msg_type, topic, lambda data, t=topic, f=family: self._on_peer(t, f, data),
                                     EVENTS, raw=True)
        self._next_discovery = 0.0

    # ------------------------------------------------------------------ plumbing

    def _publisher(self, topic: str, qos, type_name: str | None = None):
        type_name = type_name or topics.type_string(topic)
        self._record_topic(topic, type_name, latched=qos is STATE_LATCHED)
        return self.create_publisher(topics.import_type(type_name), topic, qos)

    def _record_topic(self, topic: str, type_name: str, latched: bool = False) -> None:
        if self.recorder is not None:
            self.recorder.add(topic, type_name, latched)

    def _record(self, topic: str, data: bytes) -> None:
        if self.recorder is not None:
            self.recorder.write(topic, data)

    def _open_recorder(self, path: str) -> Recorder:
        meta = {
            "scenario_name": self.scenario.name,
            "scenario": json.dumps(scenario_to_dict(self.scenario)),
            "seed": str(self.config.seed),
            "mode": self.config.mode,
            "robots": str(len(self.world.robots)),
        }
        live = None
        if self.config.foxglove_port >= 0:
            from swarm_sim.nodes.live_view import LiveView

            live = LiveView(self.config.foxglove_port, self.config.foxglove_host)
        return Recorder(self, Path(path) if path else None, meta, lambda: self.world.t_ns, live)

    def _publish(self, pub, data: bytes, topic: str, *, send: bool = True) -> None:
        if send:
            pub.publish(data)
        self._record(topic, data)

    @property
    def rejected_commands(self) -> int:
        """Commands dropped so far (any reason)."""
        return sum(n for (where, _), n in self.rejections.counts.items() if where.endswith("/" + topics.CMD_VEL))

    def _on_cmd(self, robot: RobotId, data: bytes) -> None:
        topic = topics.robot_topic(robot, topics.CMD_VEL)
        self._record(topic, data)
        try:
            stamp_ns, linear, angular = twist.decode_twist(data)
        except ValueError as exc:
            self.inbound.reject(topic, Reason.MALFORMED, str(exc))
            return
        if robot in self.barrier.dead:
            self.inbound.reject(topic, Reason.DEAD, f"{robot} was declared dead; its robot stays stopped")
            return
        if self.config.mode == "lockstep" and stamp_ns != self.world.t_ns:
            if self.barrier.has_answered(robot, stamp_ns):
                return  # its answer again, to a tick the world re-sent (`resend_period`) and has closed
            # A command for another tick (late, or forged on the bus) would break lockstep.
            late = 0 <= stamp_ns < self.world.t_ns and stamp_ns % self.world.dt_ns == 0
            if late:
                self.barrier.heard(robot)  # slow, not dead
            self.inbound.reject(topic, Reason.LATE if late else Reason.WRONG_TICK,
                                f"stamped {stamp_ns} ns at tick {self.world.t_ns} ns")
            return
        self._commands[robot] = Command(linear, angular)
        self.barrier.answered(robot, stamp_ns)

    def _on_ack(self, data: bytes) -> None:
        self._record(topics.LOCKSTEP_ACK, data)
        try:
            channel, stamp_ns = ack_codec.decode_ack(data)
        except ValueError as exc:
            self.inbound.reject(topics.LOCKSTEP_ACK, Reason.MALFORMED, str(exc))
            return
        if channel not in self.servers:
            self.inbound.reject(topics.LOCKSTEP_ACK, Reason.UNKNOWN_NODE, f"no server {channel[:40]!r} in this run")
        elif channel in self.barrier.dead:
            self.inbound.reject(topics.LOCKSTEP_ACK, Reason.DEAD, f"server {channel} was declared dead")
        elif stamp_ns < self.world.t_ns:
            self.barrier.heard(channel)  # an ack for a tick already closed: slow, not dead
        else:
            self.barrier.answered(channel, stamp_ns)

    def _on_peer(self, topic: str, family, data: bytes) -> None:
        """A robot's message to the others: recorded, checked (`swarm_sim.inbound`) and relayed
        on ``heard(topic)`` just before the next tick's observations. Lockstep order makes this
        exact: a robot publishes its messages of tick k before its command k, so they are here
        before the barrier lets tick k+1 out, and they leave before its observations, from the
        same sender, in order."""
        self._record(topic, data)
        try:
            messages = family.decode(data)
        except ValueError as exc:
            self.inbound.reject(topic, Reason.MALFORMED, str(exc)[:200])
            return
        if all([self.inbound.admit(topic, m) for m in messages]):  # a list: every bad one is counted
            self._relayed.append((topic, data))

    def _discover(self) -> None:
        """Record every topic other nodes publish (and warn about unknown robot namespaces)."""
        if self.recorder is not None:
            self.recorder.discover(self._warn_unknown_commands)

    def _warn_unknown_commands(self, topic: str) -> None:
        if topic.endswith("/" + topics.CMD_VEL) and topic not in self._cmd_topic:
            self.get_logger().warning(f"ignoring commands on {topic}: unknown robot namespace")

    # ------------------------------------------------------------------ the loop

    def _publish_tick(self, obs: dict[RobotId, Observation], *, send: bool = True) -> None:
        """Tick k's clock and observations; `send=False` records them without asking the
        controllers for another answer (the state at the end of the run)."""
        t_ns = self.world.t_ns
        self.inbound.now_ns = self.inbound.released_ns = t_ns
        if send:  # what robots sent each other at the last tick, before this tick's observations
            for topic, data in self._relayed:
                self._relays[topic].publish(data)
        self._relayed = []
        self._publish(self._clock_pub, clock_codec.encode_clock(t_ns), topics.CLOCK, send=send)
        sc = self.scenario.sensors.scan
        # Encode the unrounded odometry: the decoder applies the quaternion rounding exactly once,
        # as World.observe does for the batch runner (rounding twice can move yaw by an ulp).
        poses = self.world.odometry_poses()
        for r, o in obs.items():
            pubs = self._obs_pubs[r]
            encoded = {
                topics.ODOM: odometry.encode_odometry(r, t_ns, poses[r], o.linear_velocity, o.angular_velocity),
                topics.SCAN: scan.encode_scan(r, t_ns, o.ranges, sc),
                **self.sensing.encode_all(t_ns, o.sensed),
            }
            for name, data in encoded.items():
                self._publish(pubs[name], data, topics.robot_topic(r, name), send=send)
            self._sent[r] = encoded
        if self.state_topics:
            values = self.world.task.state()
            for st, pub in zip(self.state_topics, self._state_pubs):
                self._publish(pub, st.encode(t_ns, values[st.field]), st.topic, send=send)

    def _publish_world_state(self, final: bool = False) -> None:
        t_ns = self.world.t_ns
        events = [*self._down_events, *self.world.drain_events()]
        self._down_events = []
        if events:
            self._publish(self._events_pub, diagnostics.encode_events(t_ns, events), topics.WORLD_EVENTS)
        stats_every = max(1, round(self.config.stats_period / self.scenario.sim.dt))
        if final or self.world.tick % stats_every == 0:
            self._publish(self._stats_pub, diagnostics.encode_robot_stats(t_ns, self.world.stats),
                          topics.WORLD_ROBOT_STATS)
        markers_every = max(1, round(self.config.markers_period / self.scenario.sim.dt))
        if final or self.world.tick % markers_every == 0:
            data = markers.encode_markers(
                self.scenario, t_ns, self.world.task.placed(), self.world.true_poses()
            )
            self._publish(self._markers_pub, data, topics.WORLD_MARKERS)
        counts = dict(sorted(self.rejections.counts.items()))
        if counts != self._published_rejections:
            self._published_rejections = counts
            self._diagnostics_pub.publish(diagnostics.encode_rejections(t_ns, self.get_fully_qualified_name(), counts))

    def _start_live_view(self) -> None:
        """Serve Foxglove clients once the run's topics exist (`swarm_sim.nodes.live_view`)."""
        live = self.recorder.live if self.recorder is not None else None
        if live is not None:
            self._discover()
            live.start()
            print(f"[world] live view: {live.url} (Foxglove: Open connection -> Foxglove WebSocket)", flush=True)

    def wait_for_controllers(self, executor: Executor) -> None:
        start = time.monotonic()
        print(f"[world] up ({start - _IMPORTED:.1f} s after its imports to build the world and the topics of "
              f"{len(self.robots)} robots); waiting for the controllers{' and servers' if self.servers else ''} to connect", flush=True)
        deadline = start + self.config.startup_timeout
        missing = list(self.robots)
        said = start
        while missing and time.monotonic() < deadline:
            self._spin(executor, 0.1)
            missing = [
                r for r in self.robots
                if self._cmd_subs[r].get_publisher_count() == 0
                or any(p.get_subscription_count() == 0 for p in self._obs_pubs[r].values())
            ]
            if self.servers and self._ack_sub.get_publisher_count() < len(self.servers):
                missing.append("servers (" + ", ".join(self.servers) + ")")
            if missing and time.monotonic() - said >= self.config.progress_period:
                said = time.monotonic()
                self.print_startup(missing, said - start)
        print(f"[world] {len(self.robots) - len([m for m in missing if m in self._cmd_subs])}/{len(self.robots)} "
              f"controllers connected after {time.monotonic() - start:.1f} s: starting", flush=True)
        if missing:
            self.get_logger().warning(
                f"starting without {len(missing)} controller(s) that did not connect: {missing[:5]}"
            )

    stop_requested = False
    """Set by `main`'s SIGINT/SIGTERM handler; the run stops at its next spin."""

    def _spin(self, executor: Executor, timeout: float) -> float:
        """Spin once; returns the wall seconds the bag took (flush/split), which must not
        count against the controllers' deadline. Raises Interrupted once a stop is requested."""
        if self.stop_requested:
            raise Interrupted
        executor.spin_once(timeout_sec=timeout)
        if self.recorder is None:
            return 0.0
        t0 = time.monotonic()
        self.recorder.poll()
        return time.monotonic() - t0

    def _await_commands(self, executor: Executor) -> None:
        """Lockstep barrier: spin until every live controller and server answered this tick."""
        stamp = self.world.t_ns
        waiting = self.barrier.live()
        now = time.monotonic()
        deadline, resend = now + self.config.tick_timeout, now + self.config.resend_period
        while True:
            waiting = self.barrier.waiting(stamp, waiting)
            now = time.monotonic()
            if not waiting:
                break
            if now >= deadline:  # take what has already arrived before calling anyone stale
                for _ in range(4 * len(waiting)):
                    executor.spin_once(timeout_sec=0.0)
                break
            if now >= resend:  # a sample lost (e.g. while discovery settles): ask again
                resend = now + self.config.resend_period
                for r in waiting:
                    if r in self._sent:
                        for name, data in self._sent[r].items():
                            self._obs_pubs[r][name].publish(data)
                    else:  # a server: it answers a repeated /clock with its ack
                        self._clock_pub.publish(clock_codec.encode_clock(stamp))
            bag_time = self._spin(executor, min(0.05, max(0.0, deadline - now)))
            deadline += bag_time
            resend += bag_time
        stale, dead = self.barrier.close_tick(stamp)
        for r in stale:
            if r in self.world.stats:
                self.world.stats[r].stale_ticks += 1
            else:
                self.server_stale_ticks[r] += 1
        for r in dead:
            kind = "robot" if r in self.world.stats else "server"
            event = NodeDownEvent(r, stamp, kind, self.barrier.dead_after)
            self.down.append(event)
            self._down_events.append(event)
            if kind == "robot":
                self.get_logger().error(f"{r}: no answer for {self.barrier.dead_after} ticks: declared dead; "
                                        "its robot stands still to the end and the servers free what it held")
                self._commands[r] = Command()  # a dead controller's robot must not drive on blind
            else:
                self.get_logger().error(f"server {r}: no ack for {self.barrier.dead_after} ticks: declared dead; "
                                        "the run ends here")
                self.ended = f"server {r} died"

    def _await_wall(self, executor: Executor, until: float) -> None:
        while (remaining := until - time.monotonic()) > 0:
            self._spin(executor, min(0.05, remaining))
        stamp = self.world.t_ns
        for r in self.barrier.waiting(stamp, self.robots):
            self.world.stats[r].stale_ticks += 1

    def run(self, executor: Executor) -> None:
        cfg, sim = self.config, self.scenario.sim
        self._discover()
        self.wait_for_controllers(executor)
        self._start_live_view()
        obs = self.world.reset()
        wall0 = last_progress = time.monotonic()
        self.wall_start = wall0
        for k in range(self.scenario.ticks):
            now = time.monotonic()
            if now >= self._next_discovery:
                self._discover()
                self._next_discovery = now + 1.0
            self._publish_tick(obs)
            if cfg.mode == "lockstep":
                self._await_commands(executor)
            else:
                self._await_wall(executor, wall0 + (k + 1) * sim.dt / cfg.real_time_factor)
            obs = self.world.step({r: self._commands[r] for r in self.robots if r in self._commands})
            self._publish_world_state()
            if now - last_progress >= cfg.progress_period:
                last_progress = now
                self.print_progress(now - wall0)
            if self.ended != "complete":
                break
        self._publish_tick(obs, send=False)
        self._publish_world_state(final=True)
        # Let the controllers' last status messages reach the recorder.
        end = time.monotonic() + 0.5
        while time.monotonic() < end:
            self._spin(executor, 0.05)

    def print_startup(self, missing: list[str], waited: float) -> None:
        """What the start-up is waiting for (nodes starting and discovering each other)."""
        robots = [m for m in missing if m in self._cmd_subs]
        others = [m for m in missing if m not in self._cmd_subs]
        text = f"{len(self.robots) - len(robots)}/{len(self.robots)} controllers connected"
        if robots:
            text += f", waiting for {', '.join(robots[:3])}{' ...' if len(robots) > 3 else ''}"
        if others:
            text += f"; waiting for {', '.join(others)}"
        print(f"[world] start-up {waited:5.1f} s: {text} (gives up after {self.config.startup_timeout:.0f} s)",
              flush=True)

    def print_progress(self, wall: float) -> None:
        t = self.world.t_ns / NS_PER_S
        stale = sum(s.stale_ticks for s in self.world.stats.values())
        print(
            f"[world] t={t:7.1f}/{self.scenario.sim.duration:.0f} s  rtf={t / max(wall, 1e-9):5.2f}x  "
            f"{self.world.task.progress()}  stale={stale}",
            flush=True,
        )

    def close(self) -> None:
        if self.recorder is not None:
            self.recorder.close(
                wall_seconds=f"{time.monotonic() - getattr(self, 'wall_start', time.monotonic()):.3f}",
                sim_seconds=f"{self.world.t_ns / NS_PER_S:.6f}",
                server_stale_ticks=json.dumps(self.server_stale_ticks),
                ended=self.ended,
                dead_nodes=json.dumps([e.node for e in self.down]),
            )
        self.world.close()


def parse_args(argv: list[str]) -> tuple[WorldNodeConfig, list[str]]:
    parser = argparse.ArgumentParser(prog="swarm-world", description=__doc__.splitlines()[0])
    parser.add_argument("--scenario", default=DEFAULT_SCENARIO)
    parser.add_argument("--set", dest="overrides", action="append", default=[], metavar="KEY=VALUE")
    parser.add_argument("--seed", type=number(int, 0, 2**63 - 1), default=0)
    parser.add_argument("--mode", choices=("lockstep", "realtime"), default="lockstep")
    parser.add_argument("--tick-timeout", type=number(float, 0, 3600, open_low=True), default=WorldNodeConfig.tick_timeout)
    parser.add_argument("--real-time-factor", type=number(float, 0, 1e6, open_low=True), default=1.0)
    parser.add_argument("--bag", default="")
    parser.add_argument("--foxglove", type=number(int, 0, 65535), default=-1, metavar="PORT",
                        help="serve the run over the Foxglove WebSocket protocol (0: any free port)")
    parser.add_argument("--foxglove-host", default=WorldNodeConfig.foxglove_host)
    args, ros_args = parser.parse_known_args(argv)
    config = WorldNodeConfig(
        scenario=args.scenario, overrides=tuple(args.overrides), seed=args.seed, mode=args.mode,
        tick_timeout=args.tick_timeout, real_time_factor=args.real_time_factor, bag=args.bag,
        foxglove_port=args.foxglove, foxglove_host=args.foxglove_host,
    )
    return config, ros_args


def main(argv: list[str] | None = None) -> int:
    config, ros_args = parse_args(sys.argv[1:] if argv is None else argv)
    # Our own signal handling: rclpy's handler shuts the context down under the running loop,
    # which then waited out tick timeouts instead of stopping. A flag checked at every spin
    # stops the run promptly wherever it is.
    rclpy.init(args=["swarm-world", *ros_args], signal_handler_options=SignalHandlerOptions.NO)
    node = None
    signal.signal(signal.SIGINT, signal.default_int_handler)  # until the node exists
    try:
        node = WorldNode(config)

        def request_stop(*_: object) -> None:
            node.stop_requested = True

        signal.signal(signal.SIGINT, request_stop)
        signal.signal(signal.SIGTERM, request_stop)
        executor = make_executor()
        executor.add_node(node)
        node.run(executor)
        if node.stop_requested:
            raise Interrupted
    except (KeyboardInterrupt, ExternalShutdownException, Interrupted):
        print("[world] interrupted: closing the bag", flush=True)
        if node is not None:
            node.ended = "interrupted"
    finally:
        if node is not None:
            node.close()
            node.destroy_node()
        rclpy.try_shutdown()
    return 0


if __name__ == "__main__":
    sys.exit(main())

"""The world node: puts the `World` core on the ROS graph, owns sim time, records the run.

Every tick k it publishes ``/clock``, every robot's observations stamped k (odometry, scan and
the world task's sense: `topics.OBSERVATIONS`) and the task's state topics, then waits for the
robots' commands and the servers' acks (`swarm_sim.nodes.world_loop`: lockstep by default, or
free-running) and steps the core. A node stale `dead_after` ticks in a row is declared dead for
good (`swarm_sim.nodes.lockstep`), with a ``node_down`` event on ``/world/events``: a dead robot
stands still to the end and the servers free what it held; a dead server ends the run there
(the bag says ``ended: server <channel> died``).

Its parts, each in its own module: the loop (`world_loop`), the recorder hooks
(`world_recording`: the world's own bytes and every other node's topics go into the bag), the
relay of what robots send each other (`peer_relay`) and what it shows besides the observations
(`world_outputs`: events, stats, markers, diagnostics, live view). This module holds the node
itself: its observation publishers, its intake of commands and acks, and its command line.

Observations (and the task's state topics, e.g. the caging object's pose) are encoded straight
to CDR bytes, published raw and written to the bag as the same bytes; with ``--publish-shards K``
K processes of their own publish the observations from shared memory (`publish_shard`).

What it hears is untrusted (`swarm_sim.inbound`): commands, acks (which must carry the run's tag,
`swarm_msgs_py.auth`) and robots' messages pass its guard, and what it refuses is recorded on the
topic's refused channel. It watches the graph for foreign publishers on the run's topics
(`swarm_sim.nodes.taint`), and starts only once every server's own node acknowledges.
"""

from __future__ import annotations

import argparse
import json
import signal
import sys
import time
from dataclasses import dataclass

import rclpy
from rclpy.executors import Executor, ExternalShutdownException
from rclpy.node import Node
from rclpy.signals import SignalHandlerOptions

from swarm_msgs_py import ack as ack_codec
from swarm_msgs_py import auth, odometry, scan, topics, twist
from swarm_msgs_py import clock as clock_codec
from swarm_msgs_py.sensing import Sensing
from swarm_msgs_py.types import FINISHED, NS_PER_S, Command, NodeDownEvent, Observation, RobotId
from swarm_sim import registry
from swarm_sim.cli import first_paragraph, number
from swarm_sim.inbound import Bounds, Inbound, Reason, Rejections
from swarm_sim.nodes.command_watch import CommandWatch
from swarm_sim.nodes.executor import make_executor
from swarm_sim.nodes.lifetime import leave
from swarm_sim.nodes.lockstep import LockstepBarrier
from swarm_sim.nodes.endpoint import ack_wait
from swarm_sim.nodes.params import declare_config
from swarm_sim.nodes.peer_relay import PeerRelay
from swarm_sim.nodes.publish_shard import PublishShards, ShardDied, ShardEnvironmentError
from swarm_sim.nodes.qos import SENSOR_LOCKSTEP
from swarm_sim.nodes.run_watch import END_ACK_WAIT, END_ACK_WAIT_HERE, RunBeacon
from swarm_sim.nodes.status_watch import StatusWatch
from swarm_sim.nodes.taint import ForeignWatch
from swarm_sim.nodes.world_loop import Interrupted, WorldLoop
from swarm_sim.nodes.world_outputs import WorldOutputs
from swarm_sim.nodes.world_recording import WorldRecording
from swarm_sim.scenario import Scenario, ScenarioError, load_scenario
from swarm_sim.world import World
from swarm_sim.world.core import tune_malloc

COMMAND_BYTES = 512
"""Cap on a ``cmd_vel`` message [bytes] (ours are under 100)."""
ACK_BYTES = 256
"""Cap on a ``/lockstep/ack`` message [bytes]."""
_DECODE_ACK = auth.verified(ack_codec.decode_ack)
"""An ack must carry the run's tag when the run has a key (`swarm_msgs_py.auth`)."""


@dataclass(frozen=True)
class WorldNodeConfig:
    scenario: str = ""
    """Scenario name or YAML path ('': the default scenario)."""
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
    pace: float = 0.0
    """Lockstep: at most this many sim seconds per wall second, so a live view can be watched
    (0: as fast as every node answers). Only adds waits: the run's results do not change."""
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
    plain_twist: tuple[str, ...] = ()
    """Realtime: robots whose commands come as plain ``geometry_msgs/Twist`` (a robot's own
    computer on wall-clock time, TurtleBot-style: no stamp); a command's time is the tick it
    arrived at."""
    publish_shards: int = 0
    """Observations published by this many processes of their own (`swarm_sim.nodes.publish_shard`;
    0: by the world itself)."""


class WorldConfigError(ValueError):
    """A world node configuration that cannot run (one line, exit 2: `main`)."""


class WorldNode(Node):
    def __init__(self, config: WorldNodeConfig | None = None, **kwargs) -> None:
        super().__init__("world", **kwargs)
        self.config = cfg = declare_config(self, WorldNodeConfig, config)
        if cfg.mode not in ("lockstep", "realtime"):
            raise WorldConfigError(f"mode: expected 'lockstep' or 'realtime', got {cfg.mode!r}")
        if cfg.plain_twist and cfg.mode != "realtime":
            raise WorldConfigError("plain_twist: a plain Twist carries no tick, so only a realtime run can take it")
        self.scenario: Scenario = load_scenario(cfg.scenario, cfg.overrides, seed=cfg.seed)
        self.world = World(self.scenario, registry.task_factory(self.scenario), cfg.seed)
        self.robots: tuple[RobotId, ...] = self.world.robots
        if unknown := set(cfg.plain_twist) - set(self.robots):
            raise WorldConfigError(f"plain_twist: no robot {sorted(unknown)[0]!r} in this run")
        if not 0 <= cfg.publish_shards <= len(self.robots):
            raise WorldConfigError(f"publish_shards: expected 0-{len(self.robots)} (the run's robots), got {cfg.publish_shards}")
        self.watch = ForeignWatch(self.scenario, self.get_publishers_info_by_topic, self._count_publishers,
                                  self.get_node_names_and_namespaces, self.get_publisher_names_and_types_by_node,
                                  cfg.publish_shards)
        """The graph's publishers on the run's topics: foreign ones are reported (`check_foreign`)."""
        self.foreign: list[str] = []
        """The foreign publishers found whose messages may have reached a core: the run is tainted."""
        self.recording = WorldRecording(self, cfg, self.scenario, len(self.robots), lambda: self.world.t_ns,
                                        {t: spec.type_name for t, spec in self.watch.topics.items()},
                                        self._ours)
        self.recorder = self.recording.recorder
        """The bag (and live view) writer; None when the run records nothing."""
        self.rejections = Rejections()
        """Commands, acks and robots' messages dropped: malformed, for another tick, from a dead
        or unknown node."""

        self._clock_pub = self.recording.publisher(topics.CLOCK, SENSOR_LOCKSTEP)
        self.outputs = WorldOutputs(self, self.recording, self.scenario, self.rejections,
                                    stats_period=cfg.stats_period, markers_period=cfg.markers_period)
        algorithm = registry.of(self.scenario)
        self.sensing: Sensing = registry.resolve(registry.task(algorithm.task).sensing)
        """The task's sense message, published next to odometry and scan."""
        state = registry.task(algorithm.task).state
        self.state_topics = registry.resolve(state) if state else ()
        """The task's world-level state topics (`swarm_msgs_py.sensing.StateTopic`), every tick."""
        self._state_pubs = [self.recording.publisher(st.topic, SENSOR_LOCKSTEP, st.type_name)
                            for st in self.state_topics]
        self.shards: PublishShards | None = None
        """The processes that publish the observations (``publish_shards``); None: the world does."""
        self._obs_pubs = {}
        if cfg.publish_shards:
            for r in self.robots:
                for name in topics.OBSERVATIONS:
                    topic = topics.robot_topic(r, name)
                    self.recording.add(topic, topics.type_string(topic))
            self.shards = PublishShards(self.robots, cfg.publish_shards, self.get_logger().warning)
        else:
            self._obs_pubs = {
                r: {
                    name: self.recording.publisher(topics.robot_topic(r, name), SENSOR_LOCKSTEP)
                    for name in topics.OBSERVATIONS
                }
                for r in self.robots
            }
        # rclpy's `Publisher.publish` around the raw publish (a handle context, two type checks) was
        # half of a raw publish's Python, 336 times a tick with 112 robots: the tick calls the
        # publisher's own `publish_raw` (with shards: None, the shard publishes).
        self._obs_targets = {r: {name: (None if self.shards else self._obs_pubs[r][name].handle.publish_raw,
                                        topics.robot_topic(r, name))
                                 for name in topics.OBSERVATIONS}
                             for r in self.robots}
        """Robot -> observation name -> (raw publish, topic)."""
        self._commands: dict[RobotId, Command] = {}
        realtime = cfg.mode == "realtime"
        self.command_watch = CommandWatch(self.robots, self.scenario.dt_ns, self.scenario.ticks,
                                          round(self.scenario.sim.command_timeout * NS_PER_S) if realtime else 0)
        """Late, lost, re-sent commands per robot; realtime: the command timeout."""
        self._taken_cmd: dict[RobotId, bytes] = {}
        """Each robot's last command taken, as received (its repeats are not recorded again)."""
        self._sent: dict[RobotId, dict[str, bytes]] = {}
        """This tick's encoded observations per robot, to re-send if an answer is late."""
        self.servers: tuple[str, ...] = tuple(spec.channel for spec in algorithm.servers)
        """Server channels (center, depot) the barrier waits for besides the robots."""
        self.server_stale_ticks = dict.fromkeys(self.servers, 0)
        """Lockstep ticks each server (by channel) did not acknowledge in time."""
        self.barrier = LockstepBarrier((*self.robots, *self.servers), cfg.dead_after)
        self.down: list[NodeDownEvent] = []
        """Nodes declared dead, in order."""
        self._down_events: list[NodeDownEvent] = []
        self.ended = "complete"
        """How the run ended: ``complete``, ``finished`` (``sim.stop_when_finished``), ``interrupted``
        or ``server <channel> died``."""
        self._cmd_topic = {topics.robot_topic(r, topics.CMD_VEL): r for r in self.robots}
        self._topic_of_cmd = {r: t for t, r in self._cmd_topic.items()}
        self._cmd_subs = {}
        for topic, robot in self._cmd_topic.items():
            type_name = twist.PLAIN_TYPE_NAME if robot in cfg.plain_twist else topics.type_string(topic)
            self.recording.add(topic, type_name)
            self._cmd_subs[robot] = self.create_subscription(
                topics.import_type(type_name), topic, lambda data, r=robot: self._on_cmd(r, data),
                SENSOR_LOCKSTEP, raw=True,
            )
            self.watch.hear(topic, self._cmd_subs[robot].get_publisher_count)
        if self.servers:
            self.recording.add(topics.LOCKSTEP_ACK, topics.type_string(topics.LOCKSTEP_ACK))
            self._ack_sub = self.create_subscription(
                topics.type_of(topics.LOCKSTEP_ACK), topics.LOCKSTEP_ACK, self._on_ack,
                SENSOR_LOCKSTEP, raw=True,
            )
            self.watch.hear(topics.LOCKSTEP_ACK, self._ack_sub.get_publisher_count)
        self.inbound = Inbound(self.robots, self.scenario.dt_ns, self.rejections, self.get_logger().warning,
                               Bounds.of(self.scenario))
        """The world's guard: commands, acks and robots' messages decode through it."""
        self.relay = PeerRelay(self, algorithm, self.inbound, self.recording)
        for topic, sub in self.relay.subscriptions.items():
            self.watch.hear(topic, sub.get_publisher_count)
        self.statuses = StatusWatch(self, self.robots, self.inbound, self.recording, self.scenario.dt_ns)
        for topic, sub in self.statuses.subscriptions.items():
            self.watch.hear(topic, sub.get_publisher_count)
        self._progress = registry.resolve(algorithm.progress) if algorithm.progress else None
        self.loop = WorldLoop(self)
        self.beacon = RunBeacon(self, lambda: self.world.t_ns)
        """``/world/run``: the run goes on, then how it ended (`swarm_sim.nodes.run_watch`)."""

    stop_requested = False
    """Set by `main`'s SIGINT/SIGTERM handler; the run stops at its next spin."""

    def run(self, executor: Executor) -> None:
        """The whole run (`swarm_sim.nodes.world_loop`)."""
        self.loop.run(executor)

    def poll_recording(self) -> float:
        """Let the bag flush or split (`WorldRecording.poll`); the wall seconds that took."""
        return self.recording.poll()

    def start_live_view(self) -> None:
        """Serve the live view, if the run has one, once the run's topics exist."""
        self.outputs.start_live_view(self.discover)

    # ------------------------------------------------------------------ intake

    @property
    def rejected_commands(self) -> int:
        """Commands dropped so far (any reason)."""
        return sum(n for (where, reason), n in self.rejections.counts.items()
                   if where.endswith("/" + topics.CMD_VEL) and reason != Reason.FOREIGN.value)

    def _count_publishers(self, topic: str) -> int:
        """`Node.count_publishers` of a fully qualified name without rclpy's Python name expansion
        and validation (4x the cost of the count: 700 topics are counted every wall second)."""
        handle = self.handle
        count = getattr(handle, "get_count_publishers", None)
        if count is None:
            return self.count_publishers(topic)
        with handle:
            return count(topic)

    def _ours(self, topic: str, data: bytes) -> bool | None:
        """Whether a message the recorder found on a run's `topic` is the run's: with the run's tag
        where its messages carry one (`swarm_msgs_py.auth`; False: it is recorded apart); None
        (not recorded, counted ``too big``) if it is longer than any the run sends."""
        spec = self.watch.topics.get(topic)
        if spec is None:
            return True
        if len(data) > self.inbound.bounds.message_bytes:
            self.inbound.reject(topic, Reason.TOO_BIG, f"{len(data)} bytes, not recorded")
            return None
        return not spec.tagged or auth.verify(data) is not None

    def _on_cmd(self, robot: RobotId, data: bytes) -> None:
        topic = self._topic_of_cmd[robot]
        taken = self._take_cmd(robot, topic, data)
        if taken is not None:
            self.recording.write_taken(topic, data, taken)

    def _take_cmd(self, robot: RobotId, topic: str, data: bytes) -> bool | None:
        """Take a command (True), or refuse and count it (False: recorded apart); None for a robot's
        answer again to a tick it has answered (the world re-sent the tick, `resend_period`, and
        the controller repeats its answer for each re-sent topic): the bag keeps one command per
        robot and tick, as the run used."""
        plain = robot in self.config.plain_twist
        decoded = self.inbound.decode(topic, self._decode_plain if plain else twist.decode_twist, data, COMMAND_BYTES)
        if decoded is None:
            return False
        stamp_ns, linear, angular = decoded
        if robot in self.barrier.dead:
            self.inbound.reject(topic, Reason.DEAD, f"{robot} was declared dead; its robot stays stopped")
            return False
        if self.config.mode == "lockstep" and self.barrier.has_answered(robot, stamp_ns):
            if data == self._taken_cmd.get(robot):
                return None  # its answer again, to a tick the world re-sent (`resend_period`)
            self.inbound.reject(topic, Reason.REFUSED, f"a second, different command for tick {stamp_ns} ns")
            return False
        if self.config.mode == "lockstep" and stamp_ns != self.world.t_ns:
            # A command for another tick (late, or forged on the bus) would break lockstep.
            late = 0 <= stamp_ns < self.world.t_ns and stamp_ns % self.world.dt_ns == 0
            if late:
                self.barrier.heard(robot)  # slow, not dead
                self.command_watch.taken(robot, stamp_ns, self.world.t_ns)
            self.inbound.reject(topic, Reason.LATE if late else Reason.WRONG_TICK,
                                f"stamped {stamp_ns} ns at tick {self.world.t_ns} ns")
            return False
        if stamp_ns > self.world.t_ns:  # realtime: no robot can answer a tick not yet published
            self.inbound.reject(topic, Reason.WRONG_TICK, f"stamped {stamp_ns} ns at tick {self.world.t_ns} ns")
            return False
        if not self.command_watch.taken(robot, stamp_ns, self.world.t_ns):  # overtaken by a newer one
            self.inbound.reject(topic, Reason.LATE, f"stamped {stamp_ns} ns, older than the command held")
            return False
        self._commands[robot] = Command(linear, angular)
        self._taken_cmd[robot] = data
        self.barrier.answered(robot, stamp_ns)
        return True

    def _decode_plain(self, data: bytes) -> tuple[int, float, float]:
        """A plain Twist as (the tick it arrived at, linear, angular)."""
        return (self.world.t_ns, *twist.decode_plain_twist(data))

    def _on_ack(self, data: bytes) -> None:
        refused = self.rejections.total
        self._take_ack(data)
        self.recording.write_taken(topics.LOCKSTEP_ACK, data, self.rejections.total == refused)

    def _take_ack(self, data: bytes) -> None:
        decoded = self.inbound.decode(topics.LOCKSTEP_ACK, _DECODE_ACK, data, ACK_BYTES)
        if decoded is None:
            return
        channel, stamp_ns = decoded
        if channel not in self.servers:
            self.inbound.reject(topics.LOCKSTEP_ACK, Reason.UNKNOWN_NODE, f"no server {channel[:40]!r} in this run")
        elif channel in self.barrier.dead:
            self.inbound.reject(topics.LOCKSTEP_ACK, Reason.DEAD, f"server {channel} was declared dead")
        elif stamp_ns > self.world.t_ns:  # no server can have finished a tick not yet published
            self.inbound.reject(topics.LOCKSTEP_ACK, Reason.WRONG_TICK,
                                f"ack of tick {stamp_ns} ns at tick {self.world.t_ns} ns")
        elif stamp_ns < self.world.t_ns:
            self.barrier.heard(channel)  # an ack for a tick already closed: slow, not dead
        else:
            self.barrier.answered(channel, stamp_ns)

    def commands(self) -> dict[RobotId, Command]:
        """The last command of every robot that has sent one, in robot order (realtime: a robot
        whose newest command is older than ``sim.command_timeout`` stopped, `CommandWatch`)."""
        held = {r: self._commands[r] for r in self.robots if r in self._commands}
        return self.command_watch.fresh(held, self.world.t_ns)

    def close_tick(self, stamp: int) -> None:
        """Lockstep: tick `stamp` is over; count who was stale and declare who is dead."""
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

    # ------------------------------------------------------------------ the run's course

    def progress_text(self) -> str:
        """What the progress line says of the run: the algorithm's reading of the robots'
        statuses if its record declares one (the caging stage), else the task's (deliveries)."""
        if self._progress is not None:
            return self._progress(self.statuses.by_robot())
        return self.world.task.progress()

    def check_finished(self, executor: Executor) -> None:
        """``sim.stop_when_finished``: end the run once every live robot reports its task over
        (`swarm_sim.nodes.status_watch`); the bag's ``ended`` says ``finished``."""
        if self.scenario.sim.stop_when_finished and self.ended == "complete":
            self.statuses.settle(executor)
            if self.statuses.all_finished(self.barrier.dead):
                self.ended = FINISHED

    # ------------------------------------------------------------------ discovery

    def discover(self) -> None:
        """Record every topic other nodes publish (and warn about unknown robot namespaces), and
        look for foreign publishers on the run's topics."""
        self.recording.discover(self._warn_unknown_commands)
        self.check_foreign()

    def check_foreign(self) -> None:
        """Report each new foreign publisher on a run's topic (`swarm_sim.nodes.taint`): an error
        line, a ``foreign publisher`` count on ``/diagnostics``; one that can have reached a core
        (an untagged topic) taints the run."""
        for f in self.watch.check():
            self.inbound.reject(f.topic, Reason.FOREIGN, f"{f.node} (GID {f.gid[:16]}...)")
            if f.tainting:
                self.foreign.append(str(f))
                self.get_logger().error(f"a foreign publisher, {f}: none of this run's nodes; what it sends may "
                                        "reach the robots, so the run is tainted (swarm-run exits 6)")
            else:
                self.get_logger().error(f"a foreign publisher, {f}: none of this run's nodes; its messages lack "
                                        "the run's tag and are refused")

    def _warn_unknown_commands(self, topic: str) -> None:
        if topic.endswith("/" + topics.CMD_VEL) and topic not in self._cmd_topic:
            self.get_logger().warning(f"ignoring commands on {topic}: unknown robot namespace")

    def unconnected(self, among: list[str] | None = None) -> list[str]:
        """Robots (of `among`, default all) whose controller is not matched on every topic yet,
        and the servers if any has no ack publisher yet."""
        robots = self.robots if among is None else [r for r in among if r in self._cmd_subs]
        if self.shards is not None:  # each shard says which of its robots' publishers have matched
            matched = self.shards.ready()
            unmatched = lambda r: r not in matched  # noqa: E731
        else:
            unmatched = lambda r: any(p.get_subscription_count() == 0 for p in self._obs_pubs[r].values())  # noqa: E731
        missing = [r for r in robots if self._cmd_subs[r].get_publisher_count() == 0 or unmatched(r)]
        if self.servers:  # by their nodes' names: a foreign ack publisher must not stand in for one
            ready = self.watch.ready(topics.LOCKSTEP_ACK)
            waiting = [spec.node_name for spec in registry.of(self.scenario).servers if spec.node_name not in ready]
            if waiting:
                missing.append("servers (" + ", ".join(waiting) + ")")
        return missing

    # ------------------------------------------------------------------ publishing

    def publish_tick(self, obs: dict[RobotId, Observation], *, send: bool = True) -> None:
        """Tick k's clock and observations; `send=False` records them without asking the
        controllers for another answer (the state at the end of the run)."""
        t_ns = self.world.t_ns
        self.inbound.now_ns = self.inbound.released_ns = t_ns
        self.relay.flush(send=send)  # what robots sent each other at the last tick, before this tick's observations
        publish = self.recording.publish
        publish(self._clock_pub, clock_codec.encode_clock(t_ns), topics.CLOCK, send=send)
        sc = self.scenario.sensors.scan
        # Encode the unrounded odometry: the decoder applies the quaternion rounding exactly once,
        # as World.observe does for the batch runner (rounding twice can move yaw by an ulp).
        poses = self.world.odometry_poses()
        out = []  # (publisher, topic, data), published and recorded in one go
        senses: dict[int, bytes] = {}  # id(sense) -> its bytes: a task may hand robots that sense alike one reading
        for r, o in obs.items():
            targets = self._obs_targets[r]
            sense = senses.get(id(o.sensed))
            if sense is None:
                sense = senses[id(o.sensed)] = self.sensing.encode(t_ns, o.sensed)
            encoded = {
                topics.ODOM: odometry.encode_odometry(r, t_ns, poses[r], o.linear_velocity, o.angular_velocity),
                topics.SCAN: scan.encode_scan(r, t_ns, o.ranges, sc),
                topics.SENSE: sense,
            }
            out += [(*targets[name], data) for name, data in encoded.items()]
            self._sent[r] = encoded
        self.recording.publish_all(out, send=send and self.shards is None)
        if send and self.shards is not None:
            self.shards.publish(t_ns, self._sent, lambda: self.stop_requested)
        if self.state_topics:
            values = self.world.task.state()
            for st, pub in zip(self.state_topics, self._state_pubs):
                publish(pub, st.encode(t_ns, values[st.field]), st.topic, send=send)

    def resend(self, waiting: list[str], stamp: int) -> None:
        """Tick `stamp` again to those of `waiting` (robots: their observations; servers: the clock)."""
        robots = [r for r in waiting if r in self._sent]
        for r in robots:
            self.command_watch.resent[r] += 1
            if self.shards is None:
                for name, data in self._sent[r].items():
                    self._obs_pubs[r][name].publish(data)
        if self.shards is not None:  # the same tick from its region again (the world writes none before)
            self.shards.again(robots)
        for _ in range(len(waiting) - len(robots)):  # a server each: it answers a repeated /clock with its ack
            self._clock_pub.publish(clock_codec.encode_clock(stamp))

    def publish_world_state(self, final: bool = False) -> None:
        """After a step: events, stats, markers, diagnostics (`swarm_sim.nodes.world_outputs`)."""
        events, self._down_events = self._down_events, []
        self.outputs.publish(self.world, events, final=final)

    def close(self) -> None:
        if self.shards is not None:
            self.shards.close()
        self.recording.close(
            {f.topic for f in self.watch.found},
            wall_seconds=f"{time.monotonic() - (self.loop.wall_start or time.monotonic()):.3f}",
            sim_seconds=f"{self.world.t_ns / NS_PER_S:.6f}",
            server_stale_ticks=json.dumps(self.server_stale_ticks),
            ended=self.ended,
            dead_nodes=json.dumps([e.node for e in self.down]),
            foreign_publishers=json.dumps(self.foreign),
            commands_by_robot=json.dumps(self.command_watch.counts(
                {r: s.stale_ticks for r, s in self.world.stats.items()})),
        )
        self.world.close()


def parse_args(argv: list[str]) -> tuple[WorldNodeConfig, list[str]]:
    parser = argparse.ArgumentParser(prog="swarm-world", description=first_paragraph(__doc__))
    parser.add_argument("--scenario", default="", help="scenario name or YAML path (default: the default scenario)")
    parser.add_argument("--set", dest="overrides", action="append", default=[], metavar="KEY=VALUE",
                        help="override a scenario field (repeatable; the value is YAML)")
    parser.add_argument("--seed", type=number(int, 0, 2**63 - 1), default=0, help="random seed (default 0)")
    parser.add_argument("--mode", choices=("lockstep", "realtime"), default="lockstep",
                        help="lockstep: wait for every controller's answer to each tick (default); realtime: "
                             "step at --real-time-factor with the commands that arrived")
    parser.add_argument("--tick-timeout", type=number(float, 0, 3600, open_low=True), default=WorldNodeConfig.tick_timeout,
                        help=f"lockstep: wall seconds to wait for a tick's answers (default {WorldNodeConfig.tick_timeout:g})")
    parser.add_argument("--resend-period", type=number(float, 0, 3600, open_low=True),
                        default=WorldNodeConfig.resend_period,
                        help="lockstep: wall seconds after which a tick is sent again to the nodes that have not "
                             f"answered (default {WorldNodeConfig.resend_period:g}; a few round trips on a lossy link)")
    parser.add_argument("--real-time-factor", type=number(float, 0, 1e6, open_low=True), default=1.0,
                        help="realtime: target sim seconds per wall second (default 1)")
    parser.add_argument("--pace", type=number(float, 0, 1e6, open_low=True),
                        help="lockstep: at most this many sim seconds per wall second (default: no limit)")
    parser.add_argument("--bag", default="", help="bag directory to record to (default: record nothing)")
    parser.add_argument("--foxglove", type=number(int, 0, 65535), default=-1, metavar="PORT",
                        help="serve the run over the Foxglove WebSocket protocol (0: any free port)")
    parser.add_argument("--foxglove-host", default=WorldNodeConfig.foxglove_host,
                        help=f"address the live view binds (default {WorldNodeConfig.foxglove_host})")
    parser.add_argument("--plain-twist", nargs="+", default=[], metavar="ROBOT",
                        help="realtime: these robots' commands come as plain geometry_msgs/Twist (a robot's own "
                             "computer on wall-clock time); each counts from the tick it arrives at")
    parser.add_argument("--publish-shards", type=number(int, 0), default=0, metavar="K",
                        help="the observations published by K processes of their own, fed by shared memory "
                             "(default 0: by the world itself; docs/benchmarks.md)")
    args, ros_args = parser.parse_known_args(argv)
    config = WorldNodeConfig(
        scenario=args.scenario, overrides=tuple(args.overrides), seed=args.seed, mode=args.mode,
        tick_timeout=args.tick_timeout, real_time_factor=args.real_time_factor, bag=args.bag,
        foxglove_port=args.foxglove, foxglove_host=args.foxglove_host, pace=args.pace or 0.0,
        resend_period=args.resend_period, plain_twist=tuple(args.plain_twist), publish_shards=args.publish_shards,
    )
    return config, ros_args


def main(argv: list[str] | None = None) -> int:
    config, ros_args = parse_args(sys.argv[1:] if argv is None else argv)
    tune_malloc()  # this process runs the world (`tune_malloc`: process-wide, so not the World's to do)
    # Our own signal handling: rclpy's handler shuts the context down under the running loop,
    # which then waited out tick timeouts instead of stopping. A flag checked at every spin
    # stops the run promptly wherever it is.
    auth.load_from_environment()  # the run's key, when the launcher handed one down
    rclpy.init(args=["swarm-world", *ros_args], signal_handler_options=SignalHandlerOptions.NO)
    node = None
    code = 0
    failed = True  # until the run ends as it should (a crash: the others hear "world failed")
    signal.signal(signal.SIGINT, signal.default_int_handler)  # until the node exists
    try:
        try:
            node = WorldNode(config)
        except (ScenarioError, WorldConfigError, ShardEnvironmentError) as exc:
            # a scenario that loads but cannot be built (resources that do not fit), options that
            # contradict it or each other, shards without a client's environment
            print(f"swarm-world: {exc}", file=sys.stderr, flush=True)
            return 2

        def request_stop(*_: object) -> None:
            node.stop_requested = True

        signal.signal(signal.SIGINT, request_stop)
        signal.signal(signal.SIGTERM, request_stop)
        executor = make_executor()
        executor.add_node(node)
        node.run(executor)
        failed = False
        if node.stop_requested:
            raise Interrupted
    except ShardDied as exc:  # its robots can no longer be sent a tick: the run ends here
        print(f"swarm-world: {exc}: the run ends here", file=sys.stderr, flush=True)
        code = 1
    except (KeyboardInterrupt, ExternalShutdownException, Interrupted):
        failed = False
        print("[world] interrupted: closing the bag", flush=True)
        if node is not None:
            node.ended = "interrupted"
    finally:
        if node is not None:
            node.beacon.end("world failed" if failed else node.ended)  # every other process of the run leaves on it
            node.close()
            # until the end reached every reader: the participant goes with the process (`leave`)
            node.beacon.wait_acknowledged(END_ACK_WAIT if ack_wait() > 0 else END_ACK_WAIT_HERE)
    leave(code)  # no teardown of the node, its executor or the discovery server (`lifetime.leave`)


if __name__ == "__main__":
    sys.exit(main())

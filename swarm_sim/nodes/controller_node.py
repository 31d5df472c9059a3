"""A controller node: one robot's behaviour under the robot's namespace.

The node caches the tick's observation messages (odometry, scan and the world task's sense,
`swarm_msgs_py.sensing`) by stamp; when all of them carry the same stamp it builds the
`Observation`, hands it the messages
from other nodes stamped earlier (see `swarm_sim.messaging`), steps the behaviour, publishes
the behaviour's outgoing messages, its status when it changed, and finally the command stamped
with the tick it answers. The tick drives all work; there are no timers. Its time is the stamp
of the tick it steps on: it hears no ``/clock`` (``use_sim_time`` reads true, read-only;
`swarm_sim.nodes.executor.StampTime`).

Everything from the bus is untrusted: the world's observations and other nodes' messages pass
the endpoint's guard before the behaviour sees them (`swarm_sim.inbound`: within their topic's
size cap, decodable, stamped for a tick of the run or one it can take, numbers finite and within
the arena and the robot's limits, robots of this run), and what is dropped, here or by the
behaviour itself, is counted on ``/diagnostics``.

The node serves the standard parameter services (``ros2 param list/get``), created with it:
twelve DDS endpoints per robot, which made a 112-process start-up 16 % slower under peer-to-peer
discovery (benchmarks/README.md); the discovery server only tells each process of the endpoints on
its own topics. ``--no-parameter-services`` leaves them out: more than half of a controller's
endpoints, and with 1000 robots half of the start-up's CPU (Fast DDS pairs every endpoint it
learns of with every local one: the world, as discovery server, learns of them all); ``swarm-run``
leaves them out by default above `launch_py.run.PARAMETER_SERVICES_UP_TO` robots. The node's parameters
are read-only (it reads them once, when it is made: a later value would change nothing), so it
never has a parameter event to send, and it has no ``/parameter_events`` writer
(`NoParameterEvents`): one endpoint fewer per robot, which no one in a run reads.

With ``--plain-twist`` the node drives a robot of its own, as on a TurtleBot-class robot's
computer: it publishes plain ``geometry_msgs/Twist`` on ``cmd_vel`` and steps on wall-clock time
(a timer every ``sim.dt`` wall seconds, with the newest observations heard; the behaviour's clock
is its own tick count times dt), not on the world's ticks; topic names are remapped the standard
way (``--ros-args -r cmd_vel:=/my_robot/cmd_vel``). Against the world it needs a realtime run whose
world takes that robot's plain Twist (``swarm-world --plain-twist``).

``swarm-controllers --robots robot_0 robot_1 ...`` hosts several such nodes in one process;
with ``--fork`` it gives every robot its own process instead, forked from this one once the
imports and the scenario are loaded (one process per robot, as on real hardware, without paying
a Python start-up per robot: 112 robots reached their first tick in 20-32 s on the 2-core
machine). Each forked process is named after its robot (``ps -o comm``) and dies with its
parent; the parent passes Ctrl-C and SIGTERM on, and says which robot's process died and how.
"""

from __future__ import annotations

import argparse
import contextlib
import functools
import gc
import os
import signal
import sys
import time

import rclpy
from rclpy.executors import ExternalShutdownException
from rclpy.node import Node
from rclpy.parameter import Parameter

from swarm_msgs_py import auth, diagnostics, odometry, scan, topics, twist
from swarm_msgs_py.types import Observation, robot_index
from swarm_sim import registry
from swarm_sim.behaviour import Behaviour, behaviour_rng
from swarm_sim.cli import first_paragraph
from swarm_sim.nodes.endpoint import Endpoint, EndpointConfig, add_endpoint_arguments, endpoint_config
from swarm_sim.nodes.executor import StampTime, make_executor
from swarm_sim.nodes.lifetime import die_with_parent, set_process_name
from swarm_sim.nodes.params import declare_config
from swarm_sim.nodes.qos import EVENTS, SENSOR_LOCKSTEP
from swarm_sim.nodes.run_watch import EXIT_CODES, WORLD_RUN, RunWatch
from swarm_sim.scenario import Scenario, load_scenario

ControllerConfig = EndpointConfig
"""A controller node's parameters: scenario, overrides, seed and how long `connect` waits."""

PARAMETER_EVENTS = "/parameter_events"


class NoParameterEvents:
    """What a controller node has where rclpy makes every node a ``/parameter_events`` writer
    (issue 40, lever 4): rclpy publishes an event when a parameter is declared or set; a robot's
    parameters are declared once, at start, to no reader (the topic is volatile: a tool that comes
    later never sees those events), and are read-only after. So the writer would be a DDS endpoint
    per robot for the discovery to announce and pair, and nothing else."""

    def publish(self, _event: object) -> None:
        pass


class ControllerNode(Node):
    """One robot's controller. It creates its ``cmd_vel`` publisher, which is what the world
    waits for before the first tick, only once every topic it exchanges with the servers and
    with the world's relay of the other robots' messages is matched (`connect`): a message sent
    before its receiver is matched would be lost, and the run would no longer be the batch run
    of the same seed."""

    def __init__(self, robot: str, config: ControllerConfig | None = None, *, scenario: Scenario | None = None,
                 parameter_services: bool = True, plain_twist: bool = False, watch: RunWatch | None = None,
                 stamp_time: StampTime | None = None, **kwargs) -> None:
        """`scenario`: the one `config` names, already loaded (saves each forked process the
        parse); `parameter_services`: serve ``ros2 param``; `plain_twist`: a robot's own computer
        (see the module docstring); `watch`: the process's watch of its world and `stamp_time`
        its nodes' clock, shared by its nodes (None: this node makes its own)."""
        robot_index(robot)  # refuse names that are not robot ids
        super().__init__(
            "controller", namespace=robot, enable_rosout=False, start_parameter_services=parameter_services,
            # No type description service: our types are standard ones every peer has, and its two
            # endpoints per robot are start-up cost with a process per robot. use_sim_time false
            # here, whatever the command line says: rclpy would subscribe to /clock; on the
            # world's ticks the node's time is their stamps (`StampTime` declares it true).
            parameter_overrides=[Parameter("use_sim_time", value=False),
                                 Parameter("start_type_description_service", value=False)], **kwargs,
        )
        self._stamp_time = None if plain_twist else stamp_time or StampTime()
        """The process's clock of the ticks its nodes step on (None with ``--plain-twist``: wall time)."""
        if self._stamp_time is not None:
            self._stamp_time.attach(self)
        self.robot = robot
        self.plain_twist = plain_twist
        self._wall_ticks = 0
        self.config = cfg = declare_config(self, ControllerConfig, config, read_only=True)
        self.scenario = scenario or load_scenario(cfg.scenario, cfg.overrides, seed=cfg.seed)
        self.behaviour: Behaviour = registry.make_behaviour(self.scenario, robot, behaviour_rng(cfg.seed, robot))
        algorithm = registry.of(self.scenario)
        self.sensing = registry.resolve(registry.task(algorithm.task).sensing)
        self._latest: dict[str, tuple[int, object]] = {}
        self._last_status: tuple | None = None
        self._answered_stamp = -1
        self._answer = b""
        # Subscribe to other nodes' messages first: in a wait set where both are ready,
        # rclpy runs the earlier subscription first.
        self.endpoint = Endpoint(self, self.scenario, *registry.robot_topics(algorithm))
        guard = self.endpoint.inbound
        observations = {  # topic -> (decoder, the guard's check of its values)
            topics.ODOM: (odometry.decode_odometry, "odometry"),
            topics.SCAN: (scan.decode_scan, "scan"),
            topics.SENSE: (self.sensing.decode, "value"),
        }
        self._expected = len(observations)
        refused = lambda: self.endpoint.report.publish(max(self._answered_stamp, 0), self.behaviour)  # noqa: E731
        for name, (decode, kind) in observations.items():
            # The guard is the callback (size, decode, numbers, tick): nothing from the bus raises
            # in it or reaches the behaviour unchecked; a refusal is reported at once (the robot
            # may not tick again soon).
            deliver = functools.partial(self._on_observation, name)
            guarded = guard.sense_guard(topics.robot_topic(robot, name), decode, kind, deliver, refused)
            self.create_subscription(topics.type_of(name), name, guarded, SENSOR_LOCKSTEP, raw=True)
        self._cmd_pub = None
        self.watch = watch or RunWatch(self, guard, cfg.world_timeout)
        """The process's watch of its world: the node answers only while its world is current
        (`swarm_sim.nodes.run_watch`)."""
        self._connect_by = time.monotonic() + cfg.startup_timeout
        self._status_pub = self.create_publisher(topics.type_of(topics.STATUS), topics.STATUS, EVENTS)

    def create_publisher(self, msg_type, topic: str, *args, **kwargs):  # noqa: ANN001, ANN201
        """rclpy's own, except for the ``/parameter_events`` writer rclpy's `Node` asks for while it
        is made (`NoParameterEvents`)."""
        if topic == PARAMETER_EVENTS:
            return NoParameterEvents()
        return super().create_publisher(msg_type, topic, *args, **kwargs)

    def connect(self) -> bool:
        """Create the ``cmd_vel`` publisher once every exchange topic is matched (or the start-up
        timeout passed); True once it exists."""
        if self._cmd_pub is not None:
            return True
        # One peer on each: a server, or the world relaying what robots send each other; and the
        # world heard on /world/run (its ticks are answered only then).
        missing = self.endpoint.unmatched(1) + ([WORLD_RUN] if self.watch.run is None else [])
        if missing and time.monotonic() < self._connect_by:
            return False
        if missing:
            self.get_logger().warning(f"answering without all peers matched on {', '.join(sorted(missing))}")
        if self.plain_twist:
            self._cmd_pub = self.create_publisher(topics.import_type(twist.PLAIN_TYPE_NAME), topics.CMD_VEL,
                                                  SENSOR_LOCKSTEP)
            self.create_timer(self.scenario.sim.dt, self._wall_tick)  # the node's clock: wall time
        else:
            self._cmd_pub = self.create_publisher(topics.type_of(topics.CMD_VEL), topics.CMD_VEL, SENSOR_LOCKSTEP)
        return True

    def _wall_tick(self) -> None:
        """``--plain-twist``: a step on the wall clock with the newest observation of each topic."""
        if len(self._latest) == self._expected and self.watch.current():
            self._wall_ticks += 1
            self._tick(self._wall_ticks * self.scenario.dt_ns)

    def _on_observation(self, name: str, decoded: tuple) -> None:
        if self._cmd_pub is None or not self.watch.current():  # not connected, or not our world's tick
            return
        if self.plain_twist:  # its own clock steps it (`_wall_tick`)
            self._latest[name] = decoded
            return
        stamp = decoded[0]
        if stamp == self._answered_stamp:  # the world re-sent a tick: our answer was late or lost
            self._cmd_pub.publish(self._answer)
            return
        latest = self._latest
        latest[name] = decoded
        if len(latest) == self._expected:
            for value in latest.values():
                if value[0] != stamp:
                    return
            self._tick(stamp)

    def _tick(self, stamp_ns: int) -> None:
        if self._stamp_time is not None:
            self._stamp_time.set(stamp_ns)
        messages = self.endpoint.take(stamp_ns)
        _, pose, v, w = self._latest[topics.ODOM]
        obs = Observation(
            robot=self.robot, stamp_ns=stamp_ns, pose=pose, linear_velocity=v, angular_velocity=w,
            ranges=self._latest[topics.SCAN][1], sensed=self._latest[topics.SENSE][1],
            messages=messages,
        )
        command = self.behaviour.step(obs)
        if command.messages:
            self.endpoint.send(stamp_ns, command.messages)
        status = self.behaviour.status(stamp_ns)
        key = (status.state, status.obstacle_avoidance_events, status.trips, status.extra, status.finished)
        if key != self._last_status:
            self._last_status = key
            self._status_pub.publish(auth.sign(diagnostics.encode_status(status)))
        self.endpoint.report.publish(stamp_ns, self.behaviour)
        if self.plain_twist:
            self._cmd_pub.publish(twist.encode_plain_twist(command.linear, command.angular))
            return
        self._answer = twist.encode_twist(self.robot, stamp_ns, command.linear, command.angular)
        self._answered_stamp = stamp_ns
        self._cmd_pub.publish(self._answer)


def parse_args(argv: list[str]) -> tuple[list[str], ControllerConfig, list[str], bool, bool, bool]:
    """(robots, config, ROS arguments, fork, parameter services, plain Twist)."""
    parser = argparse.ArgumentParser(prog="swarm-controllers", description=first_paragraph(__doc__))
    parser.add_argument("--robots", nargs="+", required=True, help="robot ids, e.g. robot_0 robot_1")
    add_endpoint_arguments(parser)
    parser.add_argument("--fork", action="store_true", help="one process per robot, forked from this one")
    parser.add_argument("--no-parameter-services", dest="parameter_services", action="store_false",
                        help="no ros2 param services on the controller nodes (12 DDS endpoints a robot fewer)")
    parser.add_argument("--plain-twist", action="store_true",
                        help="a robot's own computer: plain geometry_msgs/Twist on cmd_vel, steps on wall-clock time "
                             "(realtime runs; remap topics with --ros-args -r cmd_vel:=...)")
    args, ros_args = parser.parse_known_args(argv)
    return args.robots, endpoint_config(args), ros_args, args.fork, args.parameter_services, args.plain_twist


_KEPT: list = []
"""What `serve` leaves up when told not to tear down (`serve_forked`'s robot processes, which end
by ``os._exit``): destroyed when `serve` returned, its executor threw a C++ exception in its
destructor and aborted a robot process (SIGABRT; a core dump of a loaded test suite)."""


def serve(robots: list[str], config: ControllerConfig, ros_args: list[str], *, teardown: bool = True,
          scenario: Scenario | None = None, parameter_services: bool = True, plain_twist: bool = False,
          say: bool = True) -> int:
    """The robots' controller nodes in this process, spun until the run ends (`RunWatch`: the
    exit code, with one line saying why unless `say` is False) or the process is stopped (0);
    `teardown=False` leaves without destroying the DDS participant (see `serve_forked`)."""
    rclpy.init(args=["swarm-controllers", *ros_args])
    nodes: list[ControllerNode] = []
    verdict = executor = None
    try:
        executor = make_executor()
        watch = None  # the first node's, shared by the others: one /world/run subscription a process
        stamp_time = None if plain_twist else StampTime()
        for robot in robots:
            nodes.append(ControllerNode(robot, config, scenario=scenario, parameter_services=parameter_services,
                                        plain_twist=plain_twist, watch=watch, stamp_time=stamp_time))
            watch = nodes[-1].watch
            executor.add_node(nodes[-1])
        # spin_once in a loop: the EventsExecutor's spin() does not dispatch in this rclpy build.
        # One call dispatches one message, so the loop asks a flag, not rclpy.ok() (4-9 us a call:
        # 5 ms a tick in a process of 112 robots).
        stopped = []
        rclpy.get_default_context().on_shutdown(lambda: stopped.append(True))
        connecting = list(nodes)
        while connecting and not stopped and verdict is None:
            executor.spin_once(timeout_sec=0.1)
            connecting = [n for n in connecting if not n.connect()]
            verdict = watch.verdict()
        while not stopped and verdict is None:
            executor.spin_once(timeout_sec=0.5)
            verdict = watch.verdict()
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    finally:
        if teardown:
            signal.signal(signal.SIGINT, signal.SIG_IGN)  # the run is over: a Ctrl-C now only cuts the teardown
            if executor is not None:  # first, and destroyed (`make_executor`)
                executor.shutdown()
                executor = None
            for node in nodes:
                node.destroy_node()
            rclpy.try_shutdown()
        else:
            _KEPT.extend((executor, *nodes))  # up until the caller's os._exit (`_KEPT`)
    if verdict is None:
        return 0
    code, why = verdict
    if say:
        print(f"[controllers] {_robots_text(robots)}: {why}: leaving (exit {code})", file=sys.stderr, flush=True)
    return code


def _robots_text(robots: list[str]) -> str:
    return ", ".join(robots) if len(robots) <= 4 else f"{len(robots)} robots ({robots[0]} ...)"


def _warm_up(scenario: Scenario, robot: str, config: ControllerConfig) -> None:
    """Do, once before forking, what every robot process would otherwise do first (measured: a
    forked process's first node took 0.2-0.6 s of CPU, 112 of them on 2 cores most of a
    minute): import the behaviour, sense and message-family modules and every message type,
    and the interface packages rclpy's Node pulls in lazily. No DDS entity is made here: Fast
    DDS leaves threads behind, and a forked copy of a threaded process can deadlock."""
    from rcl_interfaces import srv as parameter_services
    from rcl_interfaces.msg import ParameterEvent
    from rclpy.type_support import check_for_type_support
    from type_description_interfaces.srv import GetTypeDescription

    registry.make_behaviour(scenario, robot, behaviour_rng(config.seed, robot))
    algorithm = registry.of(scenario)
    registry.resolve(registry.task(algorithm.task).sensing)
    inbound, outbound = registry.robot_topics(algorithm)
    names = [*topics.ROBOT_TOPIC_TYPES.values(), topics.type_string(topics.DIAGNOSTICS),
             *(f.type_name for f in (*inbound.values(), *outbound.values()))]
    services = [getattr(parameter_services, n) for n in ("DescribeParameters", "GetParameterTypes", "GetParameters",
                                                         "ListParameters", "SetParameters", "SetParametersAtomically")]
    for cls in (*(topics.import_type(name) for name in names), ParameterEvent, GetTypeDescription, *services):
        check_for_type_support(cls)  # loads the type support C modules (and rosidl's parser) now


STOP_GRACE = 5.0
"""Wall seconds the forked robot processes get to leave after Ctrl-C/SIGTERM before SIGKILL."""


def serve_forked(robots: list[str], config: ControllerConfig, ros_args: list[str], *,
                 parameter_services: bool = True, plain_twist: bool = False) -> int:
    """One process per robot, forked from this one (see the module docstring).

    A robot process leaves without tearing its DDS participant down (`os._exit` once its loop
    ends): when a hundred participants leave at once, Fast DDS 2.14 can hang in participant
    deletion, and an exiting process needs no goodbye (its peers see it gone by its lease). It
    gets SIGKILL if this process dies, and this process SIGKILLs any that has not left
    `STOP_GRACE` seconds after a stop."""
    scenario = load_scenario(config.scenario, config.overrides, seed=config.seed)  # refuse a bad file once, here
    _warm_up(scenario, robots[0], config)
    gc.freeze()  # what the children inherit stays shared (no copy-on-write from the collector)
    parent = os.getpid()
    children: dict[int, str] = {}
    for robot in robots:
        pid = os.fork()
        if pid == 0:
            die_with_parent(parent, signal.SIGKILL)
            set_process_name(robot)
            code = 1
            try:
                code = serve([robot], config, ros_args, teardown=False, scenario=scenario,
                             parameter_services=parameter_services, plain_twist=plain_twist, say=False)
            finally:
                sys.stdout.flush()
                sys.stderr.flush()
                os._exit(code)
        children[pid] = robot
    stopping = 0.0  # when the stop began (monotonic)

    def signal_all(sig: int) -> None:
        for pid in children:
            with contextlib.suppress(ProcessLookupError):
                os.kill(pid, sig)

    def stop(signum: int, _frame: object) -> None:
        nonlocal stopping
        stopping = stopping or time.monotonic()
        signal_all(signal.SIGINT)

    for sig in (signal.SIGINT, signal.SIGTERM, signal.SIGHUP):
        signal.signal(sig, stop)
    ended: dict[int, list[str]] = {}  # exit code -> robots whose process left because the run ended
    while children:
        try:
            pid, status = os.waitpid(-1, os.WNOHANG)
        except ChildProcessError:
            break
        if pid == 0:
            if stopping and time.monotonic() > stopping + STOP_GRACE:
                signal_all(signal.SIGKILL)
            time.sleep(0.05)
            continue
        robot = children.pop(pid, "?")
        code = os.waitstatus_to_exitcode(status)
        if not stopping and code in EXIT_CODES:  # its run ended (`RunWatch`): said once for all below
            ended.setdefault(code, []).append(robot)
        elif not stopping or code not in (0, -signal.SIGINT, -signal.SIGKILL):
            how = f"was killed by signal {-code}" if code < 0 else f"exited with code {code}"
            print(f"[controllers] the process of {robot} (pid {pid}) {how}", file=sys.stderr, flush=True)
    if stopping or not ended:
        return 0
    code = max(ended, key=lambda c: len(ended[c]))  # what most robots heard
    for c, robots in sorted(ended.items()):
        print(f"[controllers] {_robots_text(robots)}: {EXIT_CODES[c]}: left (exit {c})", file=sys.stderr, flush=True)
    return code


def main(argv: list[str] | None = None) -> int:
    robots, config, ros_args, fork, parameter_services, plain_twist = parse_args(sys.argv[1:] if argv is None else argv)
    auth.load_from_environment()  # the run's key, when the launcher handed one down (forks inherit it)
    return (serve_forked if fork else serve)(robots, config, ros_args, parameter_services=parameter_services,
                                             plain_twist=plain_twist)


if __name__ == "__main__":
    sys.exit(main())

"""swarm-run: start the world node (which records the bag), the controller nodes and the
servers the scenario's algorithm registers (`swarm_sim.registry`: the center for MDBSA, the
depot manager for the queue strategies).

Controllers run all in one process by default; ``--controller-processes K`` spreads them over
K processes and ``0`` gives every robot its own process, as on real hardware. DDS stays on
loopback and on a private domain id (`launch_py.dds`). Discovery goes through the world node, a
Fast DDS discovery server on 127.0.0.1:6400+domain (peer-to-peer SIMPLE discovery took 120 s to
connect 112 robot processes on 2 cores, the server about a third of that: each process learns
only of the endpoints of its own topics); ``--discovery simple`` is the peer-to-peer way. Ctrl-C stops every process and still
leaves a valid bag. Needs no ros2cli or launch: plain subprocesses with the right environment.

The launcher owns its children: Ctrl-C, SIGTERM and SIGHUP stop them all (the world first, so
it closes the bag), and each child gets SIGTERM from the kernel if the launcher dies in any
other way (``PR_SET_PDEATHSIG``), so no node outlives it. It names every node that died, and
its exit code says how the run went (`EXIT_CODES`).
"""

from __future__ import annotations

import argparse
import json
import os
import secrets
import shlex
import shutil
import signal
import subprocess
import sys
import tempfile
import time
from dataclasses import dataclass
from datetime import datetime
from pathlib import Path

from launch_py import hosts
from launch_py.dds import (
    MAX_DOMAIN_ID,
    PROFILE_MAX_PROCESSES,
    PROFILE_PATH,
    DomainTaken,
    claim_domain,
    claim_free_domain,
    discovery_port,
    discovery_server_env,
    loopback_env,
    remove_dead_shm_files,
    robot_profile,
    server_profile,
    with_shared_memory,
)
from swarm_msgs_py import auth
from swarm_sim import registry
from swarm_sim.analysis.metrics import summarize
from swarm_sim.analysis.replay import load_run
from swarm_sim.analysis.text import summary_lines
from swarm_sim.cli import add_scenario_arguments, first_paragraph, number, scenario_fields, stop_on_signals
from swarm_sim.nodes.lifetime import die_with_parent
from swarm_sim.nodes.live_view import DEFAULT_PORT, LOOPBACK
from swarm_sim.nodes.publish_shard import SHARD_ENV, shard_environment
from swarm_sim.nodes.run_watch import WORLD_TIMEOUT
from swarm_sim.nodes.ws_proxy import check_port
from swarm_sim.recording import repair_bag
from swarm_sim.recording.metadata import METADATA_FILE
from swarm_sim.scenario import Scenario, ScenarioError, load_scenario

EXIT_CODES = {
    0: "the run is complete and every node lived to its end",
    1: "the bag could not be read",
    2: "bad flags or scenario, or the DDS domain is in use (nothing was started)",
    3: "a server (depot manager, center) died: the run ended early",
    4: "the run is complete, but robots were declared dead on the way (named in the output)",
    5: "the world node died: the bag was repaired and analysed up to its last flushed data",
    6: "the run is tainted: a process outside the run published on one of its topics where its messages "
       "may have reached the robots (named in the output); the results may hold what it sent",
    130: "interrupted (Ctrl-C, SIGTERM or SIGHUP): the bag holds the run up to then",
}
"""swarm-run's exit codes."""



PARAMETER_SERVICES_UP_TO = 128
"""Robots up to which the controller nodes serve ``ros2 param`` by default: every swarm of the
papers (at most 112 robots). Beyond, their twelve DDS endpoints a robot are most of a start-up's
discovery (issue 40, lever 4: 1000 robots in 4 processes took 38 s to connect with them, 20 s
without; 112 robots, a process each, showed no difference beyond the noise), and listing the
parameters of hundreds of identical robots is rarely what anyone does."""
STARTUP_REPORT_PERIOD = 5.0
"""Wall seconds between start-up lines while the world node is not up yet."""


def split_robots(robots: list[str], processes: int) -> list[list[str]]:
    """Robots dealt round-robin over `processes` groups; 0 means one process per robot."""
    count = len(robots) if processes <= 0 else min(processes, len(robots))
    return [robots[i::count] for i in range(count)]


def scenario_args(args: argparse.Namespace, scenario: Scenario) -> list[str]:
    """Arguments that make a child load exactly the scenario this launcher validated."""
    out = ["--scenario", args.scenario, "--seed", str(scenario.seed)]
    overrides = list(args.overrides)
    for key, value in scenario_fields(args).items():
        if value is not None:
            overrides.append(f"{key.replace('__', '.')}={value}")
    for text in overrides:
        out += ["--set", text]
    return out


def default_bag_dir(out: Path, scenario: Scenario) -> Path:
    stamp = datetime.now().strftime("%Y%m%d-%H%M%S")
    return out / f"{scenario.name}_{scenario.robots.count}r_s{scenario.seed}_{stamp}"


LEAVE_GRACE = 10.0
"""Wall seconds the other nodes get to leave by themselves once the world has ended its run (they
hear the end on ``/world/run``) before they are stopped."""


def _wait_left(procs: list[subprocess.Popen], seconds: float) -> None:
    """Until every process of `procs` has exited, `seconds` at most."""
    deadline = time.monotonic() + seconds
    while any(p.poll() is None for p in procs) and time.monotonic() < deadline:
        time.sleep(0.05)


def _stop(procs: list[subprocess.Popen], grace: float) -> None:
    for p in procs:
        if p.poll() is None:
            p.send_signal(signal.SIGINT)
    deadline = time.monotonic() + grace
    for p in procs:
        try:
            p.wait(timeout=max(0.1, deadline - time.monotonic()))
        except subprocess.TimeoutExpired:
            p.kill()
            p.wait()


def domain_option(text: str) -> int | str:
    """``--domain-id``: an id 0-`MAX_DOMAIN_ID`, or ``auto`` (a free one)."""
    return "auto" if text == "auto" else number(int, 0, MAX_DOMAIN_ID)(text)


def claim_run_domain(requested: int | str | None) -> tuple[int, int]:
    """The run's DDS domain, claimed for the run (`launch_py.dds.claim_domain`): the one asked
    for (``--domain-id N``, else the user's ``ROS_DOMAIN_ID``), refused if anything uses it; with
    ``auto``, or when nothing was asked for, a free one. Returns (domain, the claim's lock fd);
    raises DomainTaken (or ValueError for a bad ``ROS_DOMAIN_ID``) with the one line to print."""
    user = os.environ.get("ROS_DOMAIN_ID", "").strip()
    if requested == "auto" or (requested is None and not user):
        return claim_free_domain()
    if requested is None:
        if not user.isdigit() or int(user) > MAX_DOMAIN_ID:
            raise ValueError(f"ROS_DOMAIN_ID={user[:20]!r}: expected an id 0-{MAX_DOMAIN_ID} (or use --domain-id auto)")
        requested = int(user)
    try:
        return requested, claim_domain(requested)
    except DomainTaken as exc:
        raise DomainTaken(f"{exc}; pick another with --domain-id N, or --domain-id auto for a free one") from None


def output_directory(args: argparse.Namespace, scenario: Scenario) -> Path:
    """The run's bag directory, created (its parents too); raises ValueError with the one line to
    print when it cannot be (not an empty directory, outside ``--out``, not writable)."""
    bag = args.bag or default_bag_dir(args.out, scenario)
    if args.bag is None and args.out.resolve() not in bag.resolve().parents:  # the scenario names it
        raise ValueError(f"scenario name {scenario.name!r} would put the bag outside --out {args.out}")
    try:
        if bag.exists() and (not bag.is_dir() or any(bag.iterdir())):
            raise ValueError(f"--bag {bag}: already exists and is not an empty directory (a run never "
                             "overwrites a recording)")
        bag.parent.mkdir(parents=True, exist_ok=True)
        if not os.access(bag.parent, os.W_OK | os.X_OK):
            raise PermissionError(13, "Permission denied")
    except OSError as exc:
        existing = next((p for p in bag.parents if p.exists()), None)
        why = f"{existing} is not a directory" if existing is not None and not existing.is_dir() else exc.strerror
        raise ValueError(f"cannot record to {bag}: {why or exc}") from None
    return bag


def build_parser() -> argparse.ArgumentParser:
    """swarm-run's options (``--help`` lists them with the exit codes)."""
    parser = argparse.ArgumentParser(
        prog="swarm-run", description=first_paragraph(__doc__), formatter_class=argparse.RawDescriptionHelpFormatter,
        epilog="exit codes:\n" + "\n".join(f"  {code:3d}  {what}" for code, what in EXIT_CODES.items()))
    add_scenario_arguments(parser)
    parser.add_argument("--out", type=Path, default=Path("bags"), help="directory for bags (default: bags)")
    parser.add_argument("--bag", type=Path, help="exact bag directory (default: OUT/<scenario>_<N>r_s<seed>_<time>)")
    parser.add_argument("--mode", choices=("lockstep", "realtime"), default="lockstep",
                        help="lockstep (default): the world waits for every controller's answer to each tick, "
                             "so a run equals the batch run of its seed; realtime: the world steps at "
                             "--real-time-factor with whatever commands have arrived, as Gazebo does")
    parser.add_argument("--controller-processes", type=number(int, 0), default=1, metavar="K",
                        help="processes for the controllers (default 1; 0 = one per robot)")
    parser.add_argument("--real-time-factor", type=number(float, 0, 1e6, open_low=True), metavar="X",
                        help="sim seconds per wall second: realtime mode's target (default 1); in lockstep "
                             "the fastest it may go (default: as fast as the nodes answer; 1 with --foxglove)")
    parser.add_argument("--tick-timeout", type=number(float, 0, 3600, open_low=True), default=2.0,
                        help="lockstep: wall s to wait per tick")
    parser.add_argument("--resend-period", type=number(float, 0, 3600, open_low=True), default=0.25,
                        help="lockstep: wall s after which a tick is sent again to the nodes that have not answered "
                             "(default 0.25; across lossy links a few round trips, e.g. 0.1)")
    parser.add_argument("--domain-id", type=domain_option,
                        help=f"ROS_DOMAIN_ID 0-{MAX_DOMAIN_ID}, or auto: a free one (default: the user's ROS_DOMAIN_ID, "
                             "else a free one); a run refuses a domain anything else uses")
    parser.add_argument("--discovery", choices=("server", "simple"), default="server",
                        help="DDS discovery: the world node as discovery server for every other node (default; "
                             "scales to a process per robot), or Fast DDS's peer-to-peer SIMPLE discovery")
    services = parser.add_mutually_exclusive_group()
    services.add_argument("--parameter-services", dest="parameter_services", action="store_true", default=None,
                          help="ros2 param services on every controller node, whatever the swarm's size (default: "
                               f"up to {PARAMETER_SERVICES_UP_TO} robots)")
    services.add_argument("--no-parameter-services", dest="parameter_services", action="store_false",
                          help="no ros2 param services on the controller nodes: 12 DDS endpoints a robot fewer, "
                               "half the start-up's CPU with 1000 robots (README, Benchmarks)")
    parser.add_argument("--shared-memory", action="store_true",
                        help="DDS data between the run's processes through shared memory (/dev/shm), UDP 127.0.0.1 "
                             "for discovery and anyone else (default: UDP 127.0.0.1 only); less CPU with a few "
                             "controller processes, more with one per robot (README, Benchmarks)")
    parser.add_argument("--publish-shards", type=number(int, 0), default=0, metavar="K",
                        help="the world's observations published by K processes of their own, fed by shared memory "
                             "(default 0: by the world; pays with many robots: docs/benchmarks.md, The graph)")
    parser.add_argument("--foxglove", type=number(int, 0, 65535), nargs="?", const=DEFAULT_PORT, metavar="PORT",
                        help=f"serve the run live to Foxglove over WebSocket (default port {DEFAULT_PORT}; 0: any free)")
    parser.add_argument("--foxglove-host", default=LOOPBACK,
                        help=f"address the live view binds (default {LOOPBACK}: this machine only)")
    parser.add_argument("--json", action="store_true", help="print the run's summary as JSON")
    parser.add_argument("--bind", metavar="ADDR|IFACE",
                        help="across hosts: the world (the discovery server, port 6400 + domain), the servers and "
                             "the local controllers bind this IPv4 address (or the interface's) only, instead of "
                             "loopback (README, *Across hosts*)")
    parser.add_argument("--remote-controllers", type=remote_option, action="append", default=[],
                        metavar="HOST=ROBOT,...", help="with --bind: these robots' controllers run on HOST (started "
                        "there by hand, as printed): none is started here; the summary counts per host")
    parser.add_argument("--plain-twist", action="store_true",
                        help="realtime, with --remote-controllers: the remote robots' computers speak plain "
                             "geometry_msgs/Twist on wall-clock time (swarm-controllers --plain-twist), as "
                             "TurtleBot-class robots do")
    parser.add_argument("--world-timeout", type=number(float, 0, 86400, open_low=True), default=WORLD_TIMEOUT,
                        metavar="S", help="every controller and server process, here or on another host, leaves by "
                        "itself when the run ends, or once the world has been silent S wall seconds (killed, or "
                        f"unreachable that long; default {WORLD_TIMEOUT:g})")
    parser.add_argument("--key-file", type=Path, metavar="PATH",
                        help="write the run's credential here (mode 0600), for the controllers on other hosts "
                             "(SWARMFORAGE_KEY_FD=3 ... 3<PATH); required with --remote-controllers")
    return parser


class Refused(Exception):
    """What makes swarm-run refuse a run before starting anything (exit 2), as the line to print."""


@dataclass(frozen=True)
class Plan:
    """What the options and the scenario make of a run, checked before anything starts."""

    scenario: Scenario
    pace: float | None
    """Lockstep's cap on sim seconds per wall second (`_pace`)."""
    bind: str | None
    """The address the run binds across hosts; None: loopback."""
    remote: dict[str, list[str]]
    """Host -> the robots whose controllers run there (started by hand)."""
    local: list[str]
    """The robots whose controllers this launcher starts."""
    groups: list[list[str]]
    """`local` dealt over the controller processes."""
    servers: tuple[registry.ServerSpec, ...]
    processes: int
    """DDS processes of the run here: controllers, servers, the world and its publishing shards."""
    parameter_services: bool
    """Whether the controller nodes serve ``ros2 param`` (`PARAMETER_SERVICES_UP_TO`)."""


@dataclass(frozen=True)
class Environments:
    """The children's environments (DDS domain, discovery, transport profiles)."""

    world: dict[str, str]
    robots: dict[str, str]
    """The controller processes'."""
    others: dict[str, str]
    """The servers'."""
    profiles: Path
    """This run's Fast DDS profile files (removed at the end)."""
    port: int | None
    """The world's discovery server port; None with ``--discovery simple``."""


def plan_run(args: argparse.Namespace) -> Plan:
    """The scenario, the live view's port, the hosts and the process count, checked in that
    order; raises Refused with the line to print."""
    try:
        scenario = load_scenario(args.scenario, args.overrides, **scenario_fields(args), seed=args.seed)
    except ScenarioError as exc:
        raise Refused(exc) from None
    if (problem := _foxglove_problem(args)) is not None:
        raise Refused(problem)
    pace = _pace(args)
    try:
        bind, remote = _hosts(args, scenario)
    except hosts.HostError as exc:
        raise Refused(exc) from None
    local = [r for r in scenario.robot_names if r not in {r for robots in remote.values() for r in robots}]
    groups = split_robots(local, args.controller_processes) if local else []
    servers = registry.of(scenario).servers
    if args.publish_shards > scenario.robots.count:
        raise Refused(f"--publish-shards {args.publish_shards}: more shards than the run's {scenario.robots.count} robots")
    processes = len(groups) + len(servers) + 1 + args.publish_shards
    if processes > PROFILE_MAX_PROCESSES:
        raise Refused(f"{scenario.robots.count} robots in {len(groups)} controller processes make {processes} DDS "
                      f"processes{f' with {args.publish_shards} publishing shards' if args.publish_shards else ''}; the "
                      f"loopback profile discovers at most {PROFILE_MAX_PROCESSES} (use --controller-processes K "
                      "with fewer processes)")
    services = args.parameter_services
    if services is None:
        services = scenario.robots.count <= PARAMETER_SERVICES_UP_TO
    return Plan(scenario, pace, bind, remote, local, groups, servers, processes, services)


def dds_environments(args: argparse.Namespace, plan: Plan, domain: int) -> Environments:
    """Every child's DDS environment on `domain`: loopback (or `plan.bind` across hosts), the
    world as discovery server, the profiles written to a temporary directory."""
    bind = plan.bind
    port = discovery_port(domain) if args.discovery == "server" else None
    env = loopback_env(domain, processes=plan.processes, base=os.environ, server_port=port)
    for var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS"):  # many small processes: no BLAS thread pools,
        env.setdefault(var, "1")  # which would also not survive the controllers' fork
    profiles = Path(tempfile.mkdtemp(prefix="swarmforage-"))  # this run's Fast DDS profiles
    transport = with_shared_memory if args.shared_memory else (lambda profile: profile)
    ack_wait_here = bool(os.environ.get(hosts.ACK_WAIT_ENV)) and bind is None  # one host, asked for
    if ack_wait_here:  # reliable writers heartbeat as across hosts (the ack wait waits for an answer to one)
        shared, transport = transport, lambda profile: hosts.with_heartbeat(shared(profile), hosts.LOOPBACK_HEARTBEAT_NS)

    def profile_env(base: dict[str, str], name: str, profile: str) -> dict[str, str]:
        (profiles / name).write_text(transport(profile), encoding="utf-8")
        return {**base, "FASTRTPS_DEFAULT_PROFILES_FILE": str(profiles / name),
                "FASTDDS_DEFAULT_PROFILES_FILE": str(profiles / name)}

    if args.shared_memory:
        remove_dead_shm_files()  # what killed runs left
    if args.shared_memory or ack_wait_here:
        env = profile_env(env, "loopback.xml", PROFILE_PATH.read_text(encoding="utf-8"))
    world_env = env
    if bind is not None:  # across hosts: every process bound to `bind`, the world serves discovery there
        envs = {}
        for role in ("server", "client", "robot"):
            (profiles / f"{role}.xml").write_text(hosts.host_profile(role, bind, port), encoding="utf-8")
            envs[role] = {**env, **hosts.host_env(role, domain, bind, (bind, port), profiles / f"{role}.xml", env)}
        world_env, env, robots_env = envs["server"], envs["client"], envs["robot"]
    else:
        if port is not None:
            world_env = discovery_server_env(profile_env(env, "discovery_server.xml", server_profile(port)),
                                             profiles / "discovery_server.xml")
        # Controllers do not read the ROS graph announcements (`robot_profile`): N, not N x N, pairs.
        robots_env = profile_env(env, "robots.xml", robot_profile())
    if args.publish_shards:  # a shard is a client of the world's discovery and reads no graph, as a controller
        world_env = {**world_env, SHARD_ENV: shard_environment(world_env, robots_env)}
    return Environments(world_env, robots_env, env, profiles, port)


def announce(args: argparse.Namespace, plan: Plan, domain: int, port: int | None, bag: Path) -> None:
    """The run's first lines: what runs where, and how to look at it with ros2."""
    scenario = plan.scenario
    print(
        f"[swarm-run] {scenario.name}: {scenario.robots.count} robots, {scenario.sim.duration:.0f} s, "
        f"seed {scenario.seed}, {args.mode}, {len(plan.groups)} controller process(es)"
        f"{f', {args.publish_shards} publishing shards' if args.publish_shards else ''}, domain {domain}\n"
        f"[swarm-run] recording to {bag}",
        flush=True,
    )
    if args.parameter_services is None and not plan.parameter_services:
        print(f"[swarm-run] {scenario.robots.count} robots: the controller nodes serve no ros2 param (more than "
              f"{PARAMETER_SERVICES_UP_TO} robots; --parameter-services to have them)", flush=True)
    if port is not None and plan.bind is None:
        print(f"[swarm-run] to inspect it with ros2: ROS_DOMAIN_ID={domain} ROS_DISCOVERY_SERVER=127.0.0.1:{port} "
              f"ROS_SUPER_CLIENT=TRUE ROS_AUTOMATIC_DISCOVERY_RANGE=SYSTEM_DEFAULT "
              f"FASTRTPS_DEFAULT_PROFILES_FILE={PROFILE_PATH} ros2 topic list --spin-time 2  (discovery takes "
              "~1.5 s: --spin-time 2 without a daemon, or `ros2 daemon start` once with the same variables)",
              flush=True)


def run_key(args: argparse.Namespace, plan: Plan, domain: int, port: int | None, watching: list[str]) -> bytes:
    """This run's credential (`swarm_msgs_py.auth`), written to ``--key-file`` if asked; across
    hosts, how the other hosts join."""
    key = secrets.token_bytes(auth.KEY_BYTES)
    if args.key_file is not None:
        _write_key(args.key_file, key)
    if plan.bind is not None:
        _print_remote(domain, (plan.bind, port), plan.remote,
                      [*watching, "--mode", args.mode, *(["--plain-twist"] if args.plain_twist else [])], args.key_file)
    return key


@dataclass(frozen=True)
class Commands:
    """The run's command lines: the world node's, and the controller processes' and servers',
    each with the label the launcher names it by."""

    world: list[str]
    controllers: list[tuple[str, list[str]]]
    servers: list[tuple[str, list[str]]]


def commands(args: argparse.Namespace, plan: Plan, bag: Path, common: list[str], watching: list[str]) -> Commands:
    """The command lines of the world node, the controller processes and the servers."""
    python = [sys.executable, "-m"]
    world_cmd = [*python, "swarm_sim.nodes.world_node", *common, "--mode", args.mode, "--bag", str(bag),
                 "--tick-timeout", str(args.tick_timeout), "--resend-period", str(args.resend_period),
                 "--real-time-factor", str(args.real_time_factor or 1.0)]
    if plan.pace:
        world_cmd += ["--pace", str(plan.pace)]
    if args.publish_shards:
        world_cmd += ["--publish-shards", str(args.publish_shards)]
    if args.foxglove is not None:
        world_cmd += ["--foxglove", str(args.foxglove), "--foxglove-host", args.foxglove_host]
    options = [] if plan.parameter_services else ["--no-parameter-services"]
    if args.plain_twist:
        world_cmd += ["--plain-twist", *(r for robots in plan.remote.values() for r in robots)]
    if args.controller_processes == 0:  # one process per robot, forked after the imports
        controllers = [("controller processes (one per robot)",
                        [*python, "swarm_sim.nodes.controller_node", "--fork", *options, "--robots",
                         *plan.scenario.robot_names])]
    else:
        controllers = [(f"controller process of {', '.join(g) if len(g) <= 4 else f'{len(g)} robots'}",
                        [*python, "swarm_sim.nodes.controller_node", *options, "--robots", *g]) for g in plan.groups]
    return Commands(
        world_cmd,
        [(label, [*cmd, "--mode", args.mode, *watching]) for label, cmd in controllers],
        [(f"server {spec.channel} ({spec.node_name})",
          [*python, "swarm_sim.nodes.server_node", "--channel", spec.channel, "--mode", args.mode, *watching])
         for spec in plan.servers],
    )


def run_processes(args: argparse.Namespace, cmds: Commands, envs: Environments, key: bytes, bag: Path,
                  domain_lock: int) -> tuple[subprocess.Popen | None, bool]:
    """Start the world (the discovery server, first), the controllers and the servers; wait for
    the world to end, reporting the start-up and any child that dies; stop every child, remove
    the profiles, free the domain. Returns the world's process (None if interrupted before it
    started) and whether the run was interrupted."""
    me = os.getpid()

    def start(label: str, cmd: list[str], env: dict[str, str]) -> tuple[str, subprocess.Popen]:
        key_fd = auth.inheritable_key_pipe(key)  # the key reaches the child by a pipe, never argv
        try:
            proc = subprocess.Popen(cmd, env={**env, auth.ENV: str(key_fd)}, pass_fds=(key_fd,),
                                    start_new_session=True, preexec_fn=lambda: die_with_parent(me))
        finally:
            os.close(key_fd)
        return label, proc

    children: list[tuple[str, subprocess.Popen]] = []
    world: subprocess.Popen | None = None
    interrupted = False
    reported: set[int] = set()
    launched = said = time.monotonic()
    try:
        _, world = start("world", cmds.world, envs.world)  # first: it is the discovery server
        children += [start(label, cmd, envs.robots) for label, cmd in cmds.controllers]
        children += [start(label, cmd, envs.others) for label, cmd in cmds.servers]
        print(f"[swarm-run] started the world and {len(children)} controller/server process(es); the world node "
              "reports while they start and discover each other", flush=True)
        while world.poll() is None:
            now = time.monotonic()
            if now - said >= STARTUP_REPORT_PERIOD and not (bag / METADATA_FILE).exists():
                said = now  # the world node opens the bag once it is up; it reports from there on
                running = sum(p.poll() is None for _, p in children)
                print(f"[swarm-run] {now - launched:5.1f} s: waiting for the world node to come up "
                      f"({running + 1} processes starting: Python, ROS and pybullet imports)", flush=True)
            for label, p in children:
                # 0, 3, 130: it left because the world ended the run (it said so itself)
                if p.poll() is not None and p.pid not in reported and p.returncode not in (0, 3, 130):
                    reported.add(p.pid)
                    print(f"[swarm-run] the {label} (pid {p.pid}) {_how(p.returncode)} while the run went on; "
                          "the world declares what it ran dead", file=sys.stderr, flush=True)
            time.sleep(0.2)
    except KeyboardInterrupt:
        interrupted = True
        print("[swarm-run] stopping: the world first (it closes the bag), then the other nodes", flush=True)
        _stop([world] if world else [], grace=60.0)
    finally:
        if not interrupted and world is not None and world.poll() is not None and world.returncode >= 0:
            # the world ended the run and said so: a SIGINT would cut the others' own leaving short
            _wait_left([p for _, p in children], LEAVE_GRACE)
        _stop([p for _, p in children], grace=10.0)
        _stop([world] if world else [], grace=60.0)
        shutil.rmtree(envs.profiles, ignore_errors=True)
        if args.shared_memory:
            remove_dead_shm_files()  # robot processes leave without tearing their segments down
        os.close(domain_lock)  # every node is stopped: the domain is free again
    return world, interrupted


def report(args: argparse.Namespace, plan: Plan, bag: Path, world: subprocess.Popen | None,
           interrupted: bool) -> int:
    """Read the bag (repaired first if the world died), print the run's summary and say what
    went wrong; the exit code (`EXIT_CODES`)."""
    if world is None:  # interrupted before anything ran
        return 130
    world_died = world.returncode != 0 and not interrupted
    if world_died and not bag.exists():  # it refused the scenario before opening the bag (it said why)
        print(f"[swarm-run] the world node {_how(world.returncode)} before recording anything", file=sys.stderr)
        return 2
    if world_died:
        print(f"[swarm-run] the world node (pid {world.pid}) {_how(world.returncode)}: the run stopped early; "
              f"repairing the bag's cut-off last file", file=sys.stderr, flush=True)

    try:
        if world_died:
            repair_bag(bag)
        trace = load_run(bag)
        summary = summarize(trace)
    except ValueError as exc:
        print(f"[swarm-run] could not read the bag {bag}: {exc}", file=sys.stderr)
        return 1
    if plan.remote:
        summary["by_host"] = by_host(summary, {"local": plan.local, **plan.remote})
    if args.json:
        print(json.dumps(summary))
    else:
        print("\n".join(_done_lines(summary, trace.config, bag)), flush=True)
    return _verdict(summary, world_died=world_died, interrupted=interrupted)


def main(argv: list[str] | None = None) -> int:
    """Parse, check the run, claim its DDS domain, start its processes, wait, report."""
    args = build_parser().parse_args(argv)
    stop_on_signals()  # Ctrl-C, SIGTERM, SIGHUP: stop the children too, even if started with SIGINT ignored
    try:
        plan = plan_run(args)
    except Refused as exc:
        print(f"swarm-run: {exc}", file=sys.stderr)
        return 2
    try:
        domain, domain_lock = claim_run_domain(args.domain_id)  # held (open) until the processes end
        bag = output_directory(args, plan.scenario)
    except (ValueError, DomainTaken) as exc:
        print(f"swarm-run: {exc}", file=sys.stderr)
        return 2
    envs = dds_environments(args, plan, domain)
    common = scenario_args(args, plan.scenario)
    watching = [*common, "--world-timeout", f"{args.world_timeout:g}"]  # the controllers' and servers'
    announce(args, plan, domain, envs.port, bag)
    key = run_key(args, plan, domain, envs.port, watching)
    world, interrupted = run_processes(args, commands(args, plan, bag, common, watching), envs, key, bag, domain_lock)
    return report(args, plan, bag, world, interrupted)


def _done_lines(summary: dict, scenario: Scenario | None, bag: Path) -> list[str]:
    """The run's end: the same per-paper text as ``swarm-analyze`` (`swarm_sim.analysis.text`)."""
    rtf = summary.get("real_time_factor")
    return [f"[swarm-run] done: {summary['sim_seconds']:.1f} s sim in {summary['wall_seconds']:.1f} s wall"
            + (f" ({rtf}x)" if rtf else ""),
            *summary_lines(summary, scenario),
            *(f"  host {host:<26} {c['robots']} robots: {c['stale']} stale ticks, {c['late']} late commands, "
              f"{c['lost']} ticks without a command, {c['resent']} ticks re-sent, {c['stopped']} stops by the "
              "command timeout" for host, c in (summary.get("by_host") or {}).items()),
            f"[swarm-run] bag: {bag}  (swarm-analyze {bag} --trajectories for its figures)"]


def remote_option(text: str) -> tuple[str, list[str]]:
    """``--remote-controllers HOST=ROBOT,ROBOT,...``."""
    host, _, robots = text.partition("=")
    names = [r for r in robots.split(",") if r]
    if not host or not names:
        raise argparse.ArgumentTypeError(f"expected HOST=ROBOT,ROBOT,..., got {text[:60]!r}")
    return host, names


def _hosts(args: argparse.Namespace, scenario: Scenario) -> tuple[str | None, dict[str, list[str]]]:
    """(the address the run binds or None for loopback, {host: its robots}) from ``--bind``,
    ``--remote-controllers`` and ``--key-file``; raises HostError with the line to print."""
    bind = hosts.bind_address(args.bind) if args.bind else None
    if bind is not None and args.discovery != "server":
        raise hosts.HostError("--bind: a run across hosts discovers through the world (--discovery server)")
    if bind is not None and args.shared_memory:
        raise hosts.HostError("--shared-memory is for a run on one host: across hosts (--bind) the data goes by UDP")
    remote: dict[str, list[str]] = {}
    for host, robots in args.remote_controllers:
        remote.setdefault(host, []).extend(robots)
    if not remote:
        if args.plain_twist:
            raise hosts.HostError("--plain-twist is for the robots' own computers: name them with --remote-controllers")
        return bind, remote
    if bind is None or args.key_file is None:
        raise hosts.HostError("--remote-controllers needs --bind (an address the other hosts reach) and --key-file")
    if args.plain_twist and args.mode != "realtime":
        raise hosts.HostError("--plain-twist: a plain Twist carries no tick, so only --mode realtime can take it")
    named = [r for robots in remote.values() for r in robots]
    if unknown := sorted(set(named) - set(scenario.robot_names)):
        raise hosts.HostError(f"--remote-controllers: no robot {unknown[0]!r} in this run "
                              f"({scenario.robot_names[0]}..{scenario.robot_names[-1]})")
    if len(set(named)) != len(named):
        raise hosts.HostError("--remote-controllers: a robot is named twice")
    return bind, remote


def _write_key(path: Path, key: bytes) -> None:
    """The run's key for other hosts, readable by this user only (a new file: never overwritten)."""
    fd = os.open(path, os.O_WRONLY | os.O_CREAT | os.O_EXCL | os.O_NOFOLLOW, 0o600)
    with os.fdopen(fd, "wb") as f:
        f.write(key)


def _print_remote(domain: int, server: tuple[str, int], remote: dict[str, list[str]], common: list[str],
                  key_file: Path | None) -> None:
    """How other hosts join: a stock ros2 CLI, and each remote host's controllers."""
    join = f"ROS_DOMAIN_ID={domain} "
    where = f"--discovery-server {server[0]}:{server[1]}"
    print(f"[swarm-run] across hosts: discovery server {server[0]}:{server[1]}, domain {domain}; a stock ros2 on a "
          f"host joins with: eval \"$({join}python -m launch_py.hosts env --bind ITS_ADDRESS {where})\"", flush=True)
    for host, robots in remote.items():
        print(f"[swarm-run] on {host}: {join}SWARMFORAGE_KEY_FD=3 swarm-controllers --bind ITS_ADDRESS {where} "
              f"--robots {' '.join(robots)} {shlex.join(common)} 3<{shlex.quote(str(key_file))}", flush=True)


def by_host(summary: dict, robots_of: dict[str, list[str]]) -> dict[str, dict]:
    """The summary's per-robot command counts (`commands_by_robot`) summed per host."""
    per_robot = summary.get("commands_by_robot") or {}
    out = {}
    for host, robots in robots_of.items():
        if robots:
            counts = [per_robot.get(r, {}) for r in robots]
            out[host] = {"robots": len(robots), **{k: sum(c.get(k, 0) for c in counts)
                                                   for k in ("stale", "late", "lost", "resent", "stopped")}}
    return out


def _foxglove_problem(args: argparse.Namespace) -> str | None:
    """Why the live view could not listen where ``--foxglove`` asks (checked before any node
    starts; the world binds the port again a second later), or None."""
    if args.foxglove is None:
        return None
    reason = check_port(args.foxglove_host, args.foxglove)
    if reason is None:
        return None
    return (f"--foxglove {args.foxglove}: cannot listen on {args.foxglove_host}:{args.foxglove} ({reason}); "
            "name a free port, or --foxglove 0 for any free one")


def _pace(args: argparse.Namespace) -> float | None:
    """Lockstep's cap on sim seconds per wall second: ``--real-time-factor`` if given; 1 with
    ``--foxglove`` (a 300 s run would be over in ~20 s otherwise, too fast to watch)."""
    if args.mode != "lockstep":
        return None
    if args.real_time_factor is None and args.foxglove is not None:
        print("[swarm-run] --foxglove in lockstep: paced at 1x real time so it can be watched "
              "(--real-time-factor X to go faster, e.g. 20)", flush=True)
        return 1.0
    return args.real_time_factor


def _how(returncode: int) -> str:
    return f"was killed by signal {-returncode}" if returncode < 0 else f"exited with code {returncode}"


def _verdict(summary: dict, *, world_died: bool, interrupted: bool) -> int:
    """Say what went wrong, if anything; the exit code (`EXIT_CODES`)."""
    say = lambda text: print(f"[swarm-run] {text}", file=sys.stderr, flush=True)
    rejected = summary.get("rejected_messages") or {}
    if rejected:
        total = sum(n for by_reason in rejected.values() for n in by_reason.values())
        kinds = "; ".join(f"{w}: {', '.join(f'{n} {r}' for r, n in rs.items())}" for w, rs in list(rejected.items())[:6])
        say(f"{total} messages from the bus were rejected ({kinds})")
    dead = summary.get("dead_nodes") or []
    if dead:
        say(f"declared dead during the run: {', '.join(dead)}")
    if summary["server_stale_ticks"] or summary["stale_ticks"]:
        say(f"lockstep ticks answered late: {summary['stale_ticks']} by controllers, {summary['server_stale_ticks']} "
            "by servers (a slow machine; the run may differ from the batch run of the same seed)")
    ended = summary.get("run_ended", "complete")
    foreign = summary.get("foreign_publishers") or []
    if foreign:
        say(f"the run is tainted: foreign publishers on its topics ({'; '.join(foreign[:5])}"
            f"{' ...' if len(foreign) > 5 else ''}): its results may hold what they sent")
    if world_died:
        return 5
    if interrupted or ended == "interrupted":
        return 130
    if foreign:
        return 6
    if ended.startswith("server"):
        say(f"the run ended early: {ended}")
        return 3
    return 4 if dead else 0


if __name__ == "__main__":
    sys.exit(main())

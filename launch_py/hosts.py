"""The graph across hosts: DDS bound to one named interface, discovery through the run's server.

By default every process of a run speaks DDS on loopback only (`launch_py.dds`). To put the
controllers on other machines (a lab's cluster, the robots' own computers), each process is told
the one address it may use, ``--bind ADDR|INTERFACE``, and where the run's discovery server is,
``--discovery-server ADDR:PORT`` (the world node is that server: it serves on its own bind address,
port 6400 + domain unless told otherwise). Its Fast DDS profile is then the loopback profile with
127.0.0.1 replaced by that address everywhere (interface allow-list, unicast and metatraffic
locators), so every socket binds that address alone: never 0.0.0.0, no multicast, no shared memory.

``--bind`` refuses the unspecified address (0.0.0.0), multicast and broadcast addresses, and any
address no interface of this machine (or network namespace) holds. The domain is the run's
``ROS_DOMAIN_ID``, which every host must share. Across hosts, links lose packets, so reliable
writers heartbeat every 100 ms (`HEARTBEAT_NS`) and lockstep nodes wait for their reliable
messages of a tick to be acknowledged before they answer it (`ACK_WAIT`).

swarm-run takes ``--bind`` itself (`launch_py.run`); ``swarm-world``, ``swarm-server`` and
``swarm-controllers`` take both flags through `node_main`, which sets the process's environment
(its profile in `profile_dir`) before the node imports rclpy.

``python -m launch_py.hosts env --bind ADDR --discovery-server ADDR:PORT`` prints the environment
(and writes the profile) that lets a stock ``ros2`` CLI on that host join the run, as a super
client of the discovery server (docs/across_hosts.md).
"""

from __future__ import annotations

import argparse
import atexit
import contextlib
import errno
import fcntl
import importlib
import ipaddress
import os
import socket
import struct
import sys
import tempfile
import xml.etree.ElementTree as ET
from collections.abc import Mapping
from pathlib import Path

from launch_py import dds

LOOPBACK = "127.0.0.1"
ROLES = ("server", "client", "robot", "cli")
"""What a process is in the run's discovery: the world (the discovery server), a server node
(client), a controller process (client that reads no ROS graph, `dds.robot_profile`), a CLI
(super client: sees the whole graph)."""
_SIOCGIFADDR = 0x8915
_SIOCGIFFLAGS = 0x8913
_IFF_UP, _IFF_RUNNING = 0x1, 0x40


class HostError(ValueError):
    """A bad ``--bind`` or ``--discovery-server``: the message names it and why."""


def interface_address(name: str) -> str | None:
    """The IPv4 address of interface `name` in this network namespace, or None if it has none."""
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as s:
        try:
            packed = fcntl.ioctl(s.fileno(), _SIOCGIFADDR, struct.pack("256s", name.encode()[:15]))
        except OSError:
            return None
    return socket.inet_ntoa(packed[20:24])


def not_running(address: str) -> str | None:
    """The name of the interface holding `address` if that interface is not running (down, or up
    without a carrier yet: the kernel reports a new link's carrier a moment after it is set up),
    else None. Fast DDS leaves such an interface out of its list, so a participant bound to its
    address fails to be created ("failed to create participant", no reason given)."""
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as s:
        for _, name in socket.if_nameindex():
            if interface_address(name) != address:
                continue
            try:
                packed = fcntl.ioctl(s.fileno(), _SIOCGIFFLAGS, struct.pack("256s", name.encode()[:15]))
            except OSError:
                return None
            flags = struct.unpack_from("H", packed, 16)[0]
            return None if flags & _IFF_UP and flags & _IFF_RUNNING else name
    return None


def is_local(address: str) -> bool:
    """Whether an interface of this machine (network namespace) holds `address` (a UDP bind to it
    succeeds; EADDRNOTAVAIL otherwise)."""
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as s:
        try:
            s.bind((address, 0))
        except OSError as exc:
            if exc.errno == errno.EADDRNOTAVAIL:
                return False
            raise
    return True


def bind_address(text: str) -> str:
    """``--bind``: an IPv4 address this host holds, or the name of an interface with one; the
    unspecified, multicast and broadcast addresses are refused (HostError)."""
    try:
        address = ipaddress.IPv4Address(text)
    except ValueError:
        if text not in {name for _, name in socket.if_nameindex()}:
            raise HostError(f"--bind {text[:40]!r}: neither an IPv4 address nor an interface of this host") from None
        found = interface_address(text)
        if found is None:
            raise HostError(f"--bind {text}: the interface has no IPv4 address")
        address = ipaddress.IPv4Address(found)
    if address.is_unspecified:
        raise HostError(f"--bind {text}: DDS binds one named address, never every interface (0.0.0.0)")
    if address.is_multicast or address == ipaddress.IPv4Address("255.255.255.255"):
        raise HostError(f"--bind {text}: a multicast or broadcast address cannot be bound")
    if not is_local(str(address)):
        raise HostError(f"--bind {text}: no interface of this host holds {address}")
    down = not_running(str(address))
    if down is not None:
        raise HostError(f"--bind {text}: interface {down} is not running (down, or no carrier): DDS cannot bind "
                        "its address until the link is up")
    return str(address)


def server_address(text: str) -> tuple[str, int]:
    """``--discovery-server``: ``ADDR:PORT`` (IPv4, port 1-65535) -> (address, port)."""
    host, _, port = text.rpartition(":")
    try:
        address = ipaddress.IPv4Address(host)
        number = int(port)
    except ValueError:
        raise HostError(f"--discovery-server {text[:40]!r}: expected IPV4_ADDRESS:PORT") from None
    if address.is_unspecified or address.is_multicast or not 0 < number < 65536:
        raise HostError(f"--discovery-server {text}: not an address and port a server can listen on")
    return str(address), number


def rebind(profile: str, address: str) -> str:
    """A profile of `launch_py.dds` (loopback) with `address` in place of 127.0.0.1 everywhere."""
    ours = f"<address>{LOOPBACK}</address>"
    if ours not in profile:
        raise ValueError("not a loopback profile of launch_py.dds")
    return profile.replace(ours, f"<address>{address}</address>")


ACK_WAIT_ENV = "SWARMFORAGE_ACK_WAIT"
"""`swarm_sim.nodes.endpoint.ACK_WAIT_ENV` (not imported: this module runs before rclpy is)."""
ACK_WAIT = 10.0
"""Across hosts, wall seconds a node waits for its reliable messages of a tick to be acknowledged
before it answers the tick (`swarm_sim.nodes.endpoint.wait_acked`): past a partition of that
length a run may leave the batch run's path. A node waiting longer than the world's tick timeout
is stale at that tick first (and dead after three): runs across unreliable links want a
``--tick-timeout`` above the outages they should ride out (docs/across_hosts.md)."""
HEARTBEAT_NS = 100_000_000
"""Reliable writers' heartbeat period across hosts [ns] (Fast DDS's default: 3 s). A reader learns
that it missed a sample from the writer's next heartbeat (or a later sample), so on a lossy link
a lost status or protocol message waited up to 3 s: at the end of a run, longer than the world
listens for the robots' last messages (measured: 5 % loss, a robot's last status missing from the
bag). Writers send periodic heartbeats only while a reader has not acknowledged everything."""


def host_profile(role: str, bind: str, server_port: int) -> str:
    """The Fast DDS profile of a process in `role` (`ROLES`) bound to `bind`, its reliable writers
    heartbeating every `HEARTBEAT_NS`."""
    if role == "server":
        profile = dds.server_profile(server_port)
    elif role == "robot":
        profile = dds.robot_profile()
    else:
        profile = ET.tostring(dds._loopback_profile(), encoding="unicode")  # as the others: no comments
    return with_heartbeat(rebind(profile, bind))


LOOPBACK_HEARTBEAT_NS = 10_000_000
"""On one host with the acknowledgement wait asked for (``SWARMFORAGE_ACK_WAIT``): reliable writers
heartbeat every 10 ms (loopback's round trip is microseconds; the wait lasts until the reader's
answer to a heartbeat)."""


def with_heartbeat(profile: str, period_ns: int = HEARTBEAT_NS) -> str:
    """`profile` with its reliable writers heartbeating every `period_ns` (a node waiting for its
    messages to be acknowledged, `ACK_WAIT`, waits for the reader's answer to a heartbeat)."""
    writer = (f'<data_writer profile_name="swarmforage_hosts_writer" is_default_profile="true"><times>'
              f"<heartbeatPeriod><sec>0</sec><nanosec>{period_ns}</nanosec></heartbeatPeriod></times></data_writer>")
    return profile.replace("</profiles>", writer + "</profiles>", 1)


def host_env(role: str, domain_id: int, bind: str, server: tuple[str, int], profile_path: Path,
             base: Mapping[str, str] | None = None) -> dict[str, str]:
    """The environment of a process in `role` of a run on `domain_id` across hosts: the profile
    at `profile_path` (`host_profile`), and for every role but the server the server's address."""
    env = dds.loopback_env(domain_id, 1, base)
    env[ACK_WAIT_ENV] = str(ACK_WAIT)
    env["FASTRTPS_DEFAULT_PROFILES_FILE"] = env["FASTDDS_DEFAULT_PROFILES_FILE"] = str(profile_path)
    if role != "server":
        env["ROS_DISCOVERY_SERVER"] = f"{server[0]}:{server[1]}"
    if role == "cli":
        env["ROS_SUPER_CLIENT"] = "TRUE"
    return env


def run_domain(env: Mapping[str, str] | None = None) -> int:
    """The run's domain from ``ROS_DOMAIN_ID`` (HostError if unset or out of range)."""
    text = (os.environ if env is None else env).get("ROS_DOMAIN_ID", "").strip()
    if not text.isdigit() or int(text) > dds.MAX_DOMAIN_ID:
        raise HostError(f"ROS_DOMAIN_ID={text[:20]!r}: a run across hosts needs the run's domain id "
                        f"(0-{dds.MAX_DOMAIN_ID}) in ROS_DOMAIN_ID on every host")
    return int(text)


def resolve(role: str, bind: str | None, server: str | None, domain_id: int) -> tuple[str, tuple[str, int]]:
    """(bind address, discovery server) of a process in `role` from its flags. The server (the
    world) serves on its own address (port 6400 + domain unless ``--discovery-server`` names
    another port); every other role needs ``--discovery-server``. Without ``--bind``, loopback."""
    address = bind_address(bind) if bind else LOOPBACK
    if role == "server":
        found = server_address(server) if server else (address, dds.discovery_port(domain_id))
        if found[0] != address:
            raise HostError(f"--discovery-server {server}: the world serves discovery on its own --bind address "
                            f"{address}")
        return address, found
    if server is None:
        raise HostError("--bind needs --discovery-server ADDR:PORT (the world's address and discovery port)")
    return address, server_address(server)


def add_host_arguments(parser: argparse.ArgumentParser) -> None:
    """``--bind`` and ``--discovery-server``."""
    parser.add_argument("--bind", metavar="ADDR|IFACE",
                        help="DDS across hosts: bind every socket to this IPv4 address (or the interface's) only "
                             "(default: loopback as the launcher sets it up); needs ROS_DOMAIN_ID")
    parser.add_argument("--discovery-server", metavar="ADDR:PORT",
                        help="the run's discovery server: the world node's --bind address and port (default 6400 + "
                             "domain); required with --bind for every node but the world")


def profile_dir() -> Path:
    """This user's directory of the node commands' profiles (mode 0700), without the profiles of
    processes that have ended: a node removes its own when it exits, one killed outright leaves
    it for the next to prune. (Fast DDS takes a profile only from a real file: it resolves the
    path, so an anonymous memory file does not do.)"""
    path = Path(tempfile.gettempdir()) / f"swarmforage-hosts-{os.getuid()}"
    path.mkdir(mode=0o700, exist_ok=True)
    info = path.lstat()
    if not path.is_dir() or path.is_symlink() or info.st_uid != os.getuid() or info.st_mode & 0o077:
        raise HostError(f"{path}: not a private directory of this user; remove it")
    for old in path.glob("*.xml"):
        pid = old.stem.rpartition("-")[2]
        if pid.isdigit() and not Path(f"/proc/{pid}").exists():
            with contextlib.suppress(OSError):
                old.unlink()
    return path


def apply(role: str, bind: str | None, server: str | None) -> None:
    """Make this process a `role` of a run across hosts: its profile written to `profile_dir`
    (removed when it exits) and its environment set. Call before ``rclpy.init`` (the rmw reads
    both when the first participant is made). Raises HostError."""
    domain = run_domain()
    address, found = resolve(role, bind, server, domain)
    path = profile_dir() / f"{role}-{os.getpid()}.xml"
    path.write_text(host_profile(role, address, found[1]), encoding="utf-8")
    atexit.register(_remove, path, os.getpid())
    dds.apply_to_current_process(host_env(role, domain, address, found, path))


def _remove(path: Path, owner: int) -> None:
    if os.getpid() == owner:  # not in a forked robot process that happens to run atexit
        with contextlib.suppress(OSError):
            path.unlink()


NODES = {
    "world": ("server", "swarm_sim.nodes.world_node", "swarm-world"),
    "server": ("client", "swarm_sim.nodes.server_node", "swarm-server"),
    "controllers": ("robot", "swarm_sim.nodes.controller_node", "swarm-controllers"),
}
"""The node commands that take ``--bind``/``--discovery-server``: (role, module, program)."""


def node_main(kind: str, argv: list[str] | None = None) -> int:
    """A node command (`NODES`) with the host flags: they are applied, the rest goes to the node."""
    role, module, prog = NODES[kind]
    argv = sys.argv[1:] if argv is None else argv
    parser = argparse.ArgumentParser(prog=prog, add_help=False)
    add_host_arguments(parser)
    args, rest = parser.parse_known_args(argv)
    if "-h" in rest or "--help" in rest:  # the node's help, then these two options'
        try:
            return importlib.import_module(module).main(rest)
        finally:
            print(f"\nacross hosts (docs/across_hosts.md):\n{parser.format_help().split(chr(10), 2)[2]}")
    if args.bind is not None or args.discovery_server is not None:
        try:
            apply(role, args.bind, args.discovery_server)
        except HostError as exc:
            print(f"{prog}: {exc}", file=sys.stderr)
            return 2
    return importlib.import_module(module).main(rest)  # after `apply`: the node imports rclpy


def world(argv: list[str] | None = None) -> int:
    """``swarm-world``."""
    return node_main("world", argv)


def server(argv: list[str] | None = None) -> int:
    """``swarm-server``."""
    return node_main("server", argv)


def controllers(argv: list[str] | None = None) -> int:
    """``swarm-controllers``."""
    return node_main("controllers", argv)


def main(argv: list[str] | None = None) -> int:
    """``python -m launch_py.hosts world|server|controllers ARGS``: a node (`node_main`);
    ``... env --bind ADDR --discovery-server ADDR:PORT``: the variables (``export`` lines) and the
    profile for a stock ``ros2`` CLI on this host."""
    argv = sys.argv[1:] if argv is None else argv
    if argv and argv[0] in NODES:
        return node_main(argv[0], argv[1:])
    parser = argparse.ArgumentParser(prog="python -m launch_py.hosts", description=__doc__.split("\n\n")[0],
                                     epilog="world|server|controllers ARGS: that node with --bind/--discovery-server")
    parser.add_argument("what", choices=("env",), help="env: print the variables for a stock ros2 on this host")
    add_host_arguments(parser)
    parser.add_argument("--profile", type=Path, default=Path("swarmforage_cli.xml"),
                        help="where to write the CLI's Fast DDS profile (default ./swarmforage_cli.xml)")
    args = parser.parse_args(argv)
    if args.bind is None or args.discovery_server is None:
        parser.error("env needs --bind and --discovery-server")
    try:
        domain = run_domain()
        bind, server = resolve("cli", args.bind, args.discovery_server, domain)
    except HostError as exc:
        parser.error(str(exc))
    args.profile.write_text(host_profile("cli", bind, server[1]), encoding="utf-8")
    env = host_env("cli", domain, bind, server, args.profile.resolve(), base={})
    for key in ("ROS_DOMAIN_ID", "RMW_IMPLEMENTATION", "ROS_AUTOMATIC_DISCOVERY_RANGE", "SKIP_DEFAULT_XML_FILE",
                "RMW_FASTRTPS_PUBLICATION_MODE", "FASTRTPS_DEFAULT_PROFILES_FILE", "FASTDDS_DEFAULT_PROFILES_FILE",
                "ROS_DISCOVERY_SERVER", "ROS_SUPER_CLIENT"):
        print(f"export {key}={env[key]}")
    print("unset ROS_LOCALHOST_ONLY ROS_STATIC_PEERS")
    return 0


if __name__ == "__main__":
    sys.exit(main())

"""Loopback-only DDS environment for every process swarmforage starts.

rmw_fastrtps (Jazzy) reads discovery settings from the environment when a process
creates its first rclpy context, so everything here is plain environment variables;
this module never imports rclpy.

* Every process gets the Fast DDS profile ``fastdds_loopback.xml`` (UDP bound to
  127.0.0.1 only, no multicast, no shared memory, SPDP sent to 256 participant ids on
  127.0.0.1), so the graph is reachable from loopback only. Plain
  ``ROS_AUTOMATIC_DISCOVERY_RANGE=LOCALHOST`` is not enough: rmw_fastrtps then announces to
  127.0.0.1 only but binds its sockets to 0.0.0.0 and the LAN address (and guesses peers
  by participant index: 32 of 40 peers found in 60 s). The range must be ``SYSTEM_DEFAULT``: rmw_fastrtps
  starts from the XML default profile and, for ``LOCALHOST``, adds a 0.0.0.0 unicast
  locator and initial peers on top of it, for ``SUBNET`` it adds ``ROS_STATIC_PEERS``;
  only ``SYSTEM_DEFAULT`` leaves the profile alone.
"""

from __future__ import annotations

import errno
import fcntl
import os
import socket
import tempfile
import xml.etree.ElementTree as ET
from collections.abc import Mapping
from pathlib import Path

PROFILE_PATH = Path(__file__).with_name("fastdds_loopback.xml")
PROFILE_MAX_PROCESSES = 256
"""Participants per domain the profile can discover (its maxInitialPeersRange)."""
MAX_DOMAIN_ID = 230
"""The highest ROS_DOMAIN_ID whose ports the profile can compute: participant 255 of domain d
uses UDP port 7400 + 250 d + 11 + 2 * 255, which passes 65535 from d = 231 on (Fast DDS then
fails every participant with "Calculated port number is too high")."""
DOMAIN_RANGE = (1, 100)
"""Inclusive range of private ROS_DOMAIN_IDs, clear of 0 (everyone's default): the range ROS 2's
own test isolation draws from (domain_coordinator: 1-100), inside the "0 to 101" of ROS 2's
*About Domain ID*. A domain owns UDP ports 7400 + 250 * domain + 10 + 2 * participant (+1), so
up to 120 processes a domain stay below `EPHEMERAL_FLOOR`: above domain 101 they lie among the
ports the kernel hands to any socket on the machine, and Fast DDS meets them taken."""
EPHEMERAL_FLOOR = 32768
"""The lowest port of Linux's default ephemeral range (net.ipv4.ip_local_port_range)."""

_DROPPED = (
    # Each of these would override or extend the discovery chosen here.
    "ROS_LOCALHOST_ONLY",  # Jazzy: if 1, wins over ROS_AUTOMATIC_DISCOVERY_RANGE
    "ROS_STATIC_PEERS",  # extra (possibly remote) initial peers
    "ROS_DISCOVERY_SERVER",  # Fast DDS turns SIMPLE into a discovery-server client
    "ROS_SUPER_CLIENT",
    "FASTDDS_BUILTIN_TRANSPORTS",
    "FASTRTPS_DEFAULT_PROFILES_FILE",
    "FASTDDS_DEFAULT_PROFILES_FILE",
    "RMW_FASTRTPS_USE_QOS_FROM_XML",
    "FASTDDS_ENVIRONMENT_FILE",
    "SKIP_DEFAULT_XML_FILE",
    "RMW_FASTRTPS_PUBLICATION_MODE",
)


def loopback_env(
    domain_id: int, processes: int, base: Mapping[str, str] | None = None, *, server_port: int | None = None,
) -> dict[str, str]:
    """Environment for a child process of a graph of ``processes`` DDS processes.

    ``base`` defaults to ``os.environ``; discovery-related variables in it are
    replaced, everything else is kept. With `server_port`, the process is a client of the
    graph's discovery server on 127.0.0.1 (`discovery_server_env` makes the server).
    """
    if not 0 <= domain_id <= MAX_DOMAIN_ID:
        raise ValueError(f"ROS_DOMAIN_ID {domain_id} outside 0..{MAX_DOMAIN_ID}")
    if processes > PROFILE_MAX_PROCESSES:
        raise ValueError(f"{processes} processes exceed the profile's {PROFILE_MAX_PROCESSES}")
    env = {k: v for k, v in (os.environ if base is None else base).items() if k not in _DROPPED}
    env["RMW_IMPLEMENTATION"] = "rmw_fastrtps_cpp"
    env["ROS_DOMAIN_ID"] = str(domain_id)
    # No DEFAULT_FASTRTPS_PROFILES.xml from the working directory on top of ours.
    env["SKIP_DEFAULT_XML_FILE"] = "1"
    env["ROS_AUTOMATIC_DISCOVERY_RANGE"] = "SYSTEM_DEFAULT"
    env["FASTRTPS_DEFAULT_PROFILES_FILE"] = str(PROFILE_PATH)  # the Fast DDS 2.x name
    env["FASTDDS_DEFAULT_PROFILES_FILE"] = str(PROFILE_PATH)  # the Fast DDS 3.x name
    # Lockstep delivery relies on it: publish() puts the bytes on the socket before it returns,
    # so a robot's message stamped k reaches its peers before its cmd_vel k lets the world send
    # tick k+1 (asynchronous publication would let a sender thread reorder them under load).
    env["RMW_FASTRTPS_PUBLICATION_MODE"] = "SYNCHRONOUS"
    if server_port is not None:
        # Fast DDS turns the profile's SIMPLE discovery into a client of server id 0 there.
        env["ROS_DISCOVERY_SERVER"] = f"127.0.0.1:{server_port}"
    return env


# --------------------------------------------------------------------------- discovery server

SERVER_PREFIX = "44.53.00.5f.45.50.52.4f.53.49.4d.41"
"""GUID prefix of discovery server id 0: the one ``ROS_DISCOVERY_SERVER=127.0.0.1:PORT`` names."""


DISCOVERY_PORT_BASE = 6400
"""A graph's discovery server listens on this + domain (6400-6630): below every domain's RTPS
ports (7400 + 250 d ...), so concurrent runs on other domains never share it, and below the
ports every Fast DDS 2.14 participant on the machine binds one each of, counting up from 7000
(a reader's own listening port): at 7000 + domain, a 112-process run elsewhere on the machine
took domain 103's port, and every run asking for domain 103 was refused as "in use"."""


def discovery_port(domain_id: int) -> int:
    """The graph's discovery server port: `DISCOVERY_PORT_BASE` + domain."""
    return DISCOVERY_PORT_BASE + domain_id


_PROFILE_NS = "http://www.eprosima.com/XMLSchemas/fastRTPS_Profiles"


def _loopback_profile() -> ET.Element:
    """The loopback profile's XML tree, to derive a role's profile from (`_tag` names its tags)."""
    ET.register_namespace("", _PROFILE_NS)
    return ET.parse(PROFILE_PATH).getroot()


def _tag(tag: str) -> str:
    """A Fast DDS profile tag with its namespace."""
    return f"{{{_PROFILE_NS}}}{tag}"


def server_profile(port: int) -> str:
    """The loopback profile with discovery-server role: prefix of server id 0, metatraffic on
    127.0.0.1:`port` (everything else, transports and interface allow-list, unchanged)."""
    root = _loopback_profile()
    rtps = root.find(f".//{_tag('participant')}/{_tag('rtps')}")
    assert rtps is not None
    prefix = ET.Element(_tag("prefix"))
    prefix.text = SERVER_PREFIX
    rtps.insert(0, prefix)
    builtin = rtps.find(_tag("builtin"))
    builtin.find(f"{_tag('discovery_config')}/{_tag('discoveryProtocol')}").text = "SERVER"
    udp = builtin.find(f"{_tag('metatrafficUnicastLocatorList')}/{_tag('locator')}/{_tag('udpv4')}")
    ET.SubElement(udp, _tag("port")).text = str(port)
    builtin.remove(builtin.find(_tag("initialPeersList")))
    return ET.tostring(root, encoding="unicode")


def robot_profile() -> str:
    """The loopback profile for robot controller processes: their ``ros_discovery_info``
    readers ask for exclusive ownership, which no writer offers, so robots never match each
    other's (or anyone's) ROS graph announcements. Every process writes that topic and, by
    default, reads it: with a process per robot that is N x N reliable writer-reader pairs, the
    bulk of a 112-process start-up. A controller needs no graph (it counts matches, which come
    from DDS discovery); the world, the servers and a `ros2` CLI still read every process's
    announcements, so node names and parameter services stay visible."""
    root = _loopback_profile()
    profiles = root.find(_tag("profiles"))
    reader = ET.SubElement(profiles, _tag("data_reader"), profile_name="ros_discovery_info")
    kind = ET.SubElement(ET.SubElement(ET.SubElement(reader, _tag("qos")), _tag("ownership")), _tag("kind"))
    kind.text = "EXCLUSIVE"
    return ET.tostring(root, encoding="unicode")


SHM_SEGMENT_BYTES = 8 * 2**20
"""Each process's shared-memory segment: room for the messages in flight (the 1000-robot world
sends ~4000 observations a tick, ~1 KB each, before the first controller has read many)."""
SHM_PORT_QUEUE = 8192
"""Messages a process's shared-memory port queues (the default 512 is one tick of a 112-robot
controller process's observations; a full queue drops a message and lockstep has to re-send)."""


def with_shared_memory(profile: str) -> str:
    """`profile` (XML) with Fast DDS's shared-memory transport beside its UDP one, for processes on
    this host: data goes through segments in /dev/shm, no socket and no network stack (issue 27:
    9-17 % less CPU a tick with 112 robots in one controller process, but ~10 % more with a process
    per robot: its per-port listener threads wake more); discovery stays on UDP 127.0.0.1, and a
    peer with no shared memory (a `ros2` CLI with the plain profile) is sent UDP. The explicit UDP
    default locator goes (it would hide the shared-memory one); the interface allow-list still binds
    UDP to 127.0.0.1 alone. Not for processes on other hosts or network namespaces: they share this
    machine's /dev/shm and would bypass the network."""
    root = ET.fromstring(profile)
    shm = ET.SubElement(root.find(f".//{_tag('transport_descriptors')}"), _tag("transport_descriptor"))
    for tag, text in (("transport_id", "swarmforage_shm"), ("type", "SHM"), ("segment_size", str(SHM_SEGMENT_BYTES)),
                      ("port_queue_capacity", str(SHM_PORT_QUEUE))):
        ET.SubElement(shm, _tag(tag)).text = text
    rtps = root.find(f".//{_tag('participant')}/{_tag('rtps')}")
    ET.SubElement(rtps.find(_tag("userTransports")), _tag("transport_id")).text = "swarmforage_shm"
    rtps.remove(rtps.find(_tag("defaultUnicastLocatorList")))
    return ET.tostring(root, encoding="unicode")


def remove_dead_shm_files(directory: Path = Path("/dev/shm")) -> int:
    """Remove Fast DDS's shared-memory files whose owner is gone (as ``fastdds shm clean``): a live
    owner holds a lock on the segment's or port's ``_el``/``_sl`` file; robot processes leave
    without tearing down (`swarm_sim.nodes.controller_node.serve_forked`) and killed ones cannot,
    so each run's launcher sweeps before and after. Returns the files removed."""
    removed = 0
    try:
        names = os.listdir(directory)
    except OSError:
        return 0
    for name in names:
        if not (name.startswith("fastrtps_") and name.endswith(("_el", "_sl"))):
            continue
        lock = directory / name
        try:
            with open(lock, "ab") as f:
                fcntl.flock(f, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except OSError:
            continue  # its owner lives (or it went meanwhile)
        base = name[:-3]
        for victim in (lock, directory / base, directory / f"sem.{base}_mutex"):
            try:
                victim.unlink()
                removed += 1
            except OSError:
                pass
    return removed


def discovery_server_env(env: Mapping[str, str], profile_path: Path) -> dict[str, str]:
    """`env` (a client's) made the discovery server's: its own profile, no server to call."""
    out = {k: v for k, v in env.items() if k != "ROS_DISCOVERY_SERVER"}
    out["FASTRTPS_DEFAULT_PROFILES_FILE"] = out["FASTDDS_DEFAULT_PROFILES_FILE"] = str(profile_path)
    return out


def private_domain_id(seed: int | None = None) -> int:
    """ROS_DOMAIN_ID for one run: the user's ``ROS_DOMAIN_ID`` if set, else one
    derived from ``seed`` (default: this pid) in ``DOMAIN_RANGE``, so concurrent
    runs and tests rarely share a domain."""
    user = os.environ.get("ROS_DOMAIN_ID", "").strip()
    if user:
        return int(user)
    lo, hi = DOMAIN_RANGE
    return lo + (os.getpid() if seed is None else seed) % (hi - lo + 1)


def apply_to_current_process(env: Mapping[str, str]) -> None:
    """Make ``env`` the environment of this process.

    Call it BEFORE ``import rclpy`` (and before any other module that imports it):
    the rmw reads these variables when the first context is initialised, and Fast DDS
    loads its XML profile only once per process, so later changes have no effect.
    """
    for key in _DROPPED:
        if key not in env:
            os.environ.pop(key, None)
    os.environ.update(env)


# --------------------------------------------------------------------------- one run per domain

PROBED_PARTICIPANTS = 8
"""Participant ids whose well-known ports `domain_in_use` probes: a graph's first processes take
the lowest free ids, so a live graph holds some of the first few."""


def participant_ports(domain_id: int, participant: int) -> tuple[int, int]:
    """The UDP ports a Fast DDS participant binds on 127.0.0.1 (RTPS well-known ports): its
    metatraffic and its user-data unicast ports."""
    base = 7400 + 250 * domain_id + 10 + 2 * participant
    return base, base + 1


def udp_port_taken(port: int, host: str = "127.0.0.1") -> bool:
    """Whether a UDP socket of any process is bound to `port` on `host` (or on every address)."""
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as probe:
        try:
            probe.bind((host, port))
        except OSError as exc:
            if exc.errno == errno.EADDRINUSE:
                return True
            raise
    return False


def domain_in_use(domain_id: int) -> str | None:
    """Why `domain_id` is in use on this machine, or None if it looks free: the graph's discovery
    server port is bound (another run's world, or any other program), or a DDS participant of the
    domain is up (both well-known ports of one of its first participant ids bound: one port alone
    may be another program's ephemeral socket)."""
    port = discovery_port(domain_id)
    if udp_port_taken(port):
        return f"its discovery server port 127.0.0.1:{port} is taken"
    for participant in range(PROBED_PARTICIPANTS):
        meta, user = participant_ports(domain_id, participant)
        if udp_port_taken(meta) and udp_port_taken(user):
            return f"a DDS participant is on it (UDP ports {meta} and {user} are bound)"
    return None


class DomainTaken(Exception):
    """The domain a run asked for is in use; the message says why and what to do."""


def _lock_path(domain_id: int) -> Path:
    return Path(tempfile.gettempdir()) / f"swarmforage-domain-{domain_id}.lock"


def claim_domain(domain_id: int) -> int:
    """Reserve `domain_id` for this process's run: an exclusive lock on a per-domain file (two
    launchers starting at once cannot both pass), then `domain_in_use` (anything else on it).
    Returns the lock's file descriptor (keep it open for the run: closing it, or the process
    ending however it ends, frees the domain); raises DomainTaken."""
    try:
        fd = os.open(_lock_path(domain_id), os.O_RDWR | os.O_CREAT | os.O_NOFOLLOW | os.O_CLOEXEC, 0o600)
    except OSError as exc:  # another user's lock file, or a symlink planted in its place
        raise DomainTaken(f"domain {domain_id} is in use (its lock {_lock_path(domain_id)}: {exc.strerror})") from None
    try:
        fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
    except OSError:
        os.close(fd)
        raise DomainTaken(f"domain {domain_id} is in use by another swarmforage run on this machine") from None
    why = domain_in_use(domain_id)
    if why is not None:
        os.close(fd)
        raise DomainTaken(f"domain {domain_id} is in use: {why}")
    return fd


def _reservation_path(domain_id: int) -> Path:
    return Path(tempfile.gettempdir()) / f"swarmforage-domain-{domain_id}.reserved"


def _try_lock(path: Path) -> int | None:
    """An exclusive lock on `path` (its descriptor), or None if another process holds it (or the
    file is another user's, or a symlink)."""
    try:
        fd = os.open(path, os.O_RDWR | os.O_CREAT | os.O_NOFOLLOW | os.O_CLOEXEC, 0o600)
    except OSError:
        return None
    try:
        fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
    except OSError:
        os.close(fd)
        return None
    return fd


def reserve_free_domain(first: int | None = None) -> tuple[int, int]:
    """A domain of `DOMAIN_RANGE` reserved for this process, which then hands it to runs by
    number (``--domain-id N``, as a test session does): an exclusive lock on the domain's
    reservation file, taken only where no run holds the domain and nothing uses it. ``auto``
    (`claim_free_domain`) passes over reserved domains, so concurrent test sessions and
    runs never pick one twice. Returns (domain, the reservation's fd: keep it open); raises
    DomainTaken if none is free."""
    lo, hi = DOMAIN_RANGE
    start = lo + os.getpid() % (hi - lo + 1) if first is None else first
    for k in range(hi - lo + 1):
        domain = lo + (start - lo + k) % (hi - lo + 1)
        reservation = _try_lock(_reservation_path(domain))
        if reservation is None:
            continue
        try:
            os.close(claim_domain(domain))  # free now: no run on it, nothing bound
        except DomainTaken:
            os.close(reservation)
            continue
        return domain, reservation
    raise DomainTaken(f"every domain {lo}-{hi} is reserved or in use")


def claim_free_domain(first: int | None = None) -> tuple[int, int]:
    """A free domain of `DOMAIN_RANGE`, claimed (`claim_domain`), trying from `first` (default:
    the one this process's pid gives) upwards and passing over domains another process has
    reserved (`reserve_free_domain`); (domain, lock fd). Raises DomainTaken if none is free."""
    lo, hi = DOMAIN_RANGE
    start = lo + os.getpid() % (hi - lo + 1) if first is None else first
    for k in range(hi - lo + 1):
        domain = lo + (start - lo + k) % (hi - lo + 1)
        reservation = _try_lock(_reservation_path(domain))
        if reservation is None:  # reserved by a test session (or another auto claim this instant)
            continue
        try:
            return domain, claim_domain(domain)
        except DomainTaken:
            continue
        finally:
            os.close(reservation)  # the run's claim holds it from here
    raise DomainTaken(f"every domain {lo}-{hi} is in use")

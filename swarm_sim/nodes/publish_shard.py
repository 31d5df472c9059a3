"""Publishing shards: the world's observations sent by K processes of their own (issue 40, lever 5;
``swarm-run --publish-shards K``, off by default).

Why: publication is synchronous, so the world's main thread serialises and sends every robot's
odometry, scan and sense itself while the physics waits. `benchmarks/bench_publish_shards.py`
(the lockstep loop with the real codecs' bytes, 2 cores) measured the move: 1000 robots in 4
controller processes went from 68.9 to 59.8 ms wall a tick (every process's CPU 124 -> 113 ms,
the world's main thread 49.8 -> 20.7 ms); 112 robots in one controller process did not gain
(5.2 -> 5.7 ms: two more processes to wake on two cores). More cores let the shards send beside
the world's next step instead of taking turns with it.

How: the world still encodes and records every observation (the bag is the same). Shard k owns the
observation publishers (same topics, same QoS) of robots k::K (`shard_robots`). Each tick the world
writes shard k's messages, length-prefixed in its publishers' order (`frame`), into shard k's
region of a shared-memory block (`ShardWriter`) and sends the tick's stamp on the shard's socket;
the shard publishes them raw (`ShardReader`) and answers ``done``. A tick larger than its region
moves that shard to a new, larger block (said once, nothing dropped). Before writing the next
tick the world waits for ``done`` of every wake it sent (`ShardWriter.settle`): the lockstep
barrier alone does not prove a shard has finished reading (a tick closed by its timeout, a re-sent
tick still being published, a dead robot's messages, realtime mode), and the wait costs nothing
when it has. A shard leaves when its socket ends (the world ended) or with the world
(``PR_SET_PDEATHSIG``).
"""

from __future__ import annotations

import argparse
import json
import mmap
import os
import signal
import struct
import subprocess
import sys
from collections.abc import Callable, Iterator, Mapping, Sequence
from dataclasses import dataclass
from multiprocessing import Pipe
from multiprocessing.connection import Connection
from multiprocessing.shared_memory import SharedMemory

from swarm_msgs_py import topics
from swarm_sim.nodes.lifetime import die_with_parent, leave, set_process_name

SHARD_ENV = "SWARMFORAGE_SHARD_ENV"
"""The shards' DDS environment as the launcher gives it to the world: JSON ``{"set": {...},
"unset": [...]}`` over the world's own (the world is the discovery server; a shard is a client)."""
REGION_BYTES_PER_ROBOT = 8192
"""A shard's first region per robot [bytes] (a CPFA robot's three messages are ~1 KB; pages never
written take no memory)."""
LENGTH = struct.Struct("<I")
TICK = struct.Struct("<qI")
"""A wake: the tick's stamp [ns] and the bytes of the region it uses."""
REGION = struct.Struct("<QQ")
"""A move to another block: offset and size of the region in it (its name follows)."""
DONE = struct.Struct("<q")


def shard_node_name(k: int) -> str:
    """Shard k's node (in ``/``): the foreign-publisher watch knows it by this name."""
    return f"publish_shard_{k}"


def shard_robots(robots: Sequence[str], count: int) -> list[list[str]]:
    """The robots each of `count` shards publishes for: k::count."""
    return [list(robots[k::count]) for k in range(count)]


def frame(messages: Sequence[bytes]) -> bytes:
    """`messages`, each after its length."""
    parts = []
    for m in messages:
        parts += (LENGTH.pack(len(m)), m)
    return b"".join(parts)


def unframe(buf, used: int) -> Iterator[bytes]:
    """The messages `frame` wrote into the first `used` bytes of `buf`."""
    at = 0
    while at < used:
        (n,) = LENGTH.unpack_from(buf, at)
        at += LENGTH.size
        yield bytes(buf[at:at + n])
        at += n


class ShardDied(Exception):
    """A shard's socket ended under the world: its robots can no longer be sent their ticks."""


@dataclass(frozen=True)
class Region:
    """Where a shard's ticks are written: `size` bytes from `offset` in block `name`."""

    name: str
    """The shared-memory block's name."""
    buf: memoryview
    offset: int
    size: int


class ShardWriter:
    """The world's end of one shard: writes a tick into its region and wakes it (`publish`)."""

    def __init__(self, k: int, conn: Connection, region: Region, new_block: Callable[[int], Region],
                 say: Callable[[str], None]) -> None:
        """`new_block(size)`: a fresh region of `size` bytes, for a tick that does not fit."""
        self.k, self.conn, self.region = k, conn, region
        self._new_block, self._say = new_block, say
        self.sent = self.done = 0
        """Wakes sent, and those the shard has finished."""
        self.ready: list[int] = []
        """Indices (in its robots) of the robots whose every publisher has a subscriber."""
        self._last: bytes | None = None
        self._grown = False

    def publish(self, stamp: int, messages: Sequence[bytes], stopping: Callable[[], bool] = lambda: False) -> None:
        """Tick `stamp`'s `messages` to the shard, once it has finished the last tick."""
        self.settle(stopping)
        if self.done < self.sent:  # the run is stopping: not into a region the shard may be reading
            return
        data = frame(messages)
        region = self.region
        if len(data) > region.size:
            region = self.region = self._new_block(2 * len(data))
            if not self._grown:
                self._grown = True
                self._say(f"publish shard {self.k}: a tick of {len(data)} bytes outgrew its region; moved to a "
                          f"block of {region.size} bytes (nothing dropped)")
            self._send(b"B" + REGION.pack(region.offset, region.size) + region.name.encode())
        region.buf[region.offset:region.offset + len(data)] = data
        self._last = b"T" + TICK.pack(stamp, len(data))
        self.again()

    def again(self) -> None:
        """Wake the shard for the last tick again (a robot of it was late: duplicates are harmless,
        a controller answers a repeated tick with its same answer)."""
        if self._last is not None:
            self._send(self._last)
            self.sent += 1

    def settle(self, stopping: Callable[[], bool] = lambda: False) -> None:
        """Until the shard has finished every wake (it reads nothing of the region after)."""
        while self.done < self.sent:
            if self._poll(0.5):
                self._take()
            elif stopping():
                return

    def drain(self) -> None:
        """Take what the shard has said (readiness, done), without waiting."""
        while self._poll(0.0):
            self._take()

    def _poll(self, timeout: float) -> bool:
        try:
            return self.conn.poll(timeout)
        except OSError as exc:
            raise ShardDied(f"publish shard {self.k}: {exc}") from None

    def _send(self, data: bytes) -> None:
        try:
            self.conn.send_bytes(data)
        except OSError as exc:
            raise ShardDied(f"publish shard {self.k} is gone ({exc.strerror or exc})") from None

    def _take(self) -> None:
        try:
            msg = self.conn.recv_bytes()
        except (EOFError, OSError):
            raise ShardDied(f"publish shard {self.k} is gone") from None
        if msg[:1] == b"D":
            self.done += 1
        elif msg[:1] == b"R":
            self.ready = list(struct.unpack(f"<{(len(msg) - 1) // 4}I", msg[1:]))


class ShardReader:
    """The shard's end: publishes each tick's messages from its region (`serve`)."""

    def __init__(self, conn: Connection, region: Region, publishers: Sequence[Callable[[bytes], None]],
                 attach: Callable[[str], memoryview]) -> None:
        """`publishers`: one a message, in `frame`'s order; `attach(name)`: a block's memory."""
        self.conn, self.region, self.publishers, self._attach = conn, region, publishers, attach

    def serve(self) -> bool:
        """Handle one message from the world; False once the world has closed the socket."""
        try:
            msg = self.conn.recv_bytes()
        except (EOFError, OSError):
            return False
        kind = msg[:1]
        if kind == b"T":
            stamp, used = TICK.unpack_from(msg, 1)
            r = self.region
            messages = list(unframe(r.buf[r.offset:r.offset + used], used))
            if len(messages) != len(self.publishers):
                raise ValueError(f"tick {stamp}: {len(messages)} messages for {len(self.publishers)} publishers")
            for publish, data in zip(self.publishers, messages):
                publish(data)
            self.conn.send_bytes(b"D" + DONE.pack(stamp))
        elif kind == b"B":
            offset, size = REGION.unpack_from(msg, 1)
            name = msg[1 + REGION.size:].decode()
            self.region = Region(name, self._attach(name), offset, size)
        return True


def attach(name: str) -> memoryview:
    """A block the world made, mapped read-only: not through `SharedMemory`, whose resource tracker
    (Python < 3.13) would unlink the world's block when this process ends."""
    fd = os.open(f"/dev/shm/{name.lstrip('/')}", os.O_RDONLY)
    try:
        return memoryview(mmap.mmap(fd, 0, prot=mmap.PROT_READ))
    finally:
        os.close(fd)


def shard_environment(world: Mapping[str, str], shard: Mapping[str, str]) -> str:
    """`SHARD_ENV`'s value: what turns the world's environment into the shards'."""
    return json.dumps({"set": {k: v for k, v in shard.items() if world.get(k) != v},
                       "unset": sorted(set(world) - set(shard))})


class ShardEnvironmentError(ValueError):
    """The shards' DDS environment cannot be made from this process's (one line: the world refuses)."""


def _environment(environ: Mapping[str, str] | None = None) -> dict[str, str]:
    """The shards' environment: this process's as `SHARD_ENV` turns it into a client's. Without
    `SHARD_ENV` the shards take this process's own, which must then not be a discovery server's
    (a hand-started ``swarm-world --publish-shards`` whose profile makes it the server: its shards
    would try to be servers too)."""
    env = dict(os.environ if environ is None else environ)
    text = env.pop(SHARD_ENV, "")
    if not text:
        profile = env.get("FASTRTPS_DEFAULT_PROFILES_FILE") or env.get("FASTDDS_DEFAULT_PROFILES_FILE") or ""
        try:
            server = "<discoveryProtocol>SERVER</discoveryProtocol>" in open(profile).read() if profile else False
        except OSError:
            server = False
        if server:
            raise ShardEnvironmentError(f"--publish-shards: this world is a discovery server ({profile}) and "
                                        f"{SHARD_ENV} does not say how its shards join it (swarm-run sets it)")
        return env
    try:
        spec = json.loads(text)
        unset, assigned = list(spec["unset"]), dict(spec["set"])
        if not all(isinstance(k, str) for k in unset) or not all(isinstance(v, str) for v in assigned.values()):
            raise TypeError
    except (ValueError, KeyError, TypeError):
        raise ShardEnvironmentError(f'{SHARD_ENV}: expected JSON {{"set": {{NAME: VALUE}}, "unset": [NAME]}}, '
                                    f"got {text[:60]!r}") from None
    for key in unset:
        env.pop(key, None)
    return {**env, **assigned}


class PublishShards:
    """The world's K shard processes and their shared memory (`ShardWriter` each)."""

    def __init__(self, robots: Sequence[str], count: int, say: Callable[[str], None]) -> None:
        env = _environment()  # first: a refusal leaves no block behind
        self.robots = shard_robots(robots, count)
        size = REGION_BYTES_PER_ROBOT * len(self.robots[0])
        self._blocks = [SharedMemory(create=True, size=size * count)]
        first = self._blocks[0]
        self.writers: list[ShardWriter] = []
        self.procs: list[subprocess.Popen] = []
        for k, mine in enumerate(self.robots):
            here, there = Pipe()
            # a new interpreter (no fork of a process with DDS threads), dying with this one
            cmd = [sys.executable, "-m", __name__, "--shard", str(k), "--parent", str(os.getpid()),
                   "--fd", str(there.fileno()), "--block", first.name, "--offset", str(k * size),
                   "--size", str(size), "--robots", *mine]
            self.procs.append(subprocess.Popen(cmd, env=env, pass_fds=(there.fileno(),)))
            there.close()
            self.writers.append(ShardWriter(k, here, Region(first.name, first.buf, k * size, size),
                                            self._new_block, say))

    def _new_block(self, size: int) -> Region:
        block = SharedMemory(create=True, size=size)
        self._blocks.append(block)
        return Region(block.name, block.buf, 0, size)

    def publish(self, stamp: int, sent: Mapping[str, Mapping[str, bytes]],
                stopping: Callable[[], bool] = lambda: False) -> None:
        """Tick `stamp`: every robot's observations (`sent[robot][name]`) to its shard."""
        for writer, robots in zip(self.writers, self.robots):
            writer.publish(stamp, [sent[r][name] for r in robots for name in topics.OBSERVATIONS], stopping)

    def again(self, robots: Sequence[str]) -> None:
        """Wake the shards of `robots` again for the last tick."""
        for writer, mine in zip(self.writers, self.robots):
            if any(r in mine for r in robots):
                writer.again()

    def ready(self) -> set[str]:
        """The robots whose every observation publisher has a subscriber."""
        out: set[str] = set()
        for writer, mine in zip(self.writers, self.robots):
            writer.drain()
            out.update(mine[i] for i in writer.ready if i < len(mine))
        return out

    def close(self) -> None:
        """End the shards (their sockets close) and free the blocks."""
        for writer in self.writers:
            writer.conn.close()
        for block in self._blocks:
            try:
                block.unlink()
            except OSError:
                pass


# ------------------------------------------------------------------ the shard process

def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(prog="publish_shard", description=__doc__.splitlines()[0])
    parser.add_argument("--shard", type=int, required=True)
    parser.add_argument("--parent", type=int, required=True)
    parser.add_argument("--fd", type=int, required=True)
    parser.add_argument("--block", required=True)
    parser.add_argument("--offset", type=int, required=True)
    parser.add_argument("--size", type=int, required=True)
    parser.add_argument("--robots", nargs="+", required=True)
    args = parser.parse_args(argv)
    die_with_parent(args.parent)
    set_process_name(f"shard{args.shard}")
    signal.signal(signal.SIGINT, signal.SIG_IGN)  # the world ends it (its socket), after its last tick
    import rclpy

    from swarm_sim.nodes.qos import SENSOR_LOCKSTEP  # lazy: the edge's QoS imports rclpy, which the world side needs not

    rclpy.init(args=["publish_shard"])
    node = rclpy.create_node(shard_node_name(args.shard), start_parameter_services=False, enable_rosout=False)
    pubs = [[node.create_publisher(topics.import_type(topics.type_string(topic)), topic, SENSOR_LOCKSTEP)
             for topic in (topics.robot_topic(r, name) for name in topics.OBSERVATIONS)] for r in args.robots]
    conn = Connection(args.fd)
    reader = ShardReader(conn, Region(args.block, attach(args.block), args.offset, args.size),
                         [p.handle.publish_raw for per in pubs for p in per], attach)
    reported: list[int] | None = None
    started = False
    while True:
        if started or conn.poll(0.1):
            if not reader.serve():
                break
            started = True
            continue
        # until the first tick, tell the world which robots' publishers have matched (its start-up waits on them)
        ready = [i for i, per in enumerate(pubs) if all(p.get_subscription_count() for p in per)]
        if ready != reported:
            reported = ready
            conn.send_bytes(b"R" + struct.pack(f"<{len(ready)}I", *ready))
    leave(0)  # no teardown (`lifetime.leave`)


if __name__ == "__main__":
    main()

"""The world's publishing shards without processes or DDS (`swarm_sim.nodes.publish_shard`): what
the world writes into a shard's shared-memory region is what the shard publishes, in order, whole
even when a tick outgrows the region, and the world never writes a tick over one still being read."""

from __future__ import annotations

import json
from multiprocessing import Pipe

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from swarm_sim.nodes.publish_shard import (
    SHARD_ENV,
    Region,
    ShardEnvironmentError,
    ShardReader,
    ShardWriter,
    frame,
    shard_environment,
    shard_robots,
    unframe,
)

MESSAGES = st.lists(st.binary(max_size=300), min_size=1, max_size=12)


class Blocks:
    """Shared-memory blocks stood in by bytearrays, by name."""

    def __init__(self) -> None:
        self.by_name: dict[str, bytearray] = {}

    def new(self, size: int) -> Region:
        name = f"block{len(self.by_name)}"
        self.by_name[name] = bytearray(size)
        return Region(name, memoryview(self.by_name[name]), 0, size)

    def attach(self, name: str) -> memoryview:
        return memoryview(self.by_name[name])


def pair(count: int, region_bytes: int) -> tuple[ShardWriter, ShardReader, list[list[bytes]], list[str], Blocks]:
    """A writer and a reader of `count` publishers, joined by a socket pair, and what each
    publisher published and the writer said."""
    blocks = Blocks()
    first = blocks.new(region_bytes + 16)
    region = Region(first.name, first.buf, 16, region_bytes)  # not at the block's start, as shard k > 0
    here, there = Pipe()
    said: list[str] = []
    writer = ShardWriter(0, here, region, blocks.new, said.append)
    published: list[list[bytes]] = [[] for _ in range(count)]
    reader = ShardReader(there, region, [published[i].append for i in range(count)], blocks.attach)
    return writer, reader, published, said, blocks


@settings(max_examples=60, deadline=None)
@given(MESSAGES)
def test_framing_round_trips_messages_of_any_size_in_order(messages):
    data = frame(messages)
    assert list(unframe(memoryview(data), len(data))) == messages
    assert list(unframe(memoryview(data + b"\xff" * 7), len(data))) == messages  # the region's rest unread


@settings(max_examples=40, deadline=None)
@given(st.integers(1, 6).flatmap(lambda n: st.lists(st.lists(st.binary(max_size=200), min_size=n, max_size=n),
                                                   min_size=1, max_size=6)))
def test_every_tick_reaches_each_publisher_whole_even_past_the_region(ticks):
    count = len(ticks[0])
    writer, reader, published, said, _ = pair(count, region_bytes=64)
    for stamp, messages in enumerate(ticks):
        writer.publish(stamp, messages)
        while reader.conn.poll(0):  # the shard serves what it was sent (a move, then the tick)
            assert reader.serve()
        writer.settle()
        assert writer.done == writer.sent
        assert [p[-1] for p in published] == messages
    assert [len(p) for p in published] == [len(ticks)] * count
    grew = any(len(frame(m)) > 64 for m in ticks)
    assert len(said) == int(grew)  # said once, however often it grew


def test_a_tick_too_big_for_its_region_moves_to_a_new_block_and_loses_nothing():
    writer, reader, published, said, blocks = pair(3, region_bytes=32)
    small, big = [b"a", b"b", b"c"], [b"x" * 100, b"y" * 5, b"z" * 1000]
    writer.publish(0, small)
    assert reader.serve()
    writer.publish(1, big)
    assert reader.serve() and reader.serve()  # the move, then the tick
    writer.publish(2, small)  # back to small: the new block serves it
    assert reader.serve()
    assert published == [[b"a", b"x" * 100, b"a"], [b"b", b"y" * 5, b"b"], [b"c", b"z" * 1000, b"c"]]
    assert len(blocks.by_name) == 2 and reader.region.name == "block1" and reader.region.size >= 2 * 1107
    assert len(said) == 1 and "nothing dropped" in said[0]


def test_the_next_tick_waits_until_the_shard_has_read_the_last_one():
    writer, reader, published, _, _ = pair(1, region_bytes=64)
    writer.publish(0, [b"tick 0"])
    writer.again()  # a late robot: the same tick again, not yet read either
    waited = []
    writer.settle(stopping=lambda: waited.append(1) or True)  # the shard has read neither: no write
    assert waited and writer.done == 0
    writer.publish(1, [b"tick 1"], stopping=lambda: True)  # a stopping world writes nothing over it
    assert reader.serve() and reader.serve()
    assert published == [[b"tick 0", b"tick 0"]]
    writer.publish(1, [b"tick 1"])
    assert reader.serve() and published == [[b"tick 0", b"tick 0", b"tick 1"]]


def test_robots_are_dealt_round_robin_and_the_environment_turns_the_world_s_into_the_shards():
    assert shard_robots([f"r{i}" for i in range(5)], 2) == [["r0", "r2", "r4"], ["r1", "r3"]]
    spec = json.loads(shard_environment({"A": "1", "B": "server", "C": "x"}, {"A": "1", "B": "client", "D": "y"}))
    assert spec == {"set": {"B": "client", "D": "y"}, "unset": ["C"]}


def test_the_shards_environment_is_refused_in_one_line_when_it_cannot_be_made(tmp_path):
    """A hand-started world that is the discovery server, with no SHARD_ENV to make its shards
    clients, and a SHARD_ENV that is not the launcher's JSON: refused by name (the world prints the
    line and exits 2), not started with a server's environment or a traceback."""
    from swarm_sim.nodes.publish_shard import _environment

    server = tmp_path / "server.xml"
    server.write_text("<dds><discoveryProtocol>SERVER</discoveryProtocol></dds>")
    with pytest.raises(ShardEnvironmentError, match="discovery server"):
        _environment({"FASTRTPS_DEFAULT_PROFILES_FILE": str(server)})
    for bad in ("not json", '{"set": {}}', '{"set": {"A": 1}, "unset": []}', '[1, 2]'):
        with pytest.raises(ShardEnvironmentError, match=SHARD_ENV):
            _environment({SHARD_ENV: bad})
    client = tmp_path / "client.xml"
    client.write_text("<dds><discoveryProtocol>SIMPLE</discoveryProtocol></dds>")
    assert _environment({"FASTRTPS_DEFAULT_PROFILES_FILE": str(client), "X": "1"}) == {
        "FASTRTPS_DEFAULT_PROFILES_FILE": str(client), "X": "1"}
    spec = shard_environment({"A": "1", "B": "server"}, {"A": "1", "B": "client"})
    assert _environment({SHARD_ENV: spec, "A": "1", "B": "server"}) == {"A": "1", "B": "client"}

"""The run's credential (`swarm_msgs_py.auth`): tags on our own messages, checked where they arrive."""

from __future__ import annotations

import os

import pytest
from hypothesis import given
from hypothesis import strategies as st

from depot_manager.codec import DEPOT
from depot_manager.protocol import DepotGrant
from swarm_msgs_py import ack, auth, diagnostics
from swarm_sim.inbound import Inbound, Rejections

KEY = bytes(range(32))


@pytest.fixture
def keyed():
    auth.set_key(KEY)
    yield
    auth.set_key(None)


@given(st.text(st.characters(codec="utf-8", exclude_characters="\x00"), max_size=30), st.integers(0, 2**40))
def test_a_tagged_message_verifies_to_the_original_and_decodes_as_before(channel, stamp):
    auth.set_key(KEY)
    try:
        data = ack.encode_ack(channel, stamp)
        tagged = auth.sign(data)
        assert len(tagged) == len(data) + auth.TAG_CHARS
        assert auth.verify(tagged) == data == auth.strip(tagged)
        assert auth.verify(tagged + b"\x00\x00") is not None  # DDS pads payloads to 4 bytes between processes
        assert ack.decode_ack(auth.verify(tagged)) == (channel, stamp)
    finally:
        auth.set_key(None)


def test_untagged_forged_and_altered_messages_fail(keyed):
    (grants,) = DEPOT.encode(10, [DepotGrant(10, "robot_0", "entry_line_0", 2)])
    tagged = auth.sign(grants)
    assert DEPOT.decode(tagged) == DEPOT.decode(grants)  # decoders ignore the frame id
    assert auth.verify(grants) is None  # untagged
    auth.set_key(bytes(32))
    assert auth.verify(tagged) is None  # another run's key
    auth.set_key(KEY)
    altered = tagged.replace(b"entry_line_0", b"entry_line_1")
    assert auth.verify(altered) is None
    with pytest.raises(auth.Unauthenticated):
        auth.verified(DEPOT.decode)(grants)


def test_without_a_key_nothing_is_tagged_or_checked():
    data = diagnostics.encode_events(0, [])
    assert auth.key() is None and auth.sign(data) == data and auth.verify(data) == data


def test_a_node_counts_untagged_messages_and_replays_by_reason(keyed):
    gate = Inbound(("robot_0",), 10, Rejections(), lambda line: None)
    gate.now_ns = gate.released_ns = 10
    gate.unique = True
    posted = []
    (grants,) = DEPOT.encode(10, [DepotGrant(10, "robot_0", "entry_line_0", 2)])
    decode = auth.verified(DEPOT.decode)
    assert gate.post_all("/depot/grants", DEPOT, grants, posted.append, decode) == 0
    assert gate.post_all("/depot/grants", DEPOT, auth.sign(grants), posted.append, decode) == 1
    assert gate.post_all("/depot/grants", DEPOT, auth.sign(grants), posted.append, decode) == 0  # the same again
    gate.forget_before(100)
    assert gate.post_all("/depot/grants", DEPOT, auth.sign(grants), posted.append, decode) == 1
    assert gate.rejections.counts == {("/depot/grants", "unauthenticated"): 1, ("/depot/grants", "replayed"): 1}


def test_the_key_reaches_a_child_through_an_inherited_pipe_and_is_then_forgotten(monkeypatch):
    fd = auth.inheritable_key_pipe(KEY)
    monkeypatch.setenv(auth.ENV, str(fd))
    try:
        assert auth.load_from_environment() and auth.key() == KEY
        assert auth.ENV not in os.environ
        with pytest.raises(OSError):
            os.fstat(fd)  # closed once read
    finally:
        auth.set_key(None)

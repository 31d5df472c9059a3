"""Round trips of the inter-node protocol, the lockstep ack and the servers' state codecs,
checked against rclpy's deserializer so the bytes are real common_interfaces messages."""

from __future__ import annotations

import pytest
from diagnostic_msgs.msg import DiagnosticArray
from hypothesis import given
from hypothesis import strategies as st
from rclpy.serialization import deserialize_message
from std_msgs.msg import Header

from swarm_controllers.center import RegionState
from swarm_msgs_py import ack, protocol, server_state
from swarm_msgs_py.cdr import CodecError
from swarm_sim.protocol import (
    DepotGrant,
    DepotReport,
    ProgressReport,
    RadioQuery,
    RadioReply,
    RegionAssignment,
)

names = st.sampled_from(["robot_0", "robot_7", "robot_111"])
floats = st.floats(allow_nan=False, allow_infinity=False, width=64)
ints = st.integers(-(2**31), 2**31)
text = st.text(st.characters(codec="utf-8", exclude_characters="\x00"), max_size=20)
stamps = st.integers(0, 2**31 * 10**9 - 1)  # what builtin_interfaces/Time holds
messages = st.one_of(
    st.builds(ProgressReport, stamps, names, floats, floats, ints, floats, st.booleans()),
    st.builds(RegionAssignment, stamps, names, ints, st.sampled_from([1, -1]), floats, floats, st.booleans()),
    st.builds(DepotReport, stamps, names, st.sampled_from(["join", "at", "unloaded"]), text, ints),
    st.builds(DepotGrant, stamps, names, text, ints, st.booleans(), text),
    st.builds(RadioQuery, stamps, names, floats, floats),
    st.builds(RadioReply, stamps, names, names, floats, floats, text, ints, st.booleans()),
)


@given(st.lists(messages, max_size=6), stamps)
def test_protocol_messages_round_trip_exactly(batch, stamp):
    data = protocol.encode_messages(stamp, batch)
    assert protocol.decode_messages(data) == tuple(batch)
    msg = deserialize_message(data, DiagnosticArray)
    assert [s.name for s in msg.status] == [type(m).__name__ for m in batch]


def test_every_protocol_message_has_a_topic():
    for cls, topic in protocol.MESSAGE_TOPICS.items():
        assert topic.startswith("/"), cls
    with pytest.raises(TypeError, match="no topic"):
        protocol.topic_of(object())


def test_malformed_protocol_messages_are_named():
    from swarm_msgs_py.diagnostics import OK, encode_diagnostics

    unknown = encode_diagnostics(0, [(OK, "Teleport", "", "robot_0", ())])
    with pytest.raises(CodecError, match="Teleport"):
        protocol.decode_messages(unknown)
    missing = encode_diagnostics(0, [(OK, "RadioQuery", "", "robot_0", (("stamp_ns", "1"),))])
    with pytest.raises(CodecError, match="RadioQuery"):
        protocol.decode_messages(missing)
    bad_bool = protocol.encode_messages(0, [DepotGrant(1, "robot_0", "l", 2, True, "")]).replace(b"true", b"yes!")
    with pytest.raises(CodecError):
        protocol.decode_messages(bad_bool)
    with pytest.raises(CodecError):
        protocol.decode_messages(b"\x00\x01\x00\x00\x01")


@given(st.sampled_from(["center", "depot"]), stamps)
def test_ack_round_trip(channel, stamp):
    data = ack.encode_ack(channel, stamp)
    assert ack.decode_ack(data) == (channel, stamp)
    header = deserialize_message(data, Header)
    assert header.frame_id == channel
    assert header.stamp.sec * 10**9 + header.stamp.nanosec == stamp


def test_server_state_round_trip():
    regions = [
        RegionState(0, 12.5, (("robot_1", 1), ("robot_4", -1)), ((0.0, 3.25), (10.5, 12.5)), 7.25, False, 1.0),
        RegionState(1, 9.0, (), (), 9.0, True, float("-inf")),
    ]
    stamp, state = server_state.decode_state(server_state.encode_center_state(7, regions))
    assert stamp == 7
    assert state["region_0"] == {"length": "12.5", "remaining": "7.25", "finished": "false",
                                 "walkers": "robot_1:+1 robot_4:-1", "covered": "0.0-3.25 10.5-12.5"}
    assert state["region_1"]["finished"] == "true"

    data = server_state.encode_depot_state(
        9, (("entry_line_0", 3), ("entry_line_1", 0)), ("robot_2", ""), (), (("entry_line_0", 4, "robot_2"),)
    )
    deserialize_message(data, DiagnosticArray)
    stamp, state = server_state.decode_state(data)
    assert stamp == 9 and server_state.queue_lengths(state) == (3, 0)
    assert state["docks"] == {"dock_0": "robot_2", "dock_1": ""}
    assert state["slots"] == {"entry_line_0/4": "robot_2"}

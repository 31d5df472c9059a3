"""Round trips of the inter-node protocol, the lockstep ack and the servers' state codecs,
checked against rclpy's deserializer so the bytes are real common_interfaces messages."""

from __future__ import annotations

import pytest
from diagnostic_msgs.msg import DiagnosticArray
from hypothesis import given
from hypothesis import strategies as st
from rclpy.serialization import deserialize_message
from std_msgs.msg import Header

from depot_manager import state as depot_state
from depot_manager.codec import DEPOT, RADIO
from depot_manager.protocol import DepotGrant, DepotReport, RadioQuery, RadioReply, Refusal, ReportKind
from swarm_controllers.spiral import state as center_state
from swarm_controllers.spiral.center import RegionState
from swarm_controllers.spiral.codec import CENTER
from swarm_controllers.spiral.protocol import ProgressReport, RegionAssignment
from swarm_msgs_py import ack, server_state
from swarm_msgs_py.cdr import CodecError
from swarm_msgs_py.diagnostics import OK, encode_diagnostics
from swarm_msgs_py.records import topic_of

names = st.sampled_from(["robot_0", "robot_7", "robot_111"])
floats = st.floats(-1e9, 1e9, allow_nan=False, width=64)  # records.MAX_MAGNITUDE
ints = st.integers(-(2**31), 2**31)
text = st.text(st.characters(codec="utf-8", exclude_characters="\x00"), max_size=20)
stamps = st.integers(0, 2**31 * 10**9 - 1)  # what builtin_interfaces/Time holds
families = {
    CENTER: st.one_of(
        st.builds(ProgressReport, stamps, names, floats, floats, ints, floats, st.booleans()),
        st.builds(RegionAssignment, stamps, names, ints, st.sampled_from([1, -1]), floats, floats, st.booleans()),
    ),
    DEPOT: st.one_of(
        st.builds(DepotReport, stamps, names, st.sampled_from(ReportKind), text, ints),
        st.builds(DepotGrant, stamps, names, text, ints, st.booleans(), st.sampled_from(Refusal)),
    ),
    RADIO: st.one_of(
        st.builds(RadioQuery, stamps, names, floats, floats),
        st.builds(RadioReply, stamps, names, names, floats, floats, text, ints, st.booleans()),
    ),
}


@given(st.sampled_from(list(families)).flatmap(lambda f: st.tuples(st.just(f), st.lists(families[f], max_size=6))), stamps)
def test_protocol_messages_round_trip_exactly(family_and_batch, stamp):
    family, batch = family_and_batch
    (data,) = family.encode(stamp, batch)
    assert family.decode(data) == tuple(batch)
    msg = deserialize_message(data, DiagnosticArray)
    assert [s.name for s in msg.status] == [type(m).__name__ for m in batch]


def test_enums_travel_as_their_values():
    (data,) = DEPOT.encode(0, [DepotGrant(1, "robot_0", "entry_line_0", -1, False, Refusal.NOT_BEHIND_TAIL)])
    values = dict((v.key, v.value) for v in deserialize_message(data, DiagnosticArray).status[0].values)
    assert values["reason"] == "not behind the tail"
    (data,) = DEPOT.encode(0, [DepotReport(1, "robot_0", ReportKind.UNLOADED)])
    assert DEPOT.decode(data)[0].kind is ReportKind.UNLOADED


def test_every_protocol_message_has_a_topic():
    for family in (CENTER, DEPOT, RADIO):
        for cls, topic in family.topics.items():
            assert topic.startswith("/") and topic_of(family, cls.__new__(cls)) == topic
    with pytest.raises(TypeError, match="no topic"):
        topic_of(DEPOT, object())


def _grant_with(**changes) -> bytes:
    values = {"stamp_ns": "1", "robot": "robot_0", "line": "l", "cell": "2", "last": "true", "reason": ""}
    values.update(changes)
    pairs = tuple((k, v) for k, v in values.items() if v is not None)
    return encode_diagnostics(0, [(OK, "DepotGrant", "", "robot_0", pairs)])


@pytest.mark.parametrize("data, named", [
    (encode_diagnostics(0, [(OK, "Teleport", "", "robot_0", ())]), "Teleport"),
    (_grant_with(cell=None), "DepotGrant.cell: missing"),
    (_grant_with(colour="red"), "DepotGrant.colour: unknown field"),
    (_grant_with(cell="abc"), "DepotGrant.cell: expected a 64-bit integer"),
    (_grant_with(cell="1e3"), "DepotGrant.cell: expected a 64-bit integer"),
    (_grant_with(last="yes"), "DepotGrant.last: expected true/false"),
    (_grant_with(reason="too tired"), "DepotGrant.reason: 'too tired' is not one of"),
    (_grant_with(stamp_ns="9" * 60), "DepotGrant.stamp_ns: expected a 64-bit integer"),
    (_grant_with(stamp_ns="9" * 19), "DepotGrant.stamp_ns: expected a 64-bit integer"),
])
def test_malformed_protocol_messages_are_refused_naming_the_field(data, named):
    with pytest.raises(ValueError, match=named):
        DEPOT.decode(data)


def test_malformed_floats_and_bytes_are_refused():
    bad = encode_diagnostics(0, [(OK, "RadioQuery", "", "robot_0",
                                  (("stamp_ns", "1"), ("sender", "robot_0"), ("x", "nan"), ("y", "0.0")))])
    with pytest.raises(ValueError, match="RadioQuery.x: expected a finite number"):
        RADIO.decode(bad)
    huge = encode_diagnostics(0, [(OK, "RadioQuery", "", "robot_0", (
        ("stamp_ns", "1"), ("sender", "robot_0"), ("x", "1e308"), ("y", "0.0")))])
    with pytest.raises(ValueError, match="RadioQuery.x: expected a finite number within"):
        RADIO.decode(huge)  # squaring it raised OverflowError in the queue behaviour
    with pytest.raises(CodecError):
        DEPOT.decode(b"\x00\x01\x00\x00\x01")


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
    stamp, state = server_state.decode_state(center_state.encode_center_state(7, regions))
    assert stamp == 7
    assert state["region_0"] == {"length": "12.5", "remaining": "7.25", "finished": "false",
                                 "walkers": "robot_1:+1 robot_4:-1", "covered": "0.0-3.25 10.5-12.5"}
    assert state["region_1"]["finished"] == "true"

    depot = depot_state.DepotView(
        (("entry_line_0", 3), ("entry_line_1", 0)), ("robot_2", ""), (), (("entry_line_0", 4, "robot_2"),)
    )
    data = depot_state.encode_depot_state(9, depot)
    deserialize_message(data, DiagnosticArray)
    stamp, state = server_state.decode_state(data)
    assert stamp == 9 and depot_state.queue_lengths(state) == (3, 0)
    assert state["docks"] == {"dock_0": "robot_2", "dock_1": ""}
    assert state["slots"] == {"entry_line_0/4": "robot_2"}
    assert depot_state.decode_depot_state(data) == (9, depot)


def test_server_state_values_come_back_exactly():
    """What a server's state topic carries decodes to the very value its core gave (the series
    read from a bag equal the batch runner's), exponents and robot names with colons included."""
    regions = (
        center_state.RegionView(0, 12.5, 7.25, False, (("robot_1", 1), ("robot_4", -1)), ((0.0, 1e-05), (1e-07, 12.5))),
        center_state.RegionView(1, 1 / 3, 0.0, True, (), ((0.0, 1 / 3),)),
        center_state.RegionView(2, 2e20, 2e20, False, (("a:b", 1),), ()),
    )
    assert center_state.decode_center_state(center_state.encode_center_state(5, regions)) == (5, regions)
    depot = depot_state.DepotView((("entry/line", 2),), ("", "robot_9"), (1, 0), (("entry/line", 12, "robot_9"),))
    assert depot_state.decode_depot_state(depot_state.encode_depot_state(6, depot)) == (6, depot)
    for bad in (encode_diagnostics(0, [(OK, "region_0", "", "center", (("length", "1.0"),))]),
                encode_diagnostics(0, [(OK, "queues", "", "depot_manager", (("entry_line_0", "x"),))])):
        with pytest.raises(CodecError):
            center_state.decode_center_state(bad)
        with pytest.raises(CodecError):
            depot_state.decode_depot_state(bad)

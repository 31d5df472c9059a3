"""The sense message (`swarm_msgs_py.sensing`): every task's sense in one DiagnosticArray a robot
and tick. Any sense value comes back exactly (graph == batch rests on it); any other bytes either
decode or raise CodecError naming the type, never another exception. Wire compatibility with ROS's
serializer and rosbags: test_codecs.test_sense_wire."""

from __future__ import annotations

import struct

import pytest
from fuzz_helpers import fuzzed
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from swarm_controllers.caging.sensing import SENSING as CAGING
from swarm_controllers.caging.task import CagingSense
from swarm_controllers.drtm.sensing import SENSING as NEST
from swarm_controllers.drtm.task import NestSense
from swarm_msgs_py.cdr import CodecError, Writer
from swarm_msgs_py.diagnostics import OK, WARN, decode_diagnostics, encode_diagnostics
from swarm_msgs_py.sensing import TYPE_NAME, SenseField, Sensing, flag, vector, vectors
from swarm_sim import registry
from swarm_sim.world.tasks.foraging import ForagingSense
from swarm_sim.world.tasks.foraging_sensing import SENSING as FORAGING

STAMPS = st.integers(min_value=-(2**31) * 10**9, max_value=2**31 * 10**9 - 1)
FLOATS = st.floats(allow_nan=False)  # every float but NaN (which equals nothing), infinities and -0.0 included
XY = st.tuples(FLOATS, FLOATS)
TEXT = st.text(st.characters(blacklist_characters="\x00", blacklist_categories=("Cs",)), max_size=12)
"""Any UTF-8 text without NUL: the ids a caging sensor reports."""
SENSES = st.one_of(
    st.builds(lambda r, c: (FORAGING, ForagingSense(r, c)), st.lists(XY, max_size=5).map(tuple), st.booleans()),
    st.builds(lambda r, c, light: (NEST, NestSense(r, c, light)), st.lists(XY, max_size=5).map(tuple),
              st.booleans(), XY),
    st.builds(lambda p, b: (CAGING, CagingSense(p, b)), st.lists(TEXT, max_size=9).map(tuple),
              st.lists(st.tuples(TEXT, FLOATS, FLOATS), max_size=5).map(tuple)),
)
FAST = settings(max_examples=200, deadline=None, suppress_health_check=[HealthCheck.too_slow])


def _same(a, b) -> bool:
    """Equal, and -0.0 where the other has -0.0 (== alone takes 0.0 for -0.0)."""
    return repr(a) == repr(b) and a == b


@FAST
@given(STAMPS, SENSES)
def test_any_sense_comes_back_exactly(stamp, sensing_and_sense):
    sensing, sense = sensing_and_sense
    decoded = sensing.decode(sensing.encode(stamp, sense))
    assert decoded.stamp_ns == stamp and _same(decoded.sense, sense)
    assert type(decoded.sense) is type(sense)


def test_every_registered_task_declares_a_sense_message():
    """Each task's `Sensing` covers its sense type (the dummy plug-in's too): `Sensing` checks it."""
    tasks = {registry.task(a.task) for a in registry.algorithms()}
    senses = {registry.resolve(t.sensing).sense.__name__ for t in tasks}
    assert {"ForagingSense", "NestSense", "CagingSense", "BeaconSense"} <= senses


def test_what_ros2_topic_echo_shows():
    """One status per field, named after it, in the declared order; the values as text."""
    data = NEST.encode(10**9 + 7, NestSense(((1.25, -0.5),), True, (0.0, 0.75)))
    stamp, statuses = decode_diagnostics(data)
    assert stamp == 10**9 + 7
    assert [(s.level, s.name, s.message, s.hardware_id, s.values) for s in statuses] == [
        (OK, "resources", "", "", (("0", "1.25 -0.5"),)),
        (OK, "carrying", "", "", (("carrying", "true"),)),
        (OK, "light", "", "", (("light", "0.0 0.75"),)),
    ]


@FAST
@given(STAMPS, SENSES, st.sampled_from([OK, WARN]), TEXT, TEXT)
def test_another_writers_layout_decodes_the_same(stamp, sensing_and_sense, level, message, hardware_id):
    """A message written by another node (any level, message and hardware id; the general path,
    not the world's byte layout) gives the same sense."""
    sensing, sense = sensing_and_sense
    statuses = [(level, f.field, message, hardware_id, f.encode(getattr(sense, f.field))) for f in sensing.fields]
    decoded = sensing.decode(encode_diagnostics(stamp, statuses))
    assert decoded.stamp_ns == stamp and _same(decoded.sense, sense)


# --------------------------------------------------------------------------- untrusted bytes

VALID = [
    (FORAGING, FORAGING.encode(10**8, ForagingSense(((1.0, 2.0), (3.0, -4.0)), True))),
    (NEST, NEST.encode(10**8, NestSense((), False, (0.5, 0.5)))),
    (CAGING, CAGING.encode(10**8, CagingSense(("", "object", "robot_1"), (("robot_1", 0.1, 0.2),)))),
]


@pytest.mark.parametrize("sensing, data", VALID)
def test_truncated_messages_raise_codec_error_naming_the_type(sensing, data):
    sensing.decode(data)  # the full message is fine
    for n in range(len(data)):
        with pytest.raises(CodecError, match=f"^{TYPE_NAME} \\({sensing.sense.__name__}\\): "):
            sensing.decode(data[:n])


@pytest.mark.parametrize("sensing, data", VALID)
def test_corrupt_headers_raise_codec_error(sensing, data):
    with pytest.raises(CodecError, match="little-endian"):
        sensing.decode(b"\x00\x00\x00\x00" + data[4:])
    with pytest.raises(CodecError, match="nanosec"):
        sensing.decode(data[:8] + struct.pack("<I", 10**9) + data[12:])
    with pytest.raises(CodecError, match="frame_id"):
        sensing.decode(data[:12] + struct.pack("<I", 2**31) + data[16:])


def test_a_value_count_beyond_the_message_is_refused_before_any_value_is_read():
    w = Writer()
    w.header(5, "")
    w.u32(2)
    w.u8(OK)
    for text in ("resources", "", ""):
        w.string(text)
    w.u32(2**31)
    with pytest.raises(CodecError, match="resources: 2147483648 values overrun the 0 bytes left"):
        FORAGING.decode(w.message())


@settings(max_examples=400, deadline=None)
@given(st.sampled_from(range(len(VALID))), st.data())
def test_fuzzed_bytes_decode_or_raise_codec_error(which, data):
    """Any byte string either decodes or raises CodecError naming the type: never another exception."""
    sensing, valid = VALID[which]
    for candidate in fuzzed(valid, data, 96):
        try:
            decoded = sensing.decode(candidate)
        except CodecError as exc:
            assert str(exc).startswith(sensing.what)
        else:
            assert type(decoded.sense) is sensing.sense


def _statuses(*statuses):
    return encode_diagnostics(5, [(OK, name, "", "", values) for name, values in statuses])


@pytest.mark.parametrize("data, problem", [
    (_statuses(("resources", ())), "1 statuses, expected 2 (resources, carrying)"),
    (_statuses(("carrying", (("carrying", "true"),)), ("resources", ())), "status 'carrying' where 'resources'"),
    (_statuses(("resources", ()), ("carrying", (("carrying", "1"),))), "carrying: expected 'true' or 'false'"),
    (_statuses(("resources", ()), ("carrying", (("gripper", "true"),))), "expected one value 'carrying'"),
    (_statuses(("resources", ()), ("carrying", ())), "expected one value 'carrying'"),
    (_statuses(("resources", (("0", "1.0"),)), ("carrying", (("carrying", "true"),))), "resources[0]: expected 2"),
    (_statuses(("resources", (("0", "1.0 x"),)), ("carrying", (("carrying", "true"),))), "resources[0]: expected 2"),
    (_statuses(("resources", (("1", "1.0 2.0"),)), ("carrying", (("carrying", "true"),))), "key '1' where '0'"),
    (_statuses(("resources", (("0", "1.0 2.0 3.0"),)), ("carrying", (("carrying", "true"),))), "expected 2 numbers"),
])
def test_a_wrong_sense_is_refused_in_one_line_naming_the_problem(data, problem):
    with pytest.raises(CodecError) as err:
        FORAGING.decode(data)
    line = str(err.value)
    assert line.startswith(f"{TYPE_NAME} (ForagingSense): ") and problem in line and "\n" not in line


def test_caging_fields_refuse_what_they_cannot_read():
    bad_keys = encode_diagnostics(5, [(OK, "proximity", "", "", (("ir_1", ""),)), (OK, "bodies", "", "", ())])
    with pytest.raises(CodecError, match="not ir_0, ir_1"):
        CAGING.decode(bad_keys)
    bad_body = encode_diagnostics(5, [(OK, "proximity", "", "", ()), (OK, "bodies", "", "", (("object", "1.0"),))])
    with pytest.raises(CodecError, match="body 'object': expected 2 numbers"):
        CAGING.decode(bad_body)


def test_not_finite_numbers_decode_for_the_guard_to_count():
    """The codec gives NaN back; the controller's guard refuses it as out of bounds (test_inbound)."""
    data = _statuses(("resources", (("0", "nan 1.0"),)), ("carrying", (("carrying", "false"),)))
    (x, y), = FORAGING.decode(data).sense.resources
    assert x != x and y == 1.0


def test_what_cannot_travel_is_refused_on_encode():
    with pytest.raises(CodecError, match="NUL"):
        CAGING.encode(0, CagingSense(("a\x00b",), ()))
    with pytest.raises(CodecError, match="builtin_interfaces/Time"):
        FORAGING.encode(2**31 * 10**9, ForagingSense((), False))


def test_a_sensing_names_every_field_of_its_sense_once():
    with pytest.raises(ValueError, match=r"ForagingSense: fields \['resources'\], expected each of \['resources', 'carrying'\] once"):
        Sensing(ForagingSense, (vectors("resources", 2),))
    with pytest.raises(ValueError, match="once"):
        Sensing(ForagingSense, (vectors("resources", 2), flag("carrying"), flag("carrying")))
    with pytest.raises(ValueError, match="once"):
        Sensing(ForagingSense, (vectors("resources", 2), flag("carrying"), vector("light", 2)))
    order = Sensing(ForagingSense, (flag("carrying"), vectors("resources", 2)))  # any order: the message's
    sense = ForagingSense(((1.0, 2.0),), True)
    assert order.decode(order.encode(3, sense)) == (3, sense)
    assert decode_diagnostics(order.encode(3, sense)).statuses[0].name == "carrying"


def test_a_task_may_declare_a_field_codec_of_its_own():
    def decode(pairs):
        if pairs not in ((("carrying", "YES"),), (("carrying", "NO"),)):
            raise ValueError(f"carrying: {pairs[:1]!r}")
        return pairs[0][1] == "YES"

    own = Sensing(ForagingSense, (vectors("resources", 2),
                                  SenseField("carrying", lambda v: (("carrying", "YES" if v else "NO"),), decode)))
    assert own.decode(own.encode(1, ForagingSense((), True))) == (1, ForagingSense((), True))
    with pytest.raises(CodecError, match="carrying: "):
        own.decode(_statuses(("resources", ()), ("carrying", (("carrying", "MAYBE"),))))

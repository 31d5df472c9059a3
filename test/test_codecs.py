"""swarm_msgs_py codecs: our hand-written CDR against rclpy's serializer and rosbags' reader.

Wire check (`assert_wire`), for each codec and several values:
1. rclpy deserializes our bytes into exactly the equivalent message object;
2. our bytes equal ``serialize_message(msg)`` wherever Fast-CDR writes data: they differ only
   at padding, which Fast-CDR leaves uninitialised and we zero, and Fast-CDR may append a
   few bytes past the end (its size estimate for empty float64 sequences is too big);
3. our bytes are canonical: rosbags (an independent CDR implementation) re-serializes what
   it reads from them to the very same bytes, with no size mismatch.
"""

from __future__ import annotations

import math
import struct

import numpy as np
import pytest
from fuzz_helpers import fuzzed
from builtin_interfaces.msg import Time
from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus, KeyValue
from geometry_msgs.msg import Point, PointStamped, Quaternion, TwistStamped
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from nav_msgs.msg import Odometry
from rclpy.serialization import deserialize_message, serialize_message
from rosbags.typesys import Stores, get_typestore
from rosgraph_msgs.msg import Clock
from sensor_msgs.msg import LaserScan
from std_msgs.msg import Header
from visualization_msgs.msg import Marker, MarkerArray

from swarm_controllers.caging.sensing import SENSING as CAGING
from swarm_controllers.caging.task import CagingSense
from swarm_controllers.cpfa import codec as pheromone
from swarm_controllers.cpfa.messages import PheromoneMessage
from swarm_msgs_py import clock, diagnostics, odometry, scan, twist
from swarm_msgs_py import topics as topic_names
from swarm_msgs_py.cdr import CodecError, Reader, Writer
from swarm_msgs_py.diagnostics import Status
from swarm_msgs_py.geometry import wire_yaw, yaw_to_quaternion
from swarm_msgs_py.topics import all_topics, split_robot_topic, topic_type, type_of
from swarm_msgs_py.types import (
    BehaviourStatus,
    DropEvent,
    PickupEvent,
    Pose2D,
    RobotStats,
)
from swarm_sim.nodes.markers import encode_markers, encode_static_markers
from swarm_sim.scenario import (
    DropZoneConfig,
    ObstacleConfig,
    ScanConfig,
    Scenario,
)
from swarm_sim.world.tasks.foraging import ForagingSense
from swarm_sim.world.tasks.foraging_sensing import SENSING as FORAGING

TYPESTORE = get_typestore(Stores.ROS2_JAZZY)
ROBOTS = ["robot_0", "robot_7", "robot_42", "robot_111", "r"]
"""Name lengths chosen so frame strings end at every offset modulo 8."""

STAMPS = st.integers(min_value=-(2**31) * 10**9, max_value=2**31 * 10**9 - 1)
FINITE = st.floats(allow_nan=False, allow_infinity=False)
COORD = st.floats(min_value=-1e6, max_value=1e6, allow_nan=False)
TEXT = st.text(
    st.characters(blacklist_characters="\x00", blacklist_categories=("Cs",)), max_size=12
)  # any UTF-8 text without NUL
FAST = settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.too_slow])


def type_name(msg: object) -> str:
    package = type(msg).__module__.split(".")[0]
    return f"{package}/msg/{type(msg).__name__}"


def assert_wire(ours: bytes, msg: object) -> None:
    assert isinstance(ours, bytes)
    assert deserialize_message(ours, type(msg)) == msg
    theirs = bytes(serialize_message(msg))
    assert len(theirs) - 8 <= len(ours) <= len(theirs)
    differing = [i for i in range(len(ours)) if ours[i] != theirs[i]]
    assert all(ours[i] == 0 for i in differing), differing
    name = type_name(msg)
    assert bytes(TYPESTORE.serialize_cdr(TYPESTORE.deserialize_cdr(ours, name), name)) == ours


def stamp(ns: int) -> Time:
    return Time(sec=ns // 10**9, nanosec=ns % 10**9)


def header(ns: int, frame: str) -> Header:
    return Header(stamp=stamp(ns), frame_id=frame)


# --------------------------------------------------------------------------- clock


@pytest.mark.parametrize("ns", [0, 1, 999_999_999, 1_000_000_000, 123_456_789_012, -1])
def test_clock_wire(ns):
    assert_wire(clock.encode_clock(ns), Clock(clock=stamp(ns)))
    assert clock.decode_clock(serialize_message(Clock(clock=stamp(ns)))) == ns


@FAST
@given(STAMPS)
def test_clock_round_trip(ns):
    assert clock.decode_clock(clock.encode_clock(ns)) == ns


def test_stamp_out_of_range_is_refused():
    with pytest.raises(CodecError, match="rosgraph_msgs/msg/Clock"):
        clock.encode_clock(2**31 * 10**9)


# --------------------------------------------------------------------------- odometry


def odometry_msg(robot, ns, pose, v, w):
    msg = Odometry(header=header(ns, "world"), child_frame_id=f"{robot}/base_link")
    msg.pose.pose.position = Point(x=pose.x, y=pose.y, z=0.0)
    qx, qy, qz, qw = yaw_to_quaternion(pose.yaw)
    msg.pose.pose.orientation = Quaternion(x=qx, y=qy, z=qz, w=qw)
    msg.twist.twist.linear.x = v
    msg.twist.twist.angular.z = w
    return msg


@pytest.mark.parametrize("robot", ROBOTS)
@pytest.mark.parametrize("yaw", [0.0, 1.0, -2.5, math.pi, -math.pi, 7.0])
def test_odometry_wire(robot, yaw):
    pose = Pose2D(1.25, -3.5, yaw)
    msg = odometry_msg(robot, 1_700_000_000, pose, 0.16, -0.75)
    assert_wire(odometry.encode_odometry(robot, 1_700_000_000, pose, 0.16, -0.75), msg)
    decoded = odometry.decode_odometry(serialize_message(msg))
    assert decoded == (1_700_000_000, Pose2D(1.25, -3.5, wire_yaw(yaw)), 0.16, -0.75)
    assert -math.pi < decoded.pose.yaw <= math.pi


@FAST
@given(STAMPS, COORD, COORD, st.floats(-100, 100), FINITE, FINITE, st.sampled_from(ROBOTS))
def test_odometry_round_trip(ns, x, y, yaw, v, w, robot):
    data = odometry.encode_odometry(robot, ns, Pose2D(x, y, yaw), v, w)
    assert odometry.decode_odometry(data) == (ns, Pose2D(x, y, wire_yaw(yaw)), v, w)


def test_odometry_decodes_foreign_frames():
    """A decoder must not assume our frame names (bags from other tools)."""
    msg = odometry_msg("x", 5, Pose2D(0.5, 0.25, 0.3), 1.0, 2.0)
    msg.header.frame_id, msg.child_frame_id = "odom_frame_of_another_tool", ""
    assert odometry.decode_odometry(serialize_message(msg)).pose == Pose2D(0.5, 0.25, wire_yaw(0.3))


# --------------------------------------------------------------------------- scan

SCANS = [
    ScanConfig(),
    ScanConfig(rays=5, fov=math.pi, range_max=2.0, range_min=0.05),
    ScanConfig(rays=1, fov=1.0),
    ScanConfig(rays=360, fov=2 * math.pi, range_max=10.0),
]


def f32(x: float) -> float:
    """The value a float32 field holds after a trip over the wire."""
    return float(np.float32(x))


def scan_msg(robot, ns, ranges, cfg, angle_min, angle_max, increment):
    return LaserScan(
        header=header(ns, f"{robot}/base_link"),
        angle_min=f32(angle_min), angle_max=f32(angle_max), angle_increment=f32(increment),
        time_increment=0.0, scan_time=0.0, range_min=f32(cfg.range_min),
        range_max=f32(cfg.range_max), ranges=[float(r) for r in ranges], intensities=[],
    )  # fmt: skip


@pytest.mark.parametrize("cfg", SCANS)
@pytest.mark.parametrize("robot", ROBOTS[:3])
def test_scan_wire(cfg, robot):
    rng = np.random.default_rng(cfg.rays)
    ranges = rng.uniform(cfg.range_min, cfg.range_max, cfg.rays).astype(np.float32)
    ranges[::3] = np.inf
    full = cfg.fov >= 2 * math.pi - 1e-9
    increment = cfg.fov / cfg.rays if full or cfg.rays == 1 else cfg.fov / (cfg.rays - 1)
    angle_min = -cfg.fov / 2
    angle_max = angle_min + (cfg.rays - 1) * increment
    msg = scan_msg(robot, 300_000_000, ranges, cfg, angle_min, angle_max, increment)
    assert_wire(scan.encode_scan(robot, 300_000_000, ranges, cfg), msg)
    ns, decoded = scan.decode_scan(serialize_message(msg))
    assert ns == 300_000_000 and decoded.dtype == np.float32
    np.testing.assert_array_equal(decoded, ranges)
    if full:  # rays cover the circle without a duplicate at +-pi
        assert math.isclose(increment * cfg.rays, 2 * math.pi)
    elif cfg.rays > 1:  # the outer rays lie on the edges of the field of view
        assert math.isclose(angle_max, cfg.fov / 2)


@FAST
@given(
    STAMPS,
    st.lists(st.floats(min_value=0, max_value=1e30) | st.just(math.inf), min_size=24, max_size=24),
)
def test_scan_round_trip_rounds_to_float32(ns, values):
    ranges = np.array(values, dtype=np.float64)
    ns2, decoded = scan.decode_scan(scan.encode_scan("robot_1", ns, ranges, ScanConfig()))
    assert ns2 == ns
    np.testing.assert_array_equal(decoded, ranges.astype(np.float32))
    decoded[0] = 1.0  # a fresh, writable array, not a view into the message


def test_scan_refuses_wrong_ray_count():
    with pytest.raises(CodecError, match="sensor_msgs/msg/LaserScan"):
        scan.encode_scan("robot_0", 0, np.ones(23, np.float32), ScanConfig())


def test_scan_decodes_intensities():
    msg = LaserScan(header=header(7, "laser"), ranges=[1.0, 2.0], intensities=[5.0, 6.0])
    ns, ranges = scan.decode_scan(serialize_message(msg))
    assert ns == 7 and ranges.tolist() == [1.0, 2.0]


# --------------------------------------------------------------------------- sense


def sense_msg(ns, statuses):
    return DiagnosticArray(header=header(ns, ""), status=[
        DiagnosticStatus(level=DiagnosticStatus.OK, name=name, values=[KeyValue(key=k, value=v) for k, v in values])
        for name, values in statuses])


@pytest.mark.parametrize("sense, statuses", [
    (ForagingSense((), False), [("resources", []), ("carrying", [("carrying", "false")])]),
    (ForagingSense(((0.1, -0.2), (3.0, 4.5)), True),
     [("resources", [("0", "0.1 -0.2"), ("1", "3.0 4.5")]), ("carrying", [("carrying", "true")])]),
    (CagingSense(("", "object", "robot_3"), (("object", 1.5, -0.25),)),
     [("proximity", [("ir_0", ""), ("ir_1", "object"), ("ir_2", "robot_3")]), ("bodies", [("object", "1.5 -0.25")])]),
])
def test_sense_wire(sense, statuses):
    """The sense message is a DiagnosticArray `ros2 topic echo` shows field by field; both our
    decoder's paths (the world's bytes, rclpy's) read it."""
    sensing = FORAGING if isinstance(sense, ForagingSense) else CAGING
    msg = sense_msg(42, statuses)
    assert_wire(sensing.encode(42, sense), msg)
    assert sensing.decode(serialize_message(msg)) == (42, sense)


# --------------------------------------------------------------------------- twist


@pytest.mark.parametrize("robot", ROBOTS)
def test_twist_wire(robot):
    msg = TwistStamped(header=header(2_000_000_000, f"{robot}/base_link"))
    msg.twist.linear.x, msg.twist.angular.z = 0.12, -1.5
    assert_wire(twist.encode_twist(robot, 2_000_000_000, 0.12, -1.5), msg)
    assert twist.decode_twist(serialize_message(msg)) == (2_000_000_000, 0.12, -1.5)


def test_twist_decode_passes_nan_and_inf_through():
    msg = TwistStamped(header=header(5, "robot_1/base_link"))
    msg.twist.linear.x, msg.twist.angular.z = math.nan, -math.inf
    ns, linear, angular = twist.decode_twist(serialize_message(msg))
    assert ns == 5 and math.isnan(linear) and angular == -math.inf


@FAST
@given(STAMPS, st.floats(), st.floats(), st.sampled_from(ROBOTS))
def test_twist_round_trip_is_bit_exact(ns, linear, angular, robot):
    got = twist.decode_twist(twist.encode_twist(robot, ns, linear, angular))
    assert got.stamp_ns == ns
    assert struct.pack("<dd", got.linear, got.angular) == struct.pack("<dd", linear, angular)


# --------------------------------------------------------------------------- pheromone


def test_pheromone_wire():
    msg = PointStamped(header=header(3_500_000_000, "world"), point=Point(x=-2.0, y=4.25, z=0.0))
    m = PheromoneMessage(3_500_000_000, -2.0, 4.25)
    assert_wire(pheromone.encode_pheromone(m), msg)
    assert pheromone.decode_pheromone(serialize_message(msg)) == m


@FAST
@given(st.builds(PheromoneMessage, STAMPS, FINITE, FINITE))
def test_pheromone_round_trip(m):
    assert pheromone.decode_pheromone(pheromone.encode_pheromone(m)) == m


# --------------------------------------------------------------------------- diagnostics


def diagnostics_msg(ns, statuses):
    return DiagnosticArray(
        header=header(ns, ""),
        status=[
            DiagnosticStatus(
                level=bytes([level]), name=name, message=message, hardware_id=hw,
                values=[KeyValue(key=k, value=v) for k, v in values],
            )  # fmt: skip
            for level, name, message, hw, values in statuses
        ],
    )


STATUSES = [
    [],
    [Status(0, "", "", "", ())],
    [
        Status(2, "a", "héllo", "hw", (("k", "v"), ("key2", ""))),
        Status(1, "robot_3", "searching", "robot_3", ()),
        Status(3, "abc", "", "x" * 13, (("ü", "ø" * 3),)),
    ],
]


@pytest.mark.parametrize("statuses", STATUSES)
def test_diagnostics_wire(statuses):
    msg = diagnostics_msg(77, statuses)
    assert_wire(diagnostics.encode_diagnostics(77, statuses), msg)
    assert diagnostics.decode_diagnostics(serialize_message(msg)) == (77, tuple(statuses))


STATUS_ST = st.builds(
    Status,
    st.integers(0, 255), TEXT, TEXT, TEXT,
    st.lists(st.tuples(TEXT, TEXT), max_size=3).map(tuple),
)  # fmt: skip


@FAST
@given(STAMPS, st.lists(STATUS_ST, max_size=4))
def test_diagnostics_round_trip(ns, statuses):
    data = diagnostics.encode_diagnostics(ns, statuses)
    assert diagnostics.decode_diagnostics(data) == (ns, tuple(statuses))


def test_diagnostics_refuse_unencodable_values():
    with pytest.raises(CodecError, match="DiagnosticArray"):
        diagnostics.encode_diagnostics(0, [Status(256, "a")])
    with pytest.raises(CodecError, match="DiagnosticArray.*NUL"):
        diagnostics.encode_diagnostics(0, [Status(0, "a\x00b")])


FLOATS_EXACT = FINITE  # repr() round-trips every finite float; events refuse the others
EVENT_STAMPS = st.integers(min_value=0, max_value=2**63 - 1)  # sim time: never negative
EVENT_ST = st.one_of(
    st.builds(PickupEvent, st.sampled_from(ROBOTS), EVENT_STAMPS, st.integers(0, 10**6), FLOATS_EXACT,
              FLOATS_EXACT),
    st.builds(DropEvent, st.sampled_from(ROBOTS), EVENT_STAMPS, st.integers(0, 10**6),
              st.sampled_from(["depot", "dock_1", "région"]), FLOATS_EXACT, FLOATS_EXACT),
)  # fmt: skip


def test_events_mapping():
    events = [
        PickupEvent("robot_2", 100, 17, 0.1, -2.3),
        DropEvent("robot_5", 100, 4, "depot", 0.2, 1 / 3),
    ]
    data = diagnostics.encode_events(100, events)
    msg = deserialize_message(data, DiagnosticArray)
    assert [s.name for s in msg.status] == ["pickup", "drop"]
    assert [s.hardware_id for s in msg.status] == ["robot_2", "robot_5"]
    drop = {kv.key: kv.value for kv in msg.status[1].values}
    assert drop == {
        "resource": "4", "zone": "depot", "x": "0.2", "y": repr(1 / 3), "stamp_ns": "100"
    }
    assert diagnostics.decode_events(serialize_message(msg)) == (100, tuple(events))


@FAST
@given(STAMPS, st.lists(EVENT_ST, max_size=5))
def test_events_round_trip(ns, events):
    assert diagnostics.decode_events(diagnostics.encode_events(ns, events)) == (ns, tuple(events))


def test_events_numpy_scalars_travel_as_plain_numbers():
    event = PickupEvent("robot_1", 0, np.int64(3), np.float64(0.5), np.float32(0.25))
    _, (back,) = diagnostics.decode_events(diagnostics.encode_events(0, [event]))
    assert back == PickupEvent("robot_1", 0, 3, 0.5, 0.25)


def test_events_refuse_numbers_no_run_can_hold():
    for key, value in (("x", "inf"), ("x", "nan"), ("stamp_ns", "-1"), ("resource", "1" * 40), ("stamp_ns", "1e39")):
        values = dict((("resource", "1"), ("x", "0.5"), ("y", "0.5"), ("stamp_ns", "0")), **{key: value})
        data = diagnostics.encode_diagnostics(0, [Status(0, "pickup", "", "robot_1", tuple(values.items()))])
        with pytest.raises(CodecError, match=key):
            diagnostics.decode_events(data)


def test_events_refuse_unknown_status():
    data = diagnostics.encode_diagnostics(0, [Status(0, "teleport", "", "robot_1", ())])
    with pytest.raises(CodecError, match="DiagnosticArray.*teleport"):
        diagnostics.decode_events(data)
    data = diagnostics.encode_diagnostics(0, [Status(0, "pickup", "", "robot_1", (("x", "1"),))])
    with pytest.raises(CodecError, match="DiagnosticArray.*keys"):
        diagnostics.decode_events(data)


STATS_ST = st.builds(
    RobotStats, st.floats(min_value=0, allow_nan=False, allow_infinity=False), *[st.integers(0, 10**9)] * 4,
    st.floats(min_value=0, allow_nan=False, allow_infinity=False),
)


@FAST
@given(STAMPS, st.dictionaries(st.sampled_from(ROBOTS), STATS_ST, max_size=5))
def test_robot_stats_round_trip(ns, stats):
    got_ns, got = diagnostics.decode_robot_stats(diagnostics.encode_robot_stats(ns, stats))
    assert got_ns == ns and got == stats and list(got) == list(stats)


def test_robot_stats_mapping():
    data = diagnostics.encode_robot_stats(5, {"robot_0": RobotStats(1.5, 2, 1, 0, 3, 4.25)})
    (status,) = deserialize_message(data, DiagnosticArray).status
    assert status.name == "robot_0"
    assert [(kv.key, kv.value) for kv in status.values] == [
        ("collision_time_s", "1.5"), ("pickups", "2"), ("deliveries", "1"),
        ("clamped_commands", "0"), ("stale_ticks", "3"), ("avoidance_time_s", "4.25"),
    ]  # fmt: skip


def test_robot_stats_of_a_bag_recorded_before_avoidance_time_decode():
    from swarm_msgs_py.diagnostics import OK, Status, encode_diagnostics

    old = encode_diagnostics(5, [Status(OK, "robot_0", "", "robot_0", (
        ("collision_time_s", "1.5"), ("pickups", "2"), ("deliveries", "1"),
        ("clamped_commands", "0"), ("stale_ticks", "3")))])
    assert diagnostics.decode_robot_stats(old) == (5, {"robot_0": RobotStats(1.5, 2, 1, 0, 3, 0.0)})


BEHAVIOUR_ST = st.builds(
    BehaviourStatus,
    st.sampled_from(ROBOTS), STAMPS, TEXT, st.integers(0, 10**9), st.integers(0, 10**9),
    st.lists(st.tuples(TEXT, TEXT), max_size=3).map(tuple), st.booleans(),
)  # fmt: skip


@FAST
@given(BEHAVIOUR_ST)
def test_behaviour_status_round_trip(status):
    assert diagnostics.decode_status(diagnostics.encode_status(status)) == status


def test_behaviour_status_mapping():
    status = BehaviourStatus("robot_9", 10, "returning", 4, 2, (("site", "1.0,2.0"),))
    msg = deserialize_message(diagnostics.encode_status(status), DiagnosticArray)
    (s,) = msg.status
    assert (s.name, s.message, s.hardware_id) == ("robot_9", "returning", "robot_9")
    assert [kv.key for kv in s.values] == ["state", "obstacle_avoidance_events", "trips", "site"]
    assert diagnostics.decode_status(serialize_message(msg)) == status
    done = BehaviourStatus("robot_9", 10, "done", 4, 2, (("site", "1.0,2.0"),), finished=True)
    (s,) = deserialize_message(diagnostics.encode_status(done), DiagnosticArray).status
    assert [(kv.key, kv.value) for kv in s.values][3] == ("finished", "true")  # what `ros2 topic echo` shows
    assert diagnostics.decode_status(diagnostics.encode_status(done)) == done


# --------------------------------------------------------------------------- malformed input

VALID = {
    "rosgraph_msgs/msg/Clock": (clock.decode_clock, clock.encode_clock(12)),
    "nav_msgs/msg/Odometry": (
        odometry.decode_odometry,
        odometry.encode_odometry("robot_1", 1, Pose2D(1, 2, 3), 4, 5),
    ),
    "sensor_msgs/msg/LaserScan": (
        scan.decode_scan,
        scan.encode_scan("robot_1", 1, np.ones(24), ScanConfig()),
    ),
    "geometry_msgs/msg/TwistStamped": (twist.decode_twist, twist.encode_twist("robot_1", 1, 1, 2)),
    "geometry_msgs/msg/PointStamped": (
        pheromone.decode_pheromone,
        pheromone.encode_pheromone(PheromoneMessage(1, 2.0, 3.0)),
    ),
    "diagnostic_msgs/msg/DiagnosticArray": (
        diagnostics.decode_status,
        diagnostics.encode_status(BehaviourStatus("robot_1", 1, "search", 1, 2)),
    ),
}


@pytest.mark.parametrize("type_name", VALID)
def test_truncated_messages_raise_codec_error_naming_the_type(type_name):
    decode, data = VALID[type_name]
    decode(data)  # the full message is fine
    for n in range(len(data)):
        with pytest.raises(CodecError, match=type_name):
            decode(data[:n])


@pytest.mark.parametrize("type_name", VALID)
def test_corrupt_headers_raise_codec_error(type_name):
    decode, data = VALID[type_name]
    with pytest.raises(CodecError, match=f"{type_name}.*little-endian"):
        decode(b"\x00\x00\x00\x00" + data[4:])  # big-endian CDR
    bad_nanosec = data[:8] + struct.pack("<I", 10**9) + data[12:]
    with pytest.raises(CodecError, match=f"{type_name}.*nanosec"):
        decode(bad_nanosec)
    if type_name != "rosgraph_msgs/msg/Clock":  # frame_id length runs off the end
        with pytest.raises(CodecError, match=type_name):
            decode(data[:12] + struct.pack("<I", 2**31) + data[16:])


@settings(max_examples=300, deadline=None)
@given(st.sampled_from(sorted(VALID)), st.data())
def test_fuzzed_bytes_decode_or_raise_codec_error(type_name, data):
    """Any byte string either decodes or raises CodecError: never another exception."""
    decode, valid = VALID[type_name]
    for candidate in fuzzed(valid, data, 64):
        try:
            decode(candidate)
        except CodecError as exc:
            assert type_name in str(exc)


def test_strings_must_be_nul_terminated():
    data = bytearray(twist.encode_twist("robot_1", 1, 1.0, 2.0))
    data[16 + len("robot_1/base_link")] = ord("x")  # overwrite the NUL
    with pytest.raises(CodecError, match="TwistStamped.*NUL"):
        twist.decode_twist(bytes(data))


# --------------------------------------------------------------------------- cdr primitives


def test_writer_reader_alignment_counts_from_after_the_encapsulation():
    w = Writer()
    w.u8(7)
    w.f64(1.5)
    w.string("ab")
    w.f32_array(np.array([1.0, 2.0]))
    w.f64_array([3.0])
    data = w.message()
    assert data[:4] == b"\x00\x01\x00\x00"
    assert data[4 + 8 : 4 + 16] == struct.pack("<d", 1.5)  # 7 bytes of padding after the u8
    r = Reader(data)
    assert r.u8() == 7 and r.f64() == 1.5 and r.string() == "ab"
    assert r.f32_array().tolist() == [1.0, 2.0] and r.f64_array().tolist() == [3.0]
    assert r.pos == len(data)


# --------------------------------------------------------------------------- markers


def test_markers_deserialize_with_expected_counts():
    scenario = Scenario(
        drop_zones=(DropZoneConfig("dock_a", (3.0, 3.0), 0.4),),
        obstacles=(
            ObstacleConfig("box", (-2.0, 2.0), (0.5, 1.0), 0.3),
            ObstacleConfig("cylinder", (2.0, -2.0), (0.6, 0.6)),
        ),
    )
    static = deserialize_message(encode_static_markers(scenario), MarkerArray)
    assert [m.type for m in static.markers] == [
        Marker.LINE_STRIP, Marker.CYLINDER, Marker.CYLINDER, Marker.CUBE, Marker.CYLINDER,
    ]  # fmt: skip
    assert len(static.markers[0].points) == 5  # a closed square

    res = np.array([[1.0, 1.0], [2.0, 2.0], [3.0, 1.0]])
    poses = np.array([[0.0, 0.0, 0.0], [0.5, 0.0, 1.0]])
    world = deserialize_message(
        encode_markers(scenario, 10**9 + 5, {"resources": res}, poses, np.array([False, True])), MarkerArray
    )
    assert len(world.markers) == 5 + 1 + 2
    spheres = [m for m in world.markers if m.type == Marker.SPHERE_LIST]
    assert len(spheres) == 1 and [[p.x, p.y] for p in spheres[0].points] == res.tolist()
    robots = [m for m in world.markers if m.ns == "robots"]
    assert [m.id for m in robots] == [0, 1] and robots[0].color != robots[1].color
    assert all(m.header.frame_id == "world" for m in world.markers)
    assert (world.markers[0].header.stamp.sec, world.markers[0].header.stamp.nanosec) == (1, 5)
    # the world hands its true poses as {robot: Pose2D}: marker ids are the robot indices
    by_name = {"robot_4": Pose2D(1.0, 2.0, 0.5), "robot_2": Pose2D(-1.0, 0.0, 0.0)}
    world = deserialize_message(encode_markers(scenario, 0, {"resources": res[:0]}, by_name), MarkerArray)
    robots = [m for m in world.markers if m.ns == "robots"]
    assert [(m.id, m.pose.position.x) for m in robots] == [(4, 1.0), (2, -1.0)]
    assert len(world.markers) == 5 + 1 + 2


# --------------------------------------------------------------------------- topics


def test_topic_types():
    assert topic_type("/robot_3/odom") == "nav_msgs/msg/Odometry"
    assert topic_type("/clock") == "rosgraph_msgs/msg/Clock"
    assert split_robot_topic("/robot_3/cmd_vel") == ("robot_3", "cmd_vel")
    assert split_robot_topic("/world/events") is None
    with pytest.raises(ValueError, match="/robot_3/unknown"):
        topic_type("/robot_3/unknown")
    topics = all_topics(["robot_0", "robot_1"])
    assert topics["/robot_1/scan"] == "sensor_msgs/msg/LaserScan"
    for topic, name in topics.items():  # every type exists in stock Jazzy and imports
        assert name in TYPESTORE.types
        assert topic_names.type_name(type_of(topic)) == name
    assert type_of("cmd_vel") is TwistStamped and type_of("/world/events") is DiagnosticArray

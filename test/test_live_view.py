"""The live view (`swarm-run --foxglove`): a plain WebSocket client (the `websockets` package, no
Foxglove code) speaks the Foxglove protocol to a real run, subscribes to a few channels and decodes
what arrives with our codecs and rosbags: odometry, scans, markers (the center's, latched before
the client came), the sim clock; the server listens on 127.0.0.1 only. The client offers only the
classic subprotocol name (Foxglove Studio <= 1.87, Lichtblick before Dec 2025), which foxglove-sdk
alone refuses. The run is lockstep, which ``--foxglove`` paces at 1x real time so it can be
watched (and lasts long enough here); it is stopped with Ctrl-C once the client has seen enough.
Without a run: a client offering either name gets the clock and odometry, a busy port stops
``swarm-run`` before any node starts."""

from __future__ import annotations

import json
import os
import re
import signal
import socket
import struct
import subprocess
import sys
import threading
import time
from pathlib import Path

import psutil
import pytest
import yaml
from rosbags.typesys import Stores, get_typestore
from websockets.sync.client import connect

from swarm_msgs_py import clock as clock_codec
from swarm_msgs_py import odometry, scan
from swarm_msgs_py.types import Pose2D
from swarm_sim.nodes.live_view import LiveView
from swarm_sim.nodes.ws_proxy import CLASSIC, SDK, check_port
from swarm_sim.recording import read_bag
from swarm_sim.recording.metadata import _msgdef

WANTED = ("/clock", "/robot_0/odom", "/robot_1/scan", "/world/markers", "/center/markers")
MESSAGE_DATA, TIME = 1, 2
"""Binary opcodes of the Foxglove WebSocket protocol (server -> client)."""


def _start_run(bag: Path) -> subprocess.Popen:
    cmd = [sys.executable, "-m", "launch_py.run", "--bag", str(bag), "--scenario", "mdbsa_d", "--robots", "2",
           "--duration", "300", "--foxglove", "0",
           "--domain-id", os.environ["ROS_DOMAIN_ID"]]
    return subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
                            cwd=Path(__file__).resolve().parents[1], start_new_session=True)


def _url(proc: subprocess.Popen, deadline: float) -> tuple[str, list[str]]:
    """The live view's address, and the lines printed up to it."""
    seen = []
    while time.monotonic() < deadline:
        line = proc.stdout.readline()
        seen.append(line)
        if match := re.search(r"live view: (ws://\S+)", line):
            return match.group(1), seen
        if not line and proc.poll() is not None:
            break
    raise AssertionError("no live view line:\n" + "".join(seen))


def test_a_websocket_client_subscribes_and_decodes_the_live_run(tmp_path):
    proc = _start_run(tmp_path / "bag")
    try:
        url, before = _url(proc, time.monotonic() + 60)
        assert url.startswith("ws://127.0.0.1:")
        listening = {c.laddr.ip for p in psutil.Process(proc.pid).children(recursive=True)
                     for c in p.net_connections(kind="inet") if c.status == psutil.CONN_LISTEN}
        assert listening == {"127.0.0.1"}, listening
        channels, got, clock, walls = {}, {}, [], []
        with connect(url, subprotocols=[CLASSIC], open_timeout=20, max_size=None) as ws:
            assert ws.subprotocol == CLASSIC
            deadline = time.monotonic() + 40
            subscribed = {}
            while time.monotonic() < deadline and (len(subscribed) < len(WANTED) or len(got) < len(WANTED)):
                frame = ws.recv(timeout=5)
                if isinstance(frame, str):
                    op = json.loads(frame)
                    if op["op"] == "advertise":
                        channels.update({c["id"]: c for c in op["channels"]})
                        new = [c for c in op["channels"] if c["topic"] in WANTED and c["topic"] not in subscribed.values()]
                        for c in new:
                            subscribed[len(subscribed) + 1] = c["topic"]
                            ws.send(json.dumps({"op": "subscribe", "subscriptions": [
                                {"id": len(subscribed), "channelId": c["id"]}]}))
                elif frame[0] == MESSAGE_DATA:
                    sub, stamp = struct.unpack_from("<IQ", frame, 1)
                    got.setdefault(subscribed[sub], []).append((stamp, bytes(frame[13:])))
                elif frame[0] == TIME:
                    clock.append(struct.unpack_from("<Q", frame, 1)[0])
                    walls.append(time.monotonic())
    finally:
        proc.send_signal(signal.SIGINT)  # seen enough: Ctrl-C, which leaves a valid bag
        out, _ = proc.communicate(timeout=120)
    assert set(got) == set(WANTED), ({t: len(v) for t, v in got.items()}, len(clock), "".join(before) + out[-3000:])
    assert proc.returncode == 130, out[-3000:]
    # start-up progress: what the launcher started, then what the world waits for
    printed = "".join(before) + out
    assert "[swarm-run] started the world and 2 controller/server process(es)" in printed
    assert "[swarm-run] --foxglove in lockstep: paced at 1x real time" in printed
    assert (clock[-1] - clock[0]) / 1e9 <= 1.2 * (walls[-1] - walls[0]) + 0.5  # paced at 1x
    assert re.search(r"\[world\] up \([\d.]+ s after its imports .* of 2 robots\); waiting for the controllers "
                     r"and servers to connect", printed)
    assert re.search(r"\[world\] 2/2 controllers connected after [\d.]+ s: starting", printed)

    by_topic = {c["topic"]: c for c in channels.values()}
    odom = by_topic["/robot_0/odom"]
    assert (odom["encoding"], odom["schemaEncoding"], odom["schemaName"]) == ("cdr", "ros2msg", "nav_msgs/msg/Odometry")
    assert odom["schema"] == _msgdef("nav_msgs/msg/Odometry")  # the bag's definition
    stamp, pose, _, _ = odometry.decode_odometry(got["/robot_0/odom"][-1][1])
    assert stamp == got["/robot_0/odom"][-1][0] and abs(pose.x) < 5 and abs(pose.y) < 5
    assert len(scan.decode_scan(got["/robot_1/scan"][0][1])[1]) > 0
    store = get_typestore(Stores.ROS2_JAZZY)
    regions = store.deserialize_cdr(got["/center/markers"][0][1], "visualization_msgs/msg/MarkerArray")
    assert {m.ns for m in regions.markers} == {"regions", "planned_paths"}  # latched: sent on subscribe
    world = store.deserialize_cdr(got["/world/markers"][0][1], "visualization_msgs/msg/MarkerArray")
    assert "robots" in {m.ns for m in world.markers}
    assert clock == sorted(clock) and clock[-1] > clock[0]
    # the same bytes went to the bag
    recorded = {m.data for m in read_bag(tmp_path / "bag") if m.topic == "/robot_0/odom"}
    assert all(data in recorded for _, data in got["/robot_0/odom"])
    # and its metadata.yaml has each topic's offered QoS and type hash, as `ros2 bag record` writes them
    meta = yaml.safe_load((tmp_path / "bag" / "metadata.yaml").read_text())["rosbag2_bagfile_information"]
    recorded_topics = {t["topic_metadata"]["name"]: t["topic_metadata"] for t in meta["topics_with_message_count"]}
    for topic, reliability, durability, depth in (
            ("/robot_0/odom", "best_effort", "volatile", 10), ("/robot_1/cmd_vel", "best_effort", "volatile", 10),
            ("/robot_0/status", "reliable", "volatile", 1000), ("/center/markers", "reliable", "transient_local", 1),
            ("/center/reports", "reliable", "volatile", 1000), ("/clock", "best_effort", "volatile", 10)):
        t = recorded_topics[topic]
        (profile,) = t["offered_qos_profiles"]
        assert (profile["reliability"], profile["durability"], profile["depth"], profile["history"]) == (
            reliability, durability, depth, "keep_last"), topic
        assert profile["deadline"] == {"sec": 9223372036, "nsec": 854775807}
        assert t["type_description_hash"] == store.hash_rihs01(t["type"]) and t["type_description_hash"].startswith("RIHS01_")


def _receive(ws, wanted: tuple[str, ...], seconds: float) -> tuple[dict[str, list], list[int], dict]:
    """Subscribe to `wanted` as they are advertised; (messages by topic, time frames, channels)."""
    channels, got, clock, subscribed = {}, {}, [], {}
    deadline = time.monotonic() + seconds
    while time.monotonic() < deadline and (len(got) < len(wanted) or not clock):
        frame = ws.recv(timeout=5)
        if isinstance(frame, str):
            op = json.loads(frame)
            if op["op"] == "advertise":
                channels.update({c["id"]: c for c in op["channels"]})
                for c in op["channels"]:
                    if c["topic"] in wanted and c["topic"] not in subscribed.values():
                        subscribed[len(subscribed) + 1] = c["topic"]
                        ws.send(json.dumps({"op": "subscribe", "subscriptions": [
                            {"id": len(subscribed), "channelId": c["id"]}]}))
        elif frame[0] == MESSAGE_DATA:
            sub, stamp = struct.unpack_from("<IQ", frame, 1)
            got.setdefault(subscribed[sub], []).append((stamp, bytes(frame[13:])))
        elif frame[0] == TIME:
            clock.append(struct.unpack_from("<Q", frame, 1)[0])
    return got, clock, channels


@pytest.mark.parametrize("protocols", [[CLASSIC], [SDK], [SDK, CLASSIC]])
def test_a_client_offering_either_subprotocol_receives_the_clock_and_odometry(protocols, caplog):
    """Foxglove's app offers ``foxglove.sdk.v1``; Foxglove Studio <= 1.87, older Lichtblick and the
    ws-protocol client library offer ``foxglove.websocket.v1``, which foxglove-sdk alone refuses:
    each gets the clock and odometry, and is answered with the name it offered."""
    view = LiveView(0)
    view.add("/clock", "rosgraph_msgs/msg/Clock")
    view.add("/robot_0/odom", "nav_msgs/msg/Odometry")
    view.start()
    stop = threading.Event()

    def feed() -> None:
        t = 0
        while not stop.is_set():
            t += 100_000_000
            view.write("/clock", t, clock_codec.encode_clock(t))
            view.write("/robot_0/odom", t, odometry.encode_odometry("robot_0", t, Pose2D(1.0, 2.0, 0.5), 0.1, 0.0))
            time.sleep(0.02)

    feeder = threading.Thread(target=feed, daemon=True)
    feeder.start()
    try:
        assert view.url == f"ws://127.0.0.1:{view.port}"
        with connect(view.url, subprotocols=protocols, open_timeout=10, max_size=None) as ws:
            assert ws.subprotocol == protocols[0]
            got, clock, _ = _receive(ws, ("/clock", "/robot_0/odom"), 20)
    finally:
        stop.set()
        feeder.join()
        time.sleep(0.3)  # the SDK's listener is told of the disconnect on its own threads
        view.close()
    assert set(got) == {"/clock", "/robot_0/odom"} and clock == sorted(clock) and clock
    stamp, pose, _, _ = odometry.decode_odometry(got["/robot_0/odom"][-1][1])
    assert stamp == got["/robot_0/odom"][-1][0] and (pose.x, pose.y) == (1.0, 2.0)
    assert clock_codec.decode_clock(got["/clock"][0][1]) == got["/clock"][0][0]
    # the SDK logs through Python's logging: nothing at all for a client that leaves (it used to
    # log a failed callback per subscribed channel)
    assert [r.getMessage() for r in caplog.records if r.name.startswith("foxglove")] == []


def test_a_client_offering_no_foxglove_subprotocol_is_refused():
    from websockets.exceptions import InvalidStatus

    view = LiveView(0)
    view.start()
    try:
        with pytest.raises(InvalidStatus):
            connect(view.url, subprotocols=["something.else"], open_timeout=10)
    finally:
        view.close()


def test_a_busy_port_is_named_before_anything_starts(tmp_path):
    """The launcher checks the port before it starts any node: exit 2, one line, a hint."""
    busy = socket.create_server(("127.0.0.1", 0))
    port = busy.getsockname()[1]
    try:
        assert check_port("127.0.0.1", port) is not None and check_port("127.0.0.1", 0) is None
        with pytest.raises(OSError):
            LiveView(port)
        result = subprocess.run(
            [sys.executable, "-m", "launch_py.run", "--robots", "2", "--duration", "5", "--foxglove", str(port),
             "--bag", str(tmp_path / "bag"), "--domain-id", os.environ["ROS_DOMAIN_ID"]],
            capture_output=True, text=True, timeout=60, cwd=Path(__file__).resolve().parents[1])
    finally:
        busy.close()
    assert result.returncode == 2, result.stdout + result.stderr
    (line,) = result.stderr.strip().splitlines()
    assert f"--foxglove {port}" in line and "--foxglove 0" in line
    assert result.stdout == "" and not (tmp_path / "bag").exists()  # nothing was started


def test_the_shipped_layouts_are_the_ones_the_code_builds():
    from swarm_sim.nodes.foxglove_layout import (
        FOXGLOVE_SCRIPTS,
        LAYOUT_FILE,
        LICHTBLICK_FILE,
        STUDIO_SCRIPTS,
        TOTALS,
        build_layout,
        build_lichtblick_layout,
    )

    assert LAYOUT_FILE.read_text() == build_layout() + "\n", "run: python -m swarm_sim.nodes.foxglove_layout"
    assert LICHTBLICK_FILE.read_text() == build_lichtblick_layout() + "\n", "run: python -m swarm_sim.nodes.foxglove_layout"
    layout = json.loads(LAYOUT_FILE.read_text())
    scene = layout["content"]["items"][0]["content"]
    assert scene["panelType"] == "ThreeDee" and scene["config"]["topics"]["/world/markers"]["visible"]
    assert scene["config"]["topics"]["/depot/markers"]["visible"] and scene["config"]["topics"]["/center/markers"]
    plots = [item["content"] for item in layout["content"]["items"][1]["content"]["items"]]
    paths = {p["value"] for plot in plots for p in plot["config"]["paths"]}
    assert f"{TOTALS}.deliveries" in paths and f"{FOXGLOVE_SCRIPTS}depot_queues.total" in paths  # the depot's LivePlot
    scripts = {s["name"]: s["sourceCode"] for s in layout["userScripts"].values()}
    assert f'export const output = "{TOTALS}"' in scripts["swarm totals"]
    assert 'inputs = ["/depot/state"]' in scripts["depot queues"]

    # Lichtblick's (and Foxglove Studio's) classic form: every panel in the mosaic has a config,
    # the scripts write under /studio_script/, the plots read them
    classic = json.loads(LICHTBLICK_FILE.read_text())
    assert set(classic) >= {"configById", "layout", "userNodes", "globalVariables", "playbackConfig"}

    def leaves(node):
        return [node] if isinstance(node, str) else [*leaves(node["first"]), *leaves(node["second"])]

    assert sorted(leaves(classic["layout"])) == sorted(classic["configById"])
    assert classic["configById"]["3D!swarm"]["topics"]["/world/markers"] == {"visible": True}
    outputs = {n["sourceCode"].split('export const output = "')[1].split('"')[0] for n in classic["userNodes"].values()}
    assert outputs == {STUDIO_SCRIPTS + "swarm_totals", STUDIO_SCRIPTS + "depot_queues"}
    classic_paths = {p["value"] for k, c in classic["configById"].items() if k.startswith("Plot!") for p in c["paths"]}
    assert {p.rpartition(".")[0] for p in classic_paths} == outputs

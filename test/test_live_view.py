"""The live view (`swarm-run --foxglove`): a plain WebSocket client (the `websockets` package, no
Foxglove code) speaks the Foxglove protocol to a real run, subscribes to a few channels and decodes
what arrives with our codecs and rosbags: odometry, scans, markers (the center's, latched before
the client came), the sim clock; the server listens on 127.0.0.1 only. The run (realtime, so it
lasts long enough on a loaded machine) is stopped with Ctrl-C once the client has seen enough."""

from __future__ import annotations

import json
import os
import re
import signal
import struct
import subprocess
import sys
import time
from pathlib import Path

import psutil
import yaml
from rosbags.typesys import Stores, get_typestore
from websockets.sync.client import connect

from swarm_msgs_py import odometry, scan
from swarm_sim.recording import read_bag
from swarm_sim.recording.metadata import _msgdef

WANTED = ("/clock", "/robot_0/odom", "/robot_1/scan", "/world/markers", "/center/markers")
MESSAGE_DATA, TIME = 1, 2
"""Binary opcodes of the Foxglove WebSocket protocol (server -> client)."""


def _start_run(bag: Path) -> subprocess.Popen:
    cmd = [sys.executable, "-m", "launch_py.run", "--bag", str(bag), "--scenario", "mdbsa_d", "--robots", "2",
           "--duration", "300", "--mode", "realtime", "--real-time-factor", "1", "--foxglove", "0",
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
        channels, got, clock = {}, {}, []
        with connect(url, subprotocols=["foxglove.sdk.v1", "foxglove.websocket.v1"], open_timeout=20,
                     max_size=None) as ws:
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
    finally:
        proc.send_signal(signal.SIGINT)  # seen enough: Ctrl-C, which leaves a valid bag
        out, _ = proc.communicate(timeout=120)
    assert set(got) == set(WANTED), ({t: len(v) for t, v in got.items()}, len(clock), "".join(before) + out[-3000:])
    assert proc.returncode == 130, out[-3000:]
    # start-up progress: what the launcher started, then what the world waits for
    printed = "".join(before) + out
    assert "[swarm-run] started the world and 2 controller/server process(es)" in printed
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


def test_the_shipped_layout_is_the_one_the_code_builds():
    from swarm_sim.nodes.foxglove_layout import LAYOUT_FILE, QUEUES, TOTALS, build_layout

    assert LAYOUT_FILE.read_text() == build_layout() + "\n", "run: python -m swarm_sim.nodes.foxglove_layout"
    layout = json.loads(LAYOUT_FILE.read_text())
    scene = layout["content"]["items"][0]["content"]
    assert scene["panelType"] == "ThreeDee" and scene["config"]["topics"]["/world/markers"]["visible"]
    plots = [item["content"] for item in layout["content"]["items"][1]["content"]["items"]]
    paths = {p["value"] for plot in plots for p in plot["config"]["paths"]}
    assert f"{TOTALS}.deliveries" in paths and f"{QUEUES}.total" in paths
    scripts = {s["name"]: s["sourceCode"] for s in layout["userScripts"].values()}
    assert f'export const output = "{TOTALS}"' in scripts["swarm totals"]
    assert 'inputs = ["/depot/state"]' in scripts["depot queues"]

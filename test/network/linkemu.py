"""A switch that shapes its links in user space: loss, delay and jitter, as ``tc qdisc ... netem``.

This machine's kernel has no netem (``tc qdisc add ... netem``: "Specified qdisc kind is
unknown"; only pfifo, htb and tbf), so the testbed's switch namespace runs this process instead of
a kernel bridge when links are shaped: it reads every frame from each host's port (an AF_PACKET
socket on the switch end of the host's veth pair), learns source MAC addresses as a bridge does,
and sends each frame on to its destination port(s) after the shaping of both links it crosses
(the sender's, host -> switch, and the receiver's, switch -> host), as netem on each host's
interface and on the switch's port towards it would. Per link: ``loss`` (probability), ``delay``
and ``jitter`` [s] (each frame waits delay + uniform(-jitter, jitter), never less than 0; frames
overtake each other as with netem's jitter). A partition is loss 1.

``linkemu.py run CONFIG PORT...``: the shaping is the JSON file CONFIG ({port: {"loss": .., "delay":
.., "jitter": ..}}), re-read whenever it changes; on SIGTERM it writes its counters ({port:
{"frames_in", "dropped", "frames_out"}}) to CONFIG + ".stats" and exits.
``linkemu.py offload IFACE``: turn off the interface's checksum and segmentation offloads (run in
the host's namespace), so that every frame a host sends carries its real checksums and fits the
MTU: a frame relayed from user space is sent as it is.
"""

from __future__ import annotations

import ctypes
import fcntl
import heapq
import json
import os
import random
import select
import signal
import socket
import struct
import sys
import time

ETH_P_ALL = 3
SIOCETHTOOL = 0x8946
ETHTOOL_STXCSUM, ETHTOOL_SSG, ETHTOOL_STSO, ETHTOOL_SGSO = 0x17, 0x19, 0x1F, 0x24


def offload_off(iface: str) -> None:
    """ethtool -K IFACE tx off sg off tso off gso off, by ioctl."""
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as s:
        for cmd in (ETHTOOL_STSO, ETHTOOL_SGSO, ETHTOOL_SSG, ETHTOOL_STXCSUM):
            value = ctypes.create_string_buffer(struct.pack("II", cmd, 0))
            ifreq = struct.pack("16sP", iface.encode(), ctypes.addressof(value))
            fcntl.ioctl(s.fileno(), SIOCETHTOOL, ifreq)


def run(config_path: str, ports: list[str]) -> int:
    socks = {}
    for port in ports:
        s = socket.socket(socket.AF_PACKET, socket.SOCK_RAW, socket.htons(ETH_P_ALL))
        s.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, 8 << 20)
        s.bind((port, 0))
        s.setblocking(False)
        socks[port] = s
    port_of_fd = {s.fileno(): p for p, s in socks.items()}
    stats = {p: {"frames_in": 0, "dropped": 0, "frames_out": 0} for p in ports}
    shape: dict[str, dict] = {}
    mtime = -1.0
    macs: dict[bytes, str] = {}
    queue: list[tuple[float, int, str, bytes]] = []
    rng = random.Random(0)
    seq = 0
    stop = []
    signal.signal(signal.SIGTERM, lambda *_: stop.append(1))
    next_check = 0.0
    while not stop:
        now = time.monotonic()
        if now >= next_check:
            next_check = now + 0.02
            try:
                m = os.stat(config_path).st_mtime_ns
                if m != mtime:
                    with open(config_path, encoding="utf-8") as f:
                        shape = json.load(f)
                    mtime = m
            except (OSError, ValueError):
                pass
        wait = min(0.02, max(0.0, queue[0][0] - now)) if queue else 0.02
        readable, _, _ = select.select(list(socks.values()), [], [], wait)
        for s in readable:
            port = port_of_fd[s.fileno()]
            while True:
                try:
                    frame, addr = s.recvfrom(65536)
                except BlockingIOError:
                    break
                if addr[2] == socket.PACKET_OUTGOING:  # what we sent on this port ourselves
                    continue
                stats[port]["frames_in"] += 1
                dst, src = frame[:6], frame[6:12]
                macs[src] = port
                targets = [macs[dst]] if dst in macs and not dst[0] & 1 else [p for p in ports if p != port]
                now = time.monotonic()
                for target in targets:
                    if target == port:
                        continue
                    a, b = shape.get(port, {}), shape.get(target, {})
                    keep = (1.0 - a.get("loss", 0.0)) * (1.0 - b.get("loss", 0.0))
                    if rng.random() >= keep:
                        stats[target]["dropped"] += 1
                        continue
                    delay = sum(max(0.0, x.get("delay", 0.0) + rng.uniform(-1, 1) * x.get("jitter", 0.0))
                                for x in (a, b))
                    seq += 1
                    heapq.heappush(queue, (now + delay, seq, target, frame))
        now = time.monotonic()
        while queue and queue[0][0] <= now:
            _, _, target, frame = heapq.heappop(queue)
            try:
                socks[target].send(frame)
                stats[target]["frames_out"] += 1
            except OSError:
                stats[target]["dropped"] += 1
    with open(config_path + ".stats", "w", encoding="utf-8") as f:
        json.dump(stats, f)
    return 0


if __name__ == "__main__":
    if sys.argv[1] == "offload":
        offload_off(sys.argv[2])
        sys.exit(0)
    sys.exit(run(sys.argv[2], sys.argv[3:]))

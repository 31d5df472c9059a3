"""`/lockstep/ack`: std_msgs/msg/Header <-> (server channel, tick answered).

header.stamp = the tick [sim time] the server has finished; header.frame_id = its channel.
The world's lockstep barrier waits for these as it waits for the robots' commands.
"""

from __future__ import annotations

from swarm_msgs_py.cdr import Reader, Writer, codec

TYPE_NAME = "std_msgs/msg/Header"


@codec(TYPE_NAME)
def encode_ack(channel: str, stamp_ns: int) -> bytes:
    w = Writer()
    w.header(stamp_ns, channel)
    return w.message()


@codec(TYPE_NAME)
def decode_ack(data: bytes) -> tuple[str, int]:
    stamp_ns, channel = Reader(data).header()
    return channel, stamp_ns

"""`/world/run`: std_msgs/msg/Header <-> (run, state): the world's word that its run goes on or has ended.

header.stamp = the world's sim time; header.frame_id = ``<run> <state>``: `run`, a random id the
world draws when it starts (two worlds on one domain, one after the other, differ by it), and
`state`, ``running`` or the run's end as the bag records it (``complete``, ``finished``,
``interrupted``, ``server <channel> died``). Reliable and transient-local (a late joiner gets the
newest at once), tagged with the run's key (`swarm_msgs_py.auth`). Every other process of the run
leaves when it reads an end, or when the world has been silent too long
(`swarm_sim.nodes.run_watch`).
"""

from __future__ import annotations

from swarm_msgs_py.cdr import Reader, Writer, codec

TYPE_NAME = "std_msgs/msg/Header"
RUNNING = "running"


@codec(TYPE_NAME)
def encode_run_state(run: str, state: str, stamp_ns: int) -> bytes:
    if not run or " " in run:
        raise ValueError(f"a run id is one word, got {run!r}")
    w = Writer()
    w.header(stamp_ns, f"{run} {state}")
    return w.message()


@codec(TYPE_NAME)
def decode_run_state(data: bytes) -> tuple[str, str]:
    """(run, state); ValueError if the frame id is not ``<run> <state>``."""
    _, text = Reader(data).header()
    run, _, state = text.partition(" ")
    if not run or not state:
        raise ValueError(f"expected '<run> <state>', got {text[:60]!r}")
    return run, state

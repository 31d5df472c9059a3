"""pybullet, imported and connected without its banners.

pybullet's C module writes ``pybullet build time: ...`` to standard error when it is first
imported, which lands in our commands' output once per process of a run (three times for a
caging run), and some builds print it on standard output when a client connects, where
``--json`` output must be JSON only. The import runs with file descriptor 2, `connect` with file
descriptor 1, pointed at /dev/null; nothing pybullet writes later is touched. Import pybullet
from here (``from swarm_sim.world.bullet import pybullet as p``).
"""

from __future__ import annotations

import contextlib
import ctypes
import os
import sys
from collections.abc import Iterator


@contextlib.contextmanager
def _silenced(fd: int) -> Iterator[None]:
    """File descriptor `fd` pointed at /dev/null (C's buffered output flushed there too)."""
    for stream in (sys.stdout, sys.stderr):
        stream.flush()
    saved, devnull = os.dup(fd), os.open(os.devnull, os.O_WRONLY)
    os.dup2(devnull, fd)
    try:
        yield
    finally:
        ctypes.CDLL(None).fflush(None)
        os.dup2(saved, fd)
        os.close(saved)
        os.close(devnull)


with _silenced(2):
    import pybullet


def connect(method: int) -> int:
    """``pybullet.connect(method)`` with standard output silenced; the client id."""
    with _silenced(1):
        return pybullet.connect(method)

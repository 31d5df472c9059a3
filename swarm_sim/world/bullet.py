"""pybullet, imported without its build-time banner.

pybullet's C module writes ``pybullet build time: ...`` to standard error when it is first
imported, which lands in our commands' output once per process of a run (three times for a caging
run). The import runs with file descriptor 2 pointed at /dev/null; nothing pybullet writes later
is touched. Import pybullet from here (``from swarm_sim.world.bullet import pybullet as p``).
"""

from __future__ import annotations

import os
import sys


def _import_quietly():
    sys.stderr.flush()
    saved = os.dup(2)
    devnull = os.open(os.devnull, os.O_WRONLY)
    try:
        os.dup2(devnull, 2)
        import pybullet
    finally:
        os.dup2(saved, 2)
        os.close(saved)
        os.close(devnull)
    return pybullet


pybullet = _import_quietly()

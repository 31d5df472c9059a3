"""Process lifetime helpers shared by the launcher and the node processes: a child must never
outlive whoever started it, and a node process whose run is over leaves without a teardown."""

from __future__ import annotations

import atexit
import ctypes
import os
import signal
import sys
from typing import NoReturn

_PR_SET_PDEATHSIG = 1
_PR_SET_NAME = 15


def _prctl(option: int, arg) -> bool:
    try:
        return ctypes.CDLL(None, use_errno=True).prctl(option, arg, 0, 0, 0) == 0
    except (OSError, AttributeError):  # not Linux
        return False


def die_with_parent(parent: int, sig: int = signal.SIGTERM) -> None:
    """In a child (before exec, or right after fork): the kernel sends it `sig` when its parent
    dies, however it dies (Linux ``PR_SET_PDEATHSIG``)."""
    if _prctl(_PR_SET_PDEATHSIG, int(sig)) and os.getppid() != parent:
        os._exit(1)  # the parent died before the prctl took effect


def set_process_name(name: str) -> None:
    """What ``ps -o comm`` and /proc/<pid>/comm show (15 bytes on Linux)."""
    _prctl(_PR_SET_NAME, ctypes.c_char_p(name.encode()[:15]))


def leave(code: int) -> NoReturn:
    """End this process now, its DDS participant included, without tearing anything down:
    stdout and stderr flushed, the ``atexit`` handlers run (files this process registered for
    removal, `launch_py.hosts.apply`), then ``os._exit``. For a node whose run is over and saved:
    deleting the world's participant, the run's Fast DDS discovery server, can crash Fast DDS 2.14
    (SIGSEGV in ``CacheChangePool::~CacheChangePool`` under ``PDPServer``/``EDPServer``
    destruction: two core dumps, worlds of loaded test suites, after their bags were closed), and
    no peer needs the goodbye (they go by the run's end, ``/world/run``, and by its lease)."""
    sys.stdout.flush()
    sys.stderr.flush()
    atexit._run_exitfuncs()  # CPython's own exit step, which os._exit skips
    os._exit(code)

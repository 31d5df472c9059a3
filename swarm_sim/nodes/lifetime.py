"""Process lifetime helpers shared by the launcher and the controller process that forks one
process per robot: a child must never outlive whoever started it."""

from __future__ import annotations

import ctypes
import os
import signal

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

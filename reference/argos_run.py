"""What every reference script does alike: run ``argos3`` on a temporary experiment file in a
built checkout (its library paths are relative to it) and time it by wall and CPU seconds (the
machine is shared, so the wall time alone is no speed measure)."""
from __future__ import annotations

import json
import re
import resource
import subprocess
import time
from collections.abc import Callable
from pathlib import Path

ANSI = re.compile(r"\x1b\[[0-9;]*m")
"""ARGoS colours its log lines."""


class ReferenceError(Exception):
    """A run or an input that cannot be used; the message names it."""


def children_cpu_s() -> float:
    """CPU seconds (user + system) of this process's waited-for children so far."""
    used = resource.getrusage(resource.RUSAGE_CHILDREN)
    return used.ru_utime + used.ru_stime


def run_argos(command: list[str], tree: Path, xml: str, name: str, label: str, timeout_s: float,
              env: dict | None = None) -> tuple[str, float, float]:
    """``command`` + ``-c <temp file holding xml>`` run in ``tree``: (its output, wall s, CPU s).
    The temporary file is removed whatever happens; a failure names ``label``."""
    temp = tree / name
    temp.write_text(xml)
    try:
        start, cpu = time.perf_counter(), children_cpu_s()
        done = subprocess.run([*command, "-c", temp.name], cwd=tree, capture_output=True, text=True,
                              timeout=timeout_s, stdin=subprocess.DEVNULL, env=env)
        wall, cpu = time.perf_counter() - start, children_cpu_s() - cpu
    except subprocess.TimeoutExpired:
        raise ReferenceError(f"{label}: argos3 ran past {timeout_s:.0f} s") from None
    finally:
        temp.unlink(missing_ok=True)
    if done.returncode != 0:
        tail = (done.stderr or done.stdout).strip().splitlines()[-1:] or ["(no output)"]
        raise ReferenceError(f"{label}: argos3 exited {done.returncode}: {ANSI.sub('', tail[0])}")
    return done.stdout + "\n" + done.stderr, wall, cpu


def done_keys(out: Path, key: Callable[[dict], tuple]) -> set[tuple]:
    """The runs already in an output file, by ``key`` (so a sweep resumes); a line that is no
    reference row is refused by its line number, and nothing is written."""
    if not out.exists():
        return set()
    keys = set()
    for n, text in enumerate(out.read_text().splitlines(), 1):
        try:
            keys.add(key(json.loads(text)))
        except (ValueError, KeyError, TypeError):
            raise ReferenceError(f"{out}:{n}: not a reference row") from None
    return keys

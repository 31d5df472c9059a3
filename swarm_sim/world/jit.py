"""Compiled loops for the world's per-tick work: numba's ``njit``, set up once for every kernel.

A few of the world's per-tick steps (the scan's ray tests and robot pairs, the foraging task's
search for the resources within reach) are clearest as plain loops over robots, pairs and rays,
and too slow as Python loops; numpy's batched form of them pays dozens of fixed-cost calls a
tick and writes every intermediate to memory. numba compiles
such a loop to machine code on its first call (see `swarm_sim.world.raycast` for what it
gained).

Same results as numpy, bit for bit: fastmath stays off, so LLVM neither reassociates nor fuses a
multiply and an add into one rounding (FMA), and every ``+ - * /``, ``sqrt``, ``floor``, ``ceil``
and comparison is the one correctly rounded IEEE operation numpy does. Transcendental functions
are not: numba calls libm, numpy its own SIMD code for some (``arctan2`` here differs from libm's
in ~7 % of 2 million samples; ``cos`` and ``sin`` matched), so kernels take those values from
numpy, computed outside. The "numpy" error model makes a division by zero give inf or nan, as
in numpy, instead of raising.

Compilation and its cache: a kernel compiles on its first call and is written to a cache in
``__pycache__`` beside the source file, or, where that directory is read-only (an installed
package), in the user's cache directory (``~/.cache/numba``; ``NUMBA_CACHE_DIR`` overrides
both); later processes (sweep workers, the graph's world node) load it instead. Once per
process, measured as a 1 s, 16-robot CPFA batch run (0.06 s without numba): compiling 3.2 s
(the obstacle kernels 0.8 s more, only in scenarios with obstacles), loading from the cache
0.4 s, plus 0.2 s to import numba. A sweep's fork pool pays that once per worker, not per run.
Concurrent first runs each compile and write the same files (numba writes them atomically).
The cache is keyed by the source file's modification time and size and by the CPU, so an edited
file or another machine compiles afresh. Where no cache directory is writable at all, the
kernels compile in memory in every process (with a warning, once).
"""

from __future__ import annotations

import warnings
from collections.abc import Callable
from typing import Any

import numba

_OPTIONS: dict[str, Any] = {"error_model": "numpy"}


def _compile(fn: Callable[..., Any], **options: Any) -> Any:
    try:
        return numba.njit(cache=True, **_OPTIONS, **options)(fn)
    except RuntimeError as error:  # numba: "cannot cache function ...: no locator available"
        if "cannot cache" not in str(error):
            raise
        warnings.warn("numba finds no writable cache directory for the world's kernels: they compile in "
                      "memory in every process (set NUMBA_CACHE_DIR to a writable directory)", RuntimeWarning)
        return numba.njit(cache=False, **_OPTIONS, **options)(fn)


def kernel(fn: Callable[..., Any]) -> Any:
    """Decorator: compile the function with numba (cached on disk, IEEE arithmetic as numpy's)."""
    return _compile(fn)


def inline(fn: Callable[..., Any]) -> Any:
    """Decorator for the small helpers of a kernel: inlined into it (numba's own inlining, before
    LLVM's), so that a kernel calling them compiles as one loop body."""
    return _compile(fn, inline="always")

"""Compiled loops for the world's per-tick work: numba's ``njit``, set up once for every kernel.

A few of the world's per-tick steps (the scan's ray tests, the scan's robot pairs) are clearest
as plain loops over robots, pairs and rays, and too slow as Python loops; numpy's batched form
of them pays ~60 fixed-cost calls a tick and writes every intermediate to memory. numba compiles
such a loop to machine code on its first call (see `swarm_sim.world.raycast` for what it
gained).

Same results as numpy, bit for bit: fastmath stays off, so LLVM neither reassociates nor fuses a
multiply and an add into one rounding (FMA), and every ``+ - * /``, ``sqrt``, ``floor``, ``ceil``
and comparison is the one correctly rounded IEEE operation numpy does. Transcendental functions
are not: numba calls libm, numpy its own SIMD code for some (``arctan2`` here differs from libm's
in ~7 % of values), so kernels take those values from numpy, computed outside. The "numpy" error
model makes a division by zero give inf or nan, as in numpy, instead of raising.

Compilation and its cache: a kernel compiles on its first call (seconds) and is written to a
cache in ``__pycache__`` beside the source file, or, where that directory is read-only, in the
user's cache directory (``~/.cache/numba``; ``NUMBA_CACHE_DIR`` overrides both); later processes
(sweep workers, the graph's world node) load it in milliseconds. The cache is keyed by the source
file's modification time and size and by the CPU, so an edited file or another machine compiles
afresh.
"""

from __future__ import annotations

import numba

kernel = numba.njit(cache=True, error_model="numpy")
"""Decorator: compile the function with numba (cached on disk, IEEE arithmetic as numpy's)."""

inline = numba.njit(cache=True, error_model="numpy", inline="always")
"""Decorator for the small helpers of a kernel: inlined into it (numba's own inlining, before
LLVM's), so that a kernel calling them compiles as one loop body."""

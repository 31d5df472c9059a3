"""The MDBSA paper's per-minute foraging rate (Figs. 7 and 9) as a JSON result field.

A pure function of a `RunTrace`'s deliveries (the world's drop events, recorded in a bag as in
a batch run) and its robots, so the bag of a graph run and the batch run give the same series.
"""

from __future__ import annotations

from typing import Any

from swarm_msgs_py.types import NS_PER_S

MINUTE_NS = 60 * NS_PER_S


def resources_per_robot_per_min(trace: Any) -> list[list[float]]:
    """[[t [s], resources delivered per robot in the minute ending at t], ...] for every
    complete minute of the run (Lu & Luna 2023, Figs. 7 and 9: "the average number of
    resources collected per robot per minute").

    As the authors' loop functions count it: deliveries of the whole swarm in each minute,
    and a last partial minute is dropped (``DSA_loop_functions::PreStep`` pushes the count at
    each full minute, ``PostExperiment`` writes only those; MARSLab-UTRGV/Adaptive-Multiple-
    Distributed-Spiral-Search-Algorithm, branch luki-dev, source/DSA/DSA_loop_functions.cpp),
    here divided by the number of robots. A drop stamped t belongs to the tick (t - dt, t], so
    one stamped exactly 60 s counts in the first minute.
    """
    minutes = int(round(trace.sim_seconds * NS_PER_S)) // MINUTE_NS
    robots = len(trace.robots)
    if minutes <= 0 or robots == 0:
        return []
    counts = [0] * minutes
    for d in trace.drops:
        m = (d.stamp_ns - 1) // MINUTE_NS
        if 0 <= m < minutes:
            counts[m] += 1
    return [[60.0 * (m + 1), round(c / robots, 6)] for m, c in enumerate(counts)]


def resources_per_robot_per_min_mean(trace: Any) -> float | None:
    """The mean over the run's complete minutes of `resources_per_robot_per_min`: resources per
    robot per minute (the spiral paper's foraging rate as one number); None under a minute."""
    per_minute = resources_per_robot_per_min(trace)
    return round(sum(v for _, v in per_minute) / len(per_minute), 6) if per_minute else None

"""The queue strategies' own run metrics, over the depot manager's ``queue_lengths`` series
(recorded live by the batch runner, replayed from ``/depot/state`` in a bag)."""

from __future__ import annotations

import numpy as np

from swarm_sim.analysis.metrics import RunTrace


def queue_length_stats(trace: RunTrace) -> tuple[float, int]:
    """Time-weighted mean and the maximum of the total entry-line queue length."""
    history = trace.series.get("queue_lengths", [])
    if not history:
        return 0.0, 0
    times = [t for t, _ in history] + [trace.sim_seconds]
    totals = [sum(q) for _, q in history]
    weights = np.diff(times)
    mean = float(np.dot(weights, totals) / weights.sum()) if weights.sum() > 0 else float(totals[-1])
    return mean, max(totals)


def queue_length_mean(trace: RunTrace) -> float:
    return round(queue_length_stats(trace)[0], 6)


def queue_length_max(trace: RunTrace) -> int:
    return queue_length_stats(trace)[1]

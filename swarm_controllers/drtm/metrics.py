"""The DRTM paper's performance measures (Sec. 2.4) as JSON result fields.

Pure functions of a `RunTrace`: the nest's series (``nest_food``, ``nest_waiting``,
``nest_oaes``; read off the states the nest sends, `swarm_controllers.drtm.codec.OUTPUTS`: live
in batch, from the recorded ``/nest/state`` in a bag), the world's deliveries and the robots'
OAE counters, so a batch run and the bag of a graph run give the same numbers.
"""

from __future__ import annotations

import bisect
from typing import Any

from swarm_controllers.drtm.behaviour import ForagerState
from swarm_controllers.drtm.config import NestConfig
from swarm_sim.analysis.state_rules import events_by_state

SERIES_PERIOD = 5.0
"""The time series fields hold one value every this many seconds of sim time [s]."""


def _points(trace: Any, name: str) -> list[tuple[float, float]]:
    return trace.series.get(name, [])


def food_deviation(trace: Any) -> float | None:
    """V_f, eq. (8): the mean over ticks t = 1..T of |F_d - F(t)| [tokens] (None without nest data)."""
    points = [v for t, v in _points(trace, "nest_food") if t > 0]
    if not points or trace.config is None:
        return None
    desired = NestConfig.of(trace.config).desired_food
    return round(sum(abs(desired - v) for v in points) / len(points), 6)


def nest_food_final(trace: Any) -> float | None:
    """F(T): net food in the nest at the last tick the nest served [tokens]."""
    points = _points(trace, "nest_food")
    return round(points[-1][1], 6) if points else None


def food_collected(trace: Any) -> int:
    """F_t: food tokens delivered to the nest (the world's drops)."""
    return len(trace.drops)


def energy_efficiency(trace: Any) -> float | None:
    """E_e = E_n / E_T, eq. (9), as a fraction: the net food energy left in the nest at the end
    over the energy of all tokens collected, i.e. F(T) / F_t (the paper's numbers satisfy this:
    DRTM 20.84 / 173.76 = 11.99 %). None without a delivery."""
    final, collected = nest_food_final(trace), food_collected(trace)
    return round(final / collected, 6) if final is not None and collected else None


def oae_total(trace: Any) -> int:
    """M_T: obstacle-avoidance events of all robots (M_v = M_T / N_r is ``oae_per_robot``)."""
    return sum(s.obstacle_avoidance_events for s in trace.status.values())


def oae_by_state(trace: Any) -> dict[str, int] | None:
    """OAEs by the state (S_S ``searching``, S_R ``returning``) the robot was in when it counted
    them, from the statuses the robots published (`swarm_sim.analysis.state_rules`; None without
    them). Their sum is M_T."""
    return events_by_state(trace.status_log) if trace.status_log else None


def oae_returning_total(trace: Any) -> int | None:
    """The OAEs of robots in state S_R over the run: what the paper's M_T2 counts ("the number
    of OAEs due to robots within state S_R", Sec. 2.2, eq. (5)), over the whole run instead of
    the last T_2."""
    by_state = oae_by_state(trace)
    return None if by_state is None else by_state.get(ForagerState.RETURNING.value, 0)


def _sampled(points: list[tuple[float, float]], end: float) -> list[list[float]]:
    """`points` (t, value) sampled every SERIES_PERIOD from 0 to `end`: the latest value at or
    before each sample time."""
    if not points:
        return []
    times = [t for t, _ in points]
    out = []
    k = 0
    while k * SERIES_PERIOD <= end + 1e-9:
        t = k * SERIES_PERIOD
        i = bisect.bisect_right(times, t + 1e-9) - 1
        if i >= 0:
            out.append([round(t, 6), round(points[i][1], 6)])
        k += 1
    return out


def nest_food_series(trace: Any) -> list[list[float]]:
    """[[t [s], F(t) [tokens]], ...] every SERIES_PERIOD (Fig. 5)."""
    return _sampled(_points(trace, "nest_food"), trace.sim_seconds)


def active_robots_series(trace: Any) -> list[list[float]]:
    """[[t [s], N_r - N_W], ...] every SERIES_PERIOD: robots foraging as the nest knows it."""
    robots = len(trace.robots)
    return _sampled([(t, robots - w) for t, w in _points(trace, "nest_waiting")], trace.sim_seconds)


def oae_series(trace: Any) -> list[list[float]]:
    """[[t [s], OAEs so far], ...] every SERIES_PERIOD, as the nest heard them (Fig. 6)."""
    return _sampled(_points(trace, "nest_oaes"), trace.sim_seconds)

"""The response-threshold rules of the DRTM paper (Pang et al. 2023, eqs. (2)-(7)) and of ARTM.

Pure functions of what a waiting robot knows from the nest (F(t), N_W, M_T2) and of its own
exponent n; `swarm_controllers.drtm.behaviour` wires them into the foragers.
"""

from __future__ import annotations

import math

_MAX_EXPONENT = 700.0
"""exp() of more than this overflows a float; (theta/S)^n is then 'infinite' and P_s = 0."""


def stimulus(desired_food: float, food: float) -> float:
    """S(t) = F_d - F(t), eq. (2) [tokens]."""
    return desired_food - food


def traffic_flow_density(robots: int, waiting: int, side: float) -> float:
    """k = (N_r - N_W) / (L x L), eq. (4): active foragers per unit area [1/m^2]."""
    return (robots - waiting) / (side * side)


def mean_avoidance(recent_oaes: int, robots: int) -> float:
    """M_A = M_T2 / N_r, eq. (5): OAEs within the last T_2 per robot."""
    return recent_oaes / robots


def drtm_threshold(k: float, m_a: float, alpha: float, beta: float) -> float:
    """theta = alpha k + beta M_A, eq. (6)."""
    return alpha * k + beta * m_a


def foraging_probability(s: float, theta: float, n: int) -> float:
    """P_s of eq. (7): S^n / (S^n + theta^n) for S > 0, else 0.

    Computed as 1 / (1 + (theta / S)^n), which is the same number without overflowing for a
    large S; theta <= 0 gives 1 (any positive stimulus beats a zero threshold).
    """
    if not s > 0.0:
        return 0.0
    if theta <= 0.0:
        return 1.0
    x = n * math.log(theta / s)
    return 0.0 if x > _MAX_EXPONENT else 1.0 / (1.0 + math.exp(x))


class ArtmThreshold:
    """ARTM's threshold (Castello et al., Adv. Robot. 2014; Swarm Intell. 2016), as the DRTM
    paper describes it: it adapts to the food in the nest only; "when the stimulus decreases,
    the threshold tends to increase and fewer robots go foraging; when the stimulus increases,
    the threshold tends to decrease"; theta_t0 = 3.3, 1 <= theta <= 10.

    We could not find Castello et al.'s update rule in the public sources we could search, so
    this is our reading of that description: every time the robot hears a new F(t), theta moves
    against the stimulus change, theta <- clip(theta - gain (S(t) - S(t')), theta_min, theta_max),
    t' the previous time it heard. With gain 1 the threshold moves one token per token, in the
    units eq. (7) compares it with; it has no other free parameter.
    """

    def __init__(self, initial: float, lowest: float, highest: float, gain: float) -> None:
        self.value = initial
        self._lowest, self._highest, self._gain = lowest, highest, gain
        self._last: float | None = None

    def update(self, s: float) -> float:
        """Hear a stimulus S(t); returns the new theta."""
        if self._last is not None:
            self.value = min(max(self.value - self._gain * (s - self._last), self._lowest), self._highest)
        self._last = s
        return self.value

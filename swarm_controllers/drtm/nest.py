"""The nest server of the DRTM paper: the energy ledger (Sec. 3.1) and what robots learn of it.

ROS-free (`swarm_sim.protocol.Server`). Who owns the ledger, and why here: the ledger needs
which robots are in S_S or S_R and every obstacle-avoidance event, which only the robots know.
A world task cannot hear robots, and reading their state out of the controllers is the flaw
ARGoS loop functions have, so the robots report those as `NestReport` messages and this server,
stepped once per tick like the depot manager, keeps the books. It trusts the reports (a robot
learns of its delivery from its gripper, a world fact); reports from robots the run does not
have, or from robots the world declared dead, are refused and counted in `rejections`. A dead
robot (`robot_lost`, graph runs only) stops counting as foraging: it stands still and the paper's
ledger charges only moving foragers.

Each tick (stamp t_k) the server applies the reports stamped before t_k, in order, then charges
the tick just ended [t_{k-1}, t_k): `step_energy` per robot in S_S or S_R, C_rate dt / 60 tokens
for the nest. A robot that reported LEFT at t_{k-1} is charged for that tick; one that reported
DEPOSITED or RETURNED_EMPTY (back without a token: the ARGoS foraging example's rule) at t_{k-1}
is not (it was waiting when the tick began). Then it answers every robot with `NestState`
(F(t_k), N_W, M_T2, total OAEs, and the TOLD_* reports it applied: the foraging example's social
rule, relayed); robots see it at t_{k+1}. The run trace's nest series are read
off these states (`swarm_controllers.drtm.codec.OUTPUTS`).
"""

from __future__ import annotations

from collections import deque
from collections.abc import Sequence

from swarm_controllers.drtm.config import NestConfig
from swarm_controllers.drtm.protocol import NestEvent, NestReport, NestState
from swarm_msgs_py.types import NS_PER_S
from swarm_sim.inbound import Reason, Rejections


class NestLedger:
    """The nest's energy in the paper's units, from integer counters (so F(t) never drifts):

    E(t) = token_energy (F(0) + deliveries) - step_energy (robot ticks in S_S or S_R)
           - E_a OAEs - token_energy C_rate t / 60,     F(t) = E(t) / token_energy.
    """

    def __init__(self, config: NestConfig, dt: float) -> None:
        self.config = config
        self.dt = dt
        """Control tick [s]."""
        self.deliveries = 0
        self.active_ticks = 0
        """Robot ticks spent in S_S or S_R."""
        self.avoidances = 0
        self.ticks = 0
        """Ticks elapsed."""

    def deliver(self) -> None:
        self.deliveries += 1

    def avoid(self) -> None:
        self.avoidances += 1

    def advance(self, ticks: int, active: int) -> None:
        """`ticks` ticks pass with `active` robots in S_S or S_R."""
        self.ticks += ticks
        self.active_ticks += ticks * active

    @property
    def energy(self) -> float:
        c = self.config
        return (c.token_energy * (c.initial_food + self.deliveries) - c.step_energy * self.active_ticks
                - c.avoidance_energy * self.avoidances
                - c.token_energy * c.consumption_rate * self.ticks * self.dt / 60.0)

    @property
    def food(self) -> float:
        """F(t) [tokens]."""
        return self.energy / self.config.token_energy


class NestServer:
    """The nest, stepped once per tick (see the module docstring)."""

    def __init__(self, scenario) -> None:
        config = NestConfig.of(scenario)
        self.robots = tuple(scenario.robot_names)
        self._known = frozenset(self.robots)
        self.ledger = NestLedger(config, scenario.sim.dt)
        self._dt_ns = scenario.dt_ns
        self._window_ns = round(config.window(scenario) * NS_PER_S)
        self.active: set[str] = set()
        """Robots in S_S or S_R, as reported."""
        self.returning: set[str] = set()
        """Robots in S_R (FOUND, not yet DEPOSITED), as reported."""
        self._window_all = config.oae_window_states == "all"
        self._recent: deque[int] = deque()
        """Stamps of the OAEs of the last T_2."""
        self._last_ns: int | None = None
        self.rejections = Rejections()
        """Reports that could not be applied, by reason."""
        self.lost: set[str] = set()
        """Robots the world declared dead."""
        self._told = [0, 0]
        """TOLD_SUCCESSFUL and TOLD_UNSUCCESSFUL reports applied at this step: the nest relays them
        to every robot (in ARGoS every resting robot within range-and-bearing's reach hears them)."""

    def robot_lost(self, robot: str, stamp_ns: int) -> None:
        """`robot` was declared dead: it no longer forages, its later reports are refused."""
        self.lost.add(robot)
        self.active.discard(robot)
        self.returning.discard(robot)

    def step(self, stamp_ns: int, messages: Sequence[object]) -> tuple[NestState, ...]:
        self._told = [0, 0]
        for m in messages:
            if isinstance(m, NestReport):
                self._apply(m, stamp_ns)
        if self._last_ns is not None:
            self.ledger.advance((stamp_ns - self._last_ns) // self._dt_ns, len(self.active))
        self._last_ns = stamp_ns
        recent = self._recent
        while recent and recent[0] <= stamp_ns - self._window_ns:
            recent.popleft()
        state = NestState(stamp_ns, self.ledger.food, len(self.robots) - len(self.active), len(recent),
                          self.ledger.avoidances, *self._told)
        return (state,)

    def _apply(self, m: NestReport, stamp_ns: int) -> None:
        if m.robot not in self._known:
            self.rejections.add("NestReport", Reason.UNKNOWN_ROBOT, f"t={stamp_ns / NS_PER_S:.3f} {m.robot[:40]!r}")
            return
        if m.robot in self.lost:
            self.rejections.add("NestReport", Reason.DEAD, f"t={stamp_ns / NS_PER_S:.3f} {m.robot}")
            return
        if m.event is NestEvent.LEFT:
            self.active.add(m.robot)
        elif m.event is NestEvent.FOUND:
            self.returning.add(m.robot)
        elif m.event is NestEvent.DEPOSITED:
            self.active.discard(m.robot)
            self.returning.discard(m.robot)
            self.ledger.deliver()
        elif m.event is NestEvent.RETURNED_EMPTY:
            self.active.discard(m.robot)
            self.returning.discard(m.robot)
        elif m.event is NestEvent.TOLD_SUCCESSFUL:
            self._told[0] += 1
        elif m.event is NestEvent.TOLD_UNSUCCESSFUL:
            self._told[1] += 1
        elif m.event is NestEvent.AVOIDED:
            self.ledger.avoid()
            if self._window_all or m.robot in self.returning:
                self._recent.append(m.stamp_ns)

"""The central-place foraging algorithm (CPFA) baseline.

J. P. Hecker and M. E. Moses, "Beyond pheromones: evolving error-tolerant, flexible, and
scalable ant-inspired robot swarms", Swarm Intelligence 9:43-70, 2015 ("H&M" below): the
CPFA state diagram (Fig. 1), its pseudocode (Algorithm 1) and the behaviour descriptions in
the methods section. Where the paper leaves a detail open, the choice follows BCLab's ARGoS
CPFA controller (``CPFA_controller.cpp`` in BCLab-UNM/CPFA-ARGoS, "ARGoS" below) and says so.

Rules, in the paper's words, and how they are realised here:

* **Set search location / travel to search site** (H&M Fig. 1, Algorithm 1: disperse from
  the nest). Every robot starts at the nest (the depot disc) in DEPARTING toward a site drawn
  uniformly in the arena, a margin ``max(resources.margin, robots.diameter)`` inside the walls
  and outside the nest. The paper draws a dispersal direction U(0, 2 pi) and ARGoS a point on
  the arena border; a uniform site gives every direction as well and also ends a trip that
  reaches it. An *uninformed* traveller switches to SEARCHING with probability p_s each tick
  ("probability of switching to searching"); reaching the site starts an uninformed search.
  Informed travellers (site fidelity, pheromone) ignore p_s and search once they arrive.
* **Search with uninformed walk** (H&M: correlated random walk): every `search_step` metres of
  travel the heading becomes the current heading plus N(0, sigma), sigma = omega. As in ARGoS
  the turn is drawn relative to the robot's current yaw and wrapped to (-pi, pi]. Each tick
  the searcher gives up with probability p_r ("probability of returning to nest") and returns
  without a resource. Staying inside the arena (not specified by the paper): a leg whose end
  would leave the margin is redrawn, at most 8 times, then the robot heads for the arena
  centre; the scan avoidance handles whatever is left.
* **Search with informed walk** (H&M informed-walk equation):
  sigma = omega + (4 pi - omega) exp(-lambda_id t), t = time since the informed search began
  [s]. Searches at a remembered site (site fidelity) or at a pheromone waypoint are informed:
  they start almost undirected and relax to the uninformed walk. ARGoS counts t in search
  steps, CPFA-ROS in seconds (`CpfaConfig.informed_search_time` chooses; seconds by default).
  The ARGoS CPFA turns by w + (2 pi - w) exp(-lambda_id t) itself, w ~ N(0, omega), a loop about
  the site rather than a random walk (`CpfaConfig.informed_walk`: ``turn``).
* **Find resource, sense local density** (H&M Algorithm 1: count the resources c near the
  find): the world picks a resource up when an empty robot reaches it; on the tick
  `obs.sensed.carrying` turns True the robot records the site (its own position) and
  c = len(obs.sensed.resources), the *other* resources within the detection radius (the carried one
  no longer lies on the floor); ARGoS counts the found one as well (its density starts at 1:
  `CpfaConfig.density_counts_find`).
  No survey pause: sensing the neighbourhood is instantaneous here (later ARGoS versions
  disable their 4 s survey wait too). Then RETURNING.
* **Return to nest**: straight for the depot centre. The world drops the resource when the
  carrier enters a drop zone; `obs.sensed.carrying` turning False completes a trip (trips += 1). A
  robot that gave up has arrived when it is inside the depot disc.
* **Docks** (``depot.delivery: docks``, the queue paper's CPFA baseline, sec. III: "robots are
  required to unload resources at designated docks", staying T_unload): a carrier heads for the
  dock stop nearest to it and, once its centre is within its zone's radius of it, stands
  still until the world has dropped the resource after T_unload. No queue: carriers contend for
  a dock with their obstacle avoidance. As in the authors' CPFA (Tameem786/Collision_Free_CPFA,
  ``CPFA_controller::IsInTheNest``: the robot's centre within ``NestRadius`` of one of the
  ``NestPosition`` docks; ``BaseController::Move`` returns before its collision detection while
  the robot ``Wait``s 5 s at the nest), an unloading robot does not avoid.
* **Lay pheromone** (H&M: with probability POIS(c, lambda_lp)): after a delivery the robot
  sends a `PheromoneMessage` (the site, stamped now) with that tick's command. POIS is the
  Poisson CDF e^-lambda sum_{i<=c} lambda^i / i!, as in the paper's equation and ARGoS.
* **Site fidelity** (H&M: with probability POIS(c, lambda_sf)): after a delivery, travel back
  to the site and search informed there.
* **Follow pheromone**: otherwise, if the robot knows waypoints, pick one with probability
  proportional to its strength exp(-lambda_pd * age) (ARGoS's roulette wheel), travel there and
  search informed; waypoints weaker than `pheromone_threshold` are forgotten. Otherwise a new
  uniform site, uninformed. After a give-up return only these last two choices apply (site
  fidelity needs a find, as in ARGoS). Waypoints arrive as `PheromoneMessage`s in
  `obs.messages`, other robots' and the robot's own, one tick after sending. In ARGoS the
  layer's new waypoint is in the shared list before it chooses, so here it is added locally
  when laid and its echo is not counted twice.
* **Travel to an informed site** ends within `controller.arrival_tolerance`, or when the scan
  is blocked within one robot diameter of it (someone stands on the site; CPFA-ROS likewise
  starts searching when its travel is interrupted).

Per-draw probabilities: p_s and p_r are drawn every 1 / `CpfaConfig.draw_rate` seconds in the
reference implementation. The queue paper's lab's CPFA-ARGoS draws both only when the tick is a
multiple of 5 s (``SimulationTick() % (5 * SimulationTicksPerSecond()) == 0``), so the default
is 0.2 Hz (the early iAnt controller drew every 16 Hz step; CPFA-ROS per 0.5 m waypoint). We
keep the same hazard per second but spread it over every tick of dt seconds:
p' = 1 - (1 - p) ** (draw_rate * dt), so no 5 s clock is shared by all robots.

Motion goes through the robot model's motion layer (`swarm_controllers.motion.drive_for`): the
behaviour names targets (sites, the nest, a dock) and walk-leg headings, the model decides how the
robot drives there (the generic robot steers continuously; ``footbot_cpfa`` moves in the ARGoS
CPFA's own stop-turn-go steps). The avoidance described next is the generic robot's; a platform
model brings its authors' own (`swarm_controllers.robots`).

Obstacle avoidance has priority over every state's motion; the state machine still runs (and
draws) on avoidance ticks, as in ARGoS where the CPFA step and the collision-avoiding move are
separate. When an avoidance episode ends the robot first drives straight ahead for one
`search_step` (ARGoS pushes a FORWARD move of SearchStepSize after its avoidance turn) before
its state steers again; without that, a goal just beside an obstacle makes the avoidance turn
and the goal turn undo each other forever with the robot standing still.
"""

from __future__ import annotations

import math
from enum import Enum
from math import remainder

import numpy as np

from swarm_controllers.api import new_command, uniform_draws
from swarm_controllers.cpfa.config import CpfaConfig
from swarm_controllers.cpfa.messages import PheromoneMessage
from swarm_controllers.motion import Avoidance, Drive, drive_for
from swarm_msgs_py.types import NS_PER_S, BehaviourStatus, Command, Observation, RobotId, slot_constructor
from swarm_sim.messaging import per_inbox
from swarm_sim.registry import delivery_zones
from swarm_sim.scenario import Scenario

_TWO_PI = 2.0 * math.pi
_IDLE = (0.0, 0.0)
"""A state's twist when it stands still, or when the avoidance drives and nobody reads it."""
_FOUR_PI = 4.0 * math.pi
RIM_MARGIN = 0.1
"""[m] outside the perimeter, where a non-carrier's give-up return ends on a robot whose legs run
blind (`swarm_controllers.motion.Drive.blind_legs`): the queue authors' ``safeDistance =
redCircleRadius + 0.1`` (Tameem786/Collision_Free_CPFA, ``CPFA_controller::Searching``)."""
_LEG_REDRAWS = 8
_SITE_REDRAWS = 16


class CpfaState(Enum):
    """H&M Fig. 1, folded into the three states a robot can be observed in."""

    DEPARTING = "departing"
    """Set search location and travel to it (random site, remembered site or waypoint)."""
    SEARCHING = "searching"
    """Correlated random walk, uninformed or informed."""
    RETURNING = "returning"
    """Back to the nest, with a resource or after giving up."""


class SearchMode(Enum):
    """Where the current trip's search location came from (H&M: the information used)."""

    UNINFORMED = "uninformed"
    SITE_FIDELITY = "site_fidelity"
    PHEROMONE = "pheromone"


_new_status = slot_constructor(BehaviourStatus)
"""A status, built for a third of the dataclass's cost. `status` reads a member's text as
``_name_`` / ``_value_`` (Enum's documented sunder attributes): ``name`` and ``value`` are
properties, and an Enum's hash is Python code, ~0.15 us each in Python 3.11, on every status."""

_DEPARTING, _SEARCHING, _RETURNING, _UNINFORMED = (
    CpfaState.DEPARTING, CpfaState.SEARCHING, CpfaState.RETURNING, SearchMode.UNINFORMED
)
"""The members every tick compares against, as module constants: looking a member up on its
Enum class costs ~0.1 us in Python 3.11 (measured), a global ~0.01 us."""


@per_inbox
def _pheromones(messages: tuple[object, ...]) -> tuple[PheromoneMessage, ...]:
    """The waypoints among a tick's messages, in order (once per tick in a batch run)."""
    return tuple(m for m in messages if isinstance(m, PheromoneMessage))


def poisson_cdf(k: int, lam: float) -> float:
    """POIS(k, lambda) = P(X <= k), X ~ Poisson(lambda): e^-lambda sum_{i=0}^{k} lambda^i / i!.

    Summed in log space so that large rates neither underflow nor overflow.
    """
    k = math.floor(k)
    if k < 0:
        return 0.0
    if lam <= 0.0:
        return 1.0
    log_lam = math.log(lam)
    total = 0.0
    for i in range(k + 1):
        total += math.exp(i * log_lam - math.lgamma(i + 1) - lam)
    return min(total, 1.0)


def per_tick_probability(p: float, draw_rate: float, dt: float) -> float:
    """Rescale a probability drawn at `draw_rate` [Hz] to a tick of `dt` [s]:
    the same hazard per second, p' = 1 - (1 - p)^(rate * dt)."""
    if p <= 0.0:
        return 0.0
    if p >= 1.0:
        return 1.0
    return -math.expm1(draw_rate * dt * math.log1p(-p))


def informed_search_sigma(omega: float, lambda_id: float, t_search: float) -> float:
    """Std [rad] of an informed walk's turn after `t_search` [s] of informed search:
    omega + (4 pi - omega) exp(-lambda_id t) (H&M informed-walk equation)."""
    return omega + (_FOUR_PI - omega) * math.exp(-lambda_id * t_search)


class CpfaBehaviour:
    """One robot running the CPFA. See the module docstring for the rules and their sources."""

    # Slots, not a __dict__: a thousand robots' behaviours are stepped every tick, and compact
    # objects keep more of them in the CPU's caches between pybullet's passes over the swarm
    # (1000 robots, ticks 600-800, alternated runs: Q_MT 16.6 -> 14.7 ms a tick; CPFA and 112
    # robots within noise; issue 14).
    __slots__ = (
        "_arrival2", "_avoidance", "_blocked2", "_bound", "_carrying", "_dock_r2", "_docks", "_drive",
        "_heading", "_hold", "_informed_turn", "_keep_out2", "_lambda_id", "_lambda_lp", "_lambda_pd", "_lambda_sf",
        "_leg_x", "_leg_y", "_mode", "_nest", "_nest_r2", "_omega", "_to_point",
        "_own_unechoed", "_p_return", "_p_switch", "_pheromones", "_random", "_rng",
        "_count_find", "_rim", "_rim_carriers", "_search_in_steps", "_search_legs", "_search_step", "_search_t0",
        "_site", "_site_clearance2", "_site_count", "_stamp_ns", "_state", "_step2", "_target",
        "_threshold", "_trips", "_update_avoidance", "robot",
    )

    def __init__(
        self, scenario: Scenario, robot: RobotId, rng: np.random.Generator,
        *, keep_out: float | None = None, perimeter: float | None = None, drive: Drive | None = None,
        carrier_rim: bool = False,
    ) -> None:
        """keep_out [m]: radius of a disc about the depot centre the robot stays out of unless
        carrying (the queue strategies' perimeter): random sites and walk legs avoid it and a
        give-up return ends at its edge. None: the depot disc (the plain CPFA). perimeter [m]: the
        queue strategies' perimeter radius, given with keep_out: a give-up return's blind leg ends
        `RIM_MARGIN` outside it. drive: the robot's motion layer when another behaviour owns it
        (the queue strategies'; default: the robot model's, `swarm_controllers.motion.drive_for`).
        carrier_rim: a carrier's return leg ends there too (`depot_manager.config.QueueConfig.return_leg`)."""
        cfg = CpfaConfig.of(scenario)
        dt = scenario.sim.dt
        self.robot = robot
        self._rng = rng
        self._random = uniform_draws(rng)
        """``rng.random`` (the same numbers, cheaper)."""
        self._drive = drive_for(scenario, rng) if drive is None else drive
        self._to_point = self._drive.to_point
        self._hold = self._drive.hold
        self._avoidance = self._drive.avoidance(cfg.search_step)
        self._update_avoidance = self._avoidance.update
        self._p_switch = per_tick_probability(
            cfg.probability_of_switching_to_searching, cfg.draw_rate, dt
        )
        self._p_return = per_tick_probability(
            cfg.probability_of_returning_to_nest, cfg.draw_rate, dt
        )
        self._omega = cfg.uninformed_search_variation
        self._lambda_id = cfg.rate_of_informed_search_decay
        self._lambda_sf = cfg.rate_of_site_fidelity
        self._lambda_lp = cfg.rate_of_laying_pheromone
        self._lambda_pd = cfg.rate_of_pheromone_decay
        self._threshold = cfg.pheromone_threshold
        self._step2 = cfg.search_step**2
        self._search_step = cfg.search_step
        arrival = scenario.controller.arrival_tolerance
        self._arrival2 = arrival**2
        self._blocked2 = (arrival + scenario.robots.diameter) ** 2
        self._nest = (float(scenario.depot.center[0]), float(scenario.depot.center[1]))
        nest_radius = scenario.depot.radius if keep_out is None else keep_out
        self._nest_r2 = nest_radius**2
        margin = max(scenario.resources.margin, scenario.robots.diameter)
        half = scenario.arena.size / 2.0
        self._bound = half - margin if half > margin else half / 2.0
        self._site_clearance2 = (nest_radius + margin) ** 2
        self._keep_out2 = -1.0 if keep_out is None else keep_out**2
        self._rim = perimeter + RIM_MARGIN if perimeter is not None and self._drive.blind_legs else 0.0
        """[m] where a give-up return's blind leg ends (0: it aims at the centre and arrives at the
        keep-out radius, re-aiming on the way)."""
        self._rim_carriers = carrier_rim
        """A carrier's blind leg ends at `_rim` too, not at the centre (``QueueConfig.return_leg``)."""
        docks_mode = keep_out is None and scenario.depot.delivery == "docks"
        zones = delivery_zones(scenario) if docks_mode else ()
        self._docks = [z.center for z in zones]
        """Dock stops a carrier returns to: the zones the docks delivery implies [m, world frame]
        (empty: the depot centre)."""
        self._dock_r2 = max((z.radius for z in zones), default=0.0) ** 2

        self._state = CpfaState.DEPARTING
        self._mode = SearchMode.UNINFORMED
        self._carrying = False
        self._trips = 0
        self._stamp_ns = 0
        self._target = self._random_site()
        self._heading = 0.0
        """Current walk leg's heading [rad, world frame]."""
        self._leg_x = 0.0
        self._leg_y = 0.0
        self._search_t0 = 0.0
        """When the current search began [s]."""
        self._search_legs = 0
        """Walk legs drawn since the current search began."""
        self._search_in_steps = cfg.informed_search_time == "steps"
        self._count_find = int(cfg.density_counts_find)
        self._informed_turn = cfg.informed_walk == "turn"
        self._site: tuple[float, float] | None = None
        """Where the last resource was found, until used for site fidelity or given up."""
        self._site_count = 0
        self._pheromones: list[tuple[int, float, float]] = []
        """Known waypoints as (stamp_ns, x, y), in arrival order."""
        self._own_unechoed: set[PheromoneMessage] = set()

    # ------------------------------------------------------------------ read-only views

    @property
    def state(self) -> CpfaState:
        return self._state

    @property
    def search_mode(self) -> SearchMode:
        return self._mode

    @property
    def informed(self) -> bool:
        return self._mode is not SearchMode.UNINFORMED

    @property
    def target(self) -> tuple[float, float]:
        """Search location of the current trip [m, world frame]."""
        return self._target

    @property
    def site(self) -> tuple[float, float] | None:
        """Remembered site of the last find [m, world frame], if any."""
        return self._site

    @property
    def site_count(self) -> int:
        """c of the last find: other resources sensed at pickup."""
        return self._site_count

    @property
    def pheromones(self) -> tuple[PheromoneMessage, ...]:
        """Waypoints currently remembered (some may since have decayed below threshold)."""
        return tuple(PheromoneMessage(s, x, y) for s, x, y in self._pheromones)

    @property
    def trips(self) -> int:
        return self._trips

    @property
    def obstacle_avoidance_events(self) -> int:
        return self._avoidance.events

    @property
    def avoidance(self) -> Avoidance:
        """The robot's collision avoidance (its motion layer's)."""
        return self._avoidance

    @property
    def switch_probability(self) -> float:
        """p_s per tick of our dt."""
        return self._p_switch

    @property
    def return_probability(self) -> float:
        """p_r per tick of our dt."""
        return self._p_return

    def status(self, stamp_ns: int | None = None) -> BehaviourStatus:
        return _new_status(self.robot, self._stamp_ns if stamp_ns is None else stamp_ns, self._state._name_,
                           self._avoidance.events, self._trips, (("search", self._mode._value_),))

    # ------------------------------------------------------------------ the tick

    def step(self, obs: Observation) -> Command:
        self._stamp_ns = obs.stamp_ns
        self._drive.begin(obs.stamp_ns)
        if obs.messages:
            pheromones = _pheromones(obs.messages)
            if pheromones:
                self._receive(pheromones, obs.stamp_ns)
        out: tuple[object, ...] = ()
        carrying = bool(obs.sensed.carrying)
        if carrying is not self._carrying:
            self._carrying = carrying
            if carrying:
                self._found_resource(obs)
            else:
                self._trips += 1
                out = self._at_nest(obs, delivered=True)
        if self._docks and carrying and self._nearest_dock(obs)[1] < self._dock_r2:
            self._avoidance.reset()  # unloading at a dock: stand still, no avoidance
            return new_command(0.0, 0.0, out)
        override = self._update_avoidance(obs.ranges)
        steering = override is None
        state = self._state
        if state is _SEARCHING:  # the states by how often robots are in them
            linear, angular = self._searching(obs, steering)
        elif state is _RETURNING:
            linear, angular = self._returning(obs, steering)
        else:
            linear, angular = self._departing(obs, steering)
        if override is not None:  # the avoidance's own command, unless messages go out with it
            return override if not out else new_command(override.linear, override.angular, out)
        return new_command(linear, angular, out)

    # ------------------------------------------------------------------ states
    #
    # Each state's tick runs its rules (and their draws) and returns the (linear, angular) twist
    # of its motion. On a tick the obstacle avoidance drives (`steering` False: about half the
    # ticks of a crowded swarm) nothing reads that twist, and it is not computed: `_IDLE`.

    def _departing(self, obs: Observation, steering: bool = True) -> tuple[float, float]:
        pose = obs.pose
        x, y = pose.x, pose.y
        tx, ty = self._target
        d2 = (tx - x) ** 2 + (ty - y) ** 2
        if self._mode is _UNINFORMED:
            # H&M: an uninformed traveller starts searching with probability p_s per tick.
            if self._random() < self._p_switch or d2 < self._arrival2:
                return self._start_search(obs, steering)
        elif d2 < self._arrival2 or (self._avoidance.active and d2 < self._blocked2):
            return self._start_search(obs, steering)
        return self._to_point(x, y, pose.yaw, tx, ty) if steering else _IDLE

    def _start_search(self, obs: Observation, steering: bool = True) -> tuple[float, float]:
        self._state = CpfaState.SEARCHING
        self._search_t0 = obs.t
        self._search_legs = 0
        self._new_leg(obs)
        return self._walk(obs) if steering else _IDLE

    def _searching(self, obs: Observation, steering: bool = True) -> tuple[float, float]:
        # H&M: a searcher gives up and returns with probability p_r per tick.
        if self._random() < self._p_return:
            self._state = CpfaState.RETURNING
            return self._returning(obs, steering)
        pose = obs.pose
        done2 = (pose.x - self._leg_x) ** 2 + (pose.y - self._leg_y) ** 2
        if done2 >= self._step2:
            self._new_leg(obs)
            done2 = 0.0
        return self._walk(obs, done2) if steering else _IDLE

    def _walk(self, obs: Observation, done2: float = 0.0) -> tuple[float, float]:
        """Along the current leg's heading, for what is left of the leg (`done2`: the squared
        distance walked so far [m^2])."""
        return self._hold(remainder(self._heading - obs.pose.yaw, _TWO_PI), self._search_step - math.sqrt(done2))

    def _new_leg(self, obs: Observation) -> None:
        """Next leg of the correlated random walk: heading = yaw + N(0, sigma), or the ARGoS CPFA's
        informed turn (`CpfaConfig.informed_walk`)."""
        pose = obs.pose
        x, y, yaw = pose.x, pose.y, pose.yaw
        turn = None
        if self._mode is _UNINFORMED:
            sigma = self._omega
        else:
            t = self._search_legs if self._search_in_steps else obs.t - self._search_t0
            if self._informed_turn:
                sigma, turn = self._omega, math.exp(-self._lambda_id * t)
            else:
                sigma = informed_search_sigma(self._omega, self._lambda_id, t)
        self._search_legs += 1
        step, bound = self._search_step, self._bound
        normal = self._rng.normal
        for _ in range(_LEG_REDRAWS):
            w = normal(0.0, sigma)
            heading = yaw + (w if turn is None else remainder(w + (_TWO_PI - w) * turn, _TWO_PI))
            end_x = x + step * math.cos(heading)
            end_y = y + step * math.sin(heading)
            nx, ny = self._nest
            if (abs(end_x) <= bound and abs(end_y) <= bound
                    and (end_x - nx) ** 2 + (end_y - ny) ** 2 > self._keep_out2):
                break
        else:
            heading = math.atan2(-y, -x)  # back toward the arena centre (the world origin)
        self._heading = math.remainder(heading, _TWO_PI)
        self._leg_x, self._leg_y = x, y

    def _nearest_dock(self, obs: Observation) -> tuple[tuple[float, float], float]:
        """The dock stop nearest the robot and its squared distance [m, m^2]."""
        x, y = obs.pose.x, obs.pose.y
        d2 = [(dx - x) ** 2 + (dy - y) ** 2 for dx, dy in self._docks]
        k = min(range(len(d2)), key=d2.__getitem__)
        return self._docks[k], d2[k]

    def _returning(self, obs: Observation, steering: bool = True) -> tuple[float, float]:
        pose = obs.pose
        x, y = pose.x, pose.y
        if self._docks and self._carrying:
            if not steering:
                return _IDLE
            (tx, ty), _ = self._nearest_dock(obs)
            return self._to_point(x, y, pose.yaw, tx, ty)
        nx, ny = self._nest
        d2 = (nx - x) ** 2 + (ny - y) ** 2
        if not self._carrying and d2 < self._nest_r2:
            self._at_nest(obs, delivered=False)  # gave up; no messages on this path
            return self._departing(obs, steering)
        if d2 < self._arrival2 or not steering:
            return _IDLE  # at the centre, waiting for the drop (or the avoidance drives)
        if self._rim and (not self._carrying or self._rim_carriers):  # a blind leg to the centre: across the perimeter
            k = self._rim / math.sqrt(d2)
            return self._to_point(x, y, pose.yaw, nx + (x - nx) * k, ny + (y - ny) * k)
        return self._to_point(x, y, pose.yaw, nx, ny)

    # ------------------------------------------------------------------ events

    def _found_resource(self, obs: Observation) -> None:
        """Record the site and the local density c, then head home (H&M Alg. 1)."""
        # Plain floats: the site travels in a PheromoneMessage, whose repr orders the mailbox;
        # a numpy scalar would print differently from the float a graph receiver decodes.
        self._site = (float(obs.pose.x), float(obs.pose.y))
        self._site_count = len(obs.sensed.resources) + self._count_find
        self._state = CpfaState.RETURNING

    def _at_nest(self, obs: Observation, delivered: bool) -> tuple[object, ...]:
        """Lay pheromone, then choose site fidelity, a waypoint or a random site (H&M Alg. 1)."""
        out: tuple[object, ...] = ()
        site = self._site
        self._site = None
        self._state = CpfaState.DEPARTING
        if delivered and site is not None:
            c = self._site_count
            if self._random() < poisson_cdf(c, self._lambda_lp):
                message = PheromoneMessage(int(obs.stamp_ns), site[0], site[1])
                out = (message,)
                self._pheromones.append((message.stamp_ns, site[0], site[1]))
                self._own_unechoed.add(message)
            if self._random() < poisson_cdf(c, self._lambda_sf):
                self._target = site
                self._mode = SearchMode.SITE_FIDELITY
                return out
        waypoint = self._choose_pheromone(obs.stamp_ns)
        if waypoint is not None:
            self._target = waypoint
            self._mode = SearchMode.PHEROMONE
        else:
            self._target = self._random_site()
            self._mode = SearchMode.UNINFORMED
        return out

    def _random_site(self) -> tuple[float, float]:
        """Uniform in the arena inside the wall margin, redrawn if it falls by the nest."""
        b = self._bound
        uniform = self._rng.uniform
        nx, ny = self._nest
        x = y = 0.0
        for _ in range(_SITE_REDRAWS):
            x = float(uniform(-b, b))
            y = float(uniform(-b, b))
            if (x - nx) ** 2 + (y - ny) ** 2 > self._site_clearance2:
                break
        return (x, y)

    # ------------------------------------------------------------------ pheromones

    def _strength(self, stamp_ns: int, now_ns: int) -> float:
        age = (now_ns - stamp_ns) / NS_PER_S
        return math.exp(-self._lambda_pd * age) if age > 0.0 else 1.0

    def _receive(self, pheromones: tuple[PheromoneMessage, ...], now_ns: int) -> None:
        changed = False
        for message in pheromones:
            if message in self._own_unechoed:
                self._own_unechoed.discard(message)
                continue
            self._pheromones.append((message.stamp_ns, message.x, message.y))
            changed = True
        if changed:
            self._forget(now_ns)

    def _forget(self, now_ns: int) -> None:
        """Drop waypoints whose strength fell below the threshold."""
        threshold = self._threshold
        self._pheromones = [
            p for p in self._pheromones if self._strength(p[0], now_ns) >= threshold
        ]
        if self._own_unechoed:
            self._own_unechoed = {
                m for m in self._own_unechoed if self._strength(m.stamp_ns, now_ns) >= threshold
            }

    def _choose_pheromone(self, now_ns: int) -> tuple[float, float] | None:
        """A waypoint drawn with probability proportional to its decayed strength."""
        self._forget(now_ns)
        if not self._pheromones:
            return None
        weights = [self._strength(p[0], now_ns) for p in self._pheromones]
        u = self._random() * sum(weights)
        for weight, (_, x, y) in zip(weights, self._pheromones):
            if u < weight:
                return (x, y)
            u -= weight
        _, x, y = self._pheromones[-1]  # float round-off at the top end
        return (x, y)

"""K-Team's Khepera III: body and speed limits from K-Team's documentation.

- Body: 130 mm across, 70 mm high, 690 g (K-Team, Khepera III user manual, sec. 3.1, and data
  sheet).
- Speed: "The maximum reachable speed is 48'000 (= 333 mm/s) in open loop, and 43'000
  (= 298 mm/s) in regulation mode" (K-Team, Khepera III user manual ver. 2.2, sec. 3.2.1 *Speed*,
  with Kspeed = 144.01 speed units per mm/s). A robot driven by wheel velocities, as the caging
  paper's CoppeliaSim robots are, runs in regulation (speed control) mode: 0.298 m/s.
- Wheel base 88.5 mm (Georgia Tech's Sim.I.am Khepera III model, ``K3_WHEEL_BASE_LENGTH``; the
  user manual gives no axle length), so turning in place with both wheels at the speed limit is
  2 x 0.298 / 0.0885 = 6.73 rad/s.
- The nine infra-red proximity sensors (sec. 3.3) are `swarm_sim.scenario.ProximityConfig`'s
  defaults already.
"""

from __future__ import annotations

DIAMETER = 0.13
"""[m]"""
HEIGHT = 0.07
"""[m]"""
MASS = 0.69
"""[kg]"""
MAX_SPEED = 0.298
"""[m/s] in regulation mode (43'000 speed units / 144.01)."""
WHEEL_BASE = 0.0885
"""[m] between the wheels (Sim.I.am)."""
MAX_TURN_RATE = 2.0 * MAX_SPEED / WHEEL_BASE
"""[rad/s] turning in place at the speed limit."""

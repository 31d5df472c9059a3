"""The ARGoS foot-bot: body, wheels and sensors, as ARGoS models them.

Every value from ilpincy/argos3 (``src/plugins/robots/foot-bot/simulator/``):

- body: ``footbot_entity.cpp`` BODY_RADIUS = 0.085036758 m, BODY_HEIGHT = 0.146899733 m,
  INTERWHEEL_DISTANCE = 0.14 m; mass 1.6 kg (``dynamics2d_footbot_model.cpp``, ``m_fMass(1.6f)``).
- proximity ring: 24 sensors on the body's rim (PROXIMITY_SENSOR_RING_RADIUS = BODY_RADIUS), the
  first at PROXIMITY_SENSOR_RING_START_ANGLE = pi/24 (7.5 deg) counter-clockwise from the heading,
  one every 15 deg, each a ray of PROXIMITY_SENSOR_RING_RANGE = 0.1 m pointing outward;
  a sensor reads 1 below 0.009889556 m and 0.0100527 / (d + 0.000163144) beyond, d the distance
  from the sensor to what its ray hits, 0 when nothing is within range
  (``footbot_proximity_default_sensor.cpp``, ``CProximitySensorImpl::CalculateReading``).
- light sensors: the same ring of 24 (``footbot_entity.cpp``); the ``rot_z_only`` light sensor
  (``footbot_light_rotzonly_sensor.cpp``) sees every light whose ray to the robot is not occluded,
  at any distance (its reading falls with distance, but the foraging example only uses the
  direction of the sum: ``CFootBotForaging::CalculateVectorToLight``).
- motor ground sensors: four, at (+-0.063, +-0.0116) m in the body frame (``footbot_entity.cpp``,
  the grayscale ground sensors), 0.0641 m from the centre; readings 0-3 at (0.063, 0.0116),
  (-0.063, 0.0116), (-0.063, -0.0116), (0.063, -0.0116) m
  (``control_interface/ci_footbot_motor_ground_sensor.cpp``).

Here the ring is the scan: 24 rays over 345 deg (a scan that is not a full circle puts its rays on
both edges, ``fov / (rays - 1)`` = 15 deg apart from -172.5 deg), i.e. the foot-bot's sensor
directions 7.5 + 15 k deg, in another order.
"""

from __future__ import annotations

import math

import numpy as np

BODY_RADIUS = 0.085036758
"""[m] ``footbot_entity.cpp``."""
BODY_HEIGHT = 0.146899733
"""[m] ``footbot_entity.cpp``."""
INTERWHEEL_DISTANCE = 0.14
"""[m] between the wheels' contact points (``footbot_entity.cpp``)."""
MASS = 1.6
"""[kg] ``dynamics2d_footbot_model.cpp``."""
RING_SENSORS = 24
RING_RANGE = 0.1
"""[m] beyond the body, along each sensor's ray."""
RING_FOV = math.radians(345.0)
"""The scan's field of view that puts its 24 rays on the foot-bot's sensor directions [rad]."""
MOTOR_GROUND_SENSORS = ((0.063, 0.0116), (-0.063, 0.0116), (-0.063, -0.0116), (0.063, -0.0116))
"""[m, body frame, x ahead, y left] the motor ground sensors, in the order of their readings."""
GROUND_SENSOR_OFFSET = math.hypot(*MOTOR_GROUND_SENSORS[0])
"""[m] from the centre to each motor ground sensor."""
_NEAR = 0.009889556
_A = 0.0100527
_B = 0.000163144


def ring_reading(d: np.ndarray) -> np.ndarray:
    """The foot-bot proximity sensor's reading for hits `d` [m] from the sensor (d within range)."""
    with np.errstate(divide="ignore"):
        return np.where(d < _NEAR, 1.0, _A / (np.maximum(d, 0.0) + _B))


def ring_value(d: float) -> float:
    """`ring_reading` of one hit [m from the sensor], in plain floats (a controller reads its own
    ring every tick: numpy's per-call cost would be most of it)."""
    return 1.0 if d < _NEAR else _A / (max(d, 0.0) + _B)


def wheel_speed_to_turn_rate(wheel: float) -> float:
    """[rad/s] of a foot-bot turning in place with its wheels at +-`wheel` [m/s]."""
    return 2.0 * wheel / INTERWHEEL_DISTANCE

"""Shared test set-up: every ROS-using test runs on loopback and a private domain."""

from __future__ import annotations

import os
import random

# Before anything imports rclpy: loopback only, and a domain no other run on this machine uses.
os.environ["ROS_AUTOMATIC_DISCOVERY_RANGE"] = "LOCALHOST"
os.environ.setdefault("ROS_DOMAIN_ID", str(random.Random(os.getpid()).randint(101, 199)))
os.environ.setdefault("RMW_IMPLEMENTATION", "rmw_fastrtps_cpp")

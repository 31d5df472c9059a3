"""The foraging task's sense (`swarm_sim.world.tasks.foraging.ForagingSense`) on the graph.

| topic | type | field |
|---|---|---|
| ``/<robot>/resources`` | geometry_msgs/msg/PoseArray (`resources` codec) | resources within the detection radius, nearest first |
| ``/<robot>/gripper`` | sensor_msgs/msg/JointState (`gripper` codec) | carrying |
"""

from __future__ import annotations

from swarm_msgs_py import gripper, resources, topics
from swarm_msgs_py.sensing import SenseTopic, Sensing
from swarm_sim.world.tasks.foraging import ForagingSense

SENSING = Sensing(ForagingSense, (
    SenseTopic(topics.RESOURCES, resources.TYPE_NAME, "resources",
               resources.encode_resources, resources.decode_resources),
    SenseTopic(topics.GRIPPER, gripper.TYPE_NAME, "carrying",
               gripper.encode_gripper, gripper.decode_gripper),
))

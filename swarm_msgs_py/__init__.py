"""swarm_msgs_py: the single place where a core type (`swarm_sim.types`) meets a ROS message.

Only standard common_interfaces types travel, so a stock Jazzy ``ros2 topic echo`` and any
MCAP viewer read every topic. The hot codecs write and read CDR bytes directly with `struct`
(rclpy publishes `bytes`; ``raw=True`` subscriptions hand us bytes) and import no ROS package,
so bag analysis decodes without ROS. Only `markers` and `qos` import rclpy.

Stamps are integer sim-time nanoseconds (``header.stamp`` = the tick). Every decoder raises
`CodecError` (a ValueError naming the ROS type) on malformed or truncated bytes. Each codec
module's docstring gives its field-by-field mapping.

TOPIC MAP (robot topics are relative names under the robot's namespace ``/<robot>``)

====================  ===================================  ================  ======================
topic                 type                                 from -> to        core value (codec)
====================  ===================================  ================  ======================
/clock                rosgraph_msgs/msg/Clock              world -> all      stamp_ns (`clock`)
/<robot>/odom         nav_msgs/msg/Odometry                world -> robot    Pose2D, v, w
                                                                             (`odometry`)
/<robot>/scan         sensor_msgs/msg/LaserScan            world -> robot    float32 ranges
                                                                             (`scan`)
/<robot>/resources    geometry_msgs/msg/PoseArray          world -> robot    detected (x, y)
                                                                             (`resources`)
/<robot>/gripper      sensor_msgs/msg/JointState           world -> robot    carrying (`gripper`)
/<robot>/cmd_vel      geometry_msgs/msg/TwistStamped       robot -> world    linear, angular;
                                                                             stamp = tick answered
                                                                             (`twist`)
/<robot>/status       diagnostic_msgs/msg/DiagnosticArray  robot -> bag      BehaviourStatus
                                                                             (`diagnostics`)
/world/events         diagnostic_msgs/msg/DiagnosticArray  world -> all      PickupEvent/DropEvent
                                                                             (`diagnostics`)
/world/robot_stats    diagnostic_msgs/msg/DiagnosticArray  world -> bag      {robot: RobotStats}
                                                                             (`diagnostics`)
/nest/pheromones      geometry_msgs/msg/PointStamped       robot -> robots   PheromoneMessage
                                                                             (`pheromone`)
/world/markers        visualization_msgs/msg/MarkerArray   world -> RViz     scenario + state
                                                                             (`markers`)
/center/reports       diagnostic_msgs/msg/DiagnosticArray  robot -> center   ProgressReport
                                                                             (`center_protocol`)
/center/assignments   diagnostic_msgs/msg/DiagnosticArray  center -> robots  RegionAssignment
                                                                             (`center_protocol`)
/center/state         diagnostic_msgs/msg/DiagnosticArray  center -> all     regions' walkers and
                                                                             progress (`server_state`)
/center/markers       visualization_msgs/msg/MarkerArray   center -> RViz    regions, paths
/depot/reports        diagnostic_msgs/msg/DiagnosticArray  robot -> depot    DepotReport
                                                                             (`depot_protocol`)
/depot/grants         diagnostic_msgs/msg/DiagnosticArray  depot -> robots   DepotGrant (`depot_protocol`)
/depot/state          diagnostic_msgs/msg/DiagnosticArray  depot -> all      queues and docks
                                                                             (`server_state`)
/depot/markers        visualization_msgs/msg/MarkerArray   depot -> RViz     lines, docks, slots
/radio                diagnostic_msgs/msg/DiagnosticArray  robot -> robots   RadioQuery/RadioReply,
                                                                             kept within range
                                                                             (`depot_protocol`)
/lockstep/ack         std_msgs/msg/Header                  server -> world   tick done (`ack`)
====================  ===================================  ================  ======================

Frames: ``world`` for poses, resources, pheromones and markers; ``<robot>/base_link`` for the
scan and the command (odometry: frame ``world``, child ``<robot>/base_link``).

QoS (`qos`): observations, commands, /clock and acks use SENSOR_LOCKSTEP (best effort, keep-last 10;
the lockstep barrier re-sends what was lost);
markers, robot stats and assignment/state topics STATE_LATCHED (reliable, transient-local,
depth 1); events, status and pheromones EVENTS (reliable, keep-last 1000).
Names and types as data: `topics`. A server's state and markers topics, and the run-trace
series read off what it publishes, are declared with its registry record (`server_outputs`).
"""

from swarm_msgs_py.cdr import CodecError

__all__ = ["CodecError"]

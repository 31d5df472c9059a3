"""swarm_sim: the ROS-free world core (pybullet), the scenario, recording and analysis,
plus the thin world node that puts the core on the ROS graph."""

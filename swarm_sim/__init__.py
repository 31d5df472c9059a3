"""swarm_sim: the ROS-free core (the scenario, the registry and its records, the pybullet world,
the batch runner, recording and the analysis of runs, the servers' output declarations), on the
wire vocabulary of `swarm_msgs_py`; above it the ROS edge, the one folder `swarm_sim.nodes`."""

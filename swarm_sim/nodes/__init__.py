"""The world's and the servers' ROS nodes: thin adapters around the ROS-free cores."""

"""The ROS edge: the world, server, recorder and controller nodes with their QoS, executor,
parameters and markers, thin adapters around the ROS-free core; the only modules that import
rclpy or a message package (`test/test_layout.py` checks the folder)."""

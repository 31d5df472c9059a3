"""launch_py: entrypoints that start the node graph (`swarm-run`) without ros2launch, the
loopback-only DDS set-up, and `*.launch.py` files for users with a full ROS 2 install."""

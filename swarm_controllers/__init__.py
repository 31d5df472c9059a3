"""swarm_controllers: the ROS-free robot behaviours (CPFA baseline and the papers' methods),
scan-based obstacle avoidance and steering helpers, plus the thin controller node that puts
one behaviour per robot on the ROS graph."""

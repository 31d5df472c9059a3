"""The robot models' motion layers (`swarm_controllers.motion.Drive`), one module per authors' controller.

- `stop_turn_go`: the CPFA lineage's ``BaseController`` (the queue and spiral papers' foot-bots);
- `wheel_turning`: the ARGoS foraging example's ``SetWheelSpeedsFromVector`` and ``diffusion``
  (the DRTM paper's foot-bots);
- `ring`: the proximity ring as a controller reads it from its scan.

The generic robot's (and the Khepera III's) is `swarm_controllers.motion.ContinuousDrive`.
"""

"""The core imports and runs with rclpy and every *_msgs package unavailable."""

from __future__ import annotations

import subprocess
import sys
import textwrap

CORE_MODULES = [
    "swarm_sim.types", "swarm_sim.scenario", "swarm_sim.geometry", "swarm_sim.messaging",
    "swarm_sim.world.raycast", "swarm_sim.world.resources", "swarm_sim.world", "swarm_sim.analysis.metrics",
    "swarm_sim.bag", "swarm_sim.batch", "swarm_sim.analysis.replay", "swarm_sim.analysis.plots", "swarm_sim.analysis.cli",
    "swarm_controllers.api", "swarm_controllers.motion", "swarm_controllers.avoidance",
    "swarm_controllers.cpfa", "swarm_controllers.ddsa", "swarm_controllers.mdbsa",
    "swarm_controllers.queueing", "swarm_controllers.spiral", "swarm_controllers.center",
    "swarm_sim.protocol", "swarm_sim.compare", "swarm_sim.compare.sweep", "swarm_sim.compare.stats",
    "swarm_sim.compare.report", "swarm_sim.compare.comparison", "swarm_sim.compare.queue_paper",
    "swarm_sim.compare.spiral_paper", "swarm_sim.compare.cli",
    "depot_manager.geometry", "depot_manager.admission", "depot_manager.server",
    "swarm_msgs_py.protocol", "swarm_msgs_py.server_state", "swarm_msgs_py.ack",
    "swarm_msgs_py.cdr", "swarm_msgs_py.clock", "swarm_msgs_py.odometry", "swarm_msgs_py.scan",
    "swarm_msgs_py.resources", "swarm_msgs_py.gripper", "swarm_msgs_py.twist",
    "swarm_msgs_py.pheromone", "swarm_msgs_py.diagnostics", "swarm_msgs_py.topics",
]

BLOCKER = textwrap.dedent(
    """
    import importlib.abc, sys

    class Block(importlib.abc.MetaPathFinder):
        def find_spec(self, name, path=None, target=None):
            root = name.split(".")[0]
            if root in ("rclpy", "rosidl_runtime_py") or root.endswith("_msgs") or root == "rcl_interfaces":
                raise ImportError(f"blocked for this test: {name}")
            return None

    sys.meta_path.insert(0, Block())
    """
)


def test_core_modules_import_without_ros():
    code = BLOCKER + textwrap.dedent(
        f"""
        import importlib
        for name in {CORE_MODULES!r}:
            importlib.import_module(name)
        # and the core actually runs: a few ticks of the batch runner
        from swarm_sim.batch import run_batch
        from swarm_sim.scenario import load_scenario
        run = run_batch(load_scenario("cpfa", ["robots.count=4", "sim.duration=1.0"]))
        assert run.trace.sim_seconds == 1.0, run.trace.sim_seconds
        for name in ("queue_qmt", "mdbsa_d"):  # with the depot manager / center cores
            run = run_batch(load_scenario(name, ["robots.count=4", "sim.duration=1.0"]))
            assert run.trace.sim_seconds == 1.0, (name, run.trace.sim_seconds)
        print("ok")
        """
    )
    result = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert result.returncode == 0, result.stderr
    assert result.stdout.strip().endswith("ok")


def test_blocker_really_blocks():
    code = BLOCKER + "import rclpy\n"
    result = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=60)
    assert result.returncode != 0 and "blocked for this test" in result.stderr

"""The core imports and runs with rclpy and every *_msgs package unavailable."""

from __future__ import annotations

import subprocess
import sys
import textwrap

ROS_ADAPTERS = ("swarm_msgs_py.markers", "swarm_msgs_py.qos", "swarm_msgs_py.executor", "swarm_msgs_py.params",
                "swarm_sim.nodes.world_node", "swarm_sim.nodes.server_node", "swarm_sim.nodes.recorder",
                "swarm_sim.nodes.endpoint", "swarm_sim.nodes.world_loop", "swarm_sim.nodes.world_outputs",
                "swarm_sim.nodes.world_recording", "swarm_sim.nodes.peer_relay", "swarm_sim.nodes.status_watch",
                "swarm_sim.nodes.run_watch")
"""The only modules allowed to import rclpy or message packages: the nodes (also every
``*_node`` module) and the codecs that build rclpy message objects."""


def core_modules() -> list[str]:
    """Every module of our packages that is not a ROS adapter: found by walking the packages,
    so a new core module is checked without being listed."""
    import pkgutil

    import depot_manager
    import swarm_controllers
    import swarm_msgs_py
    import swarm_sim

    out = []
    for package in (swarm_sim, swarm_controllers, depot_manager, swarm_msgs_py):
        for info in pkgutil.walk_packages(package.__path__, package.__name__ + "."):
            if info.name not in ROS_ADAPTERS and not info.name.rpartition(".")[2].endswith("node"):
                out.append(info.name)
    return out


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
        for name in {core_modules()!r}:
            importlib.import_module(name)
        # and the core actually runs: a few ticks of the batch runner
        from swarm_sim.batch import run_batch
        from swarm_sim.scenario import load_scenario
        run = run_batch(load_scenario("cpfa", ["robots.count=4", "sim.duration=1.0"]))
        assert run.trace.sim_seconds == 1.0, run.trace.sim_seconds
        for name in ("queue_qmt", "mdbsa_d"):  # with the depot manager / center cores (every
            # registered algorithm is also checked by test_conformance)
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

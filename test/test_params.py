"""`ros2 param list/get` on every node: the controller (from its first tick on), depot-manager and
center nodes serve the standard parameter services (as the world does). A client node asks them
over DDS what ``ros2 param list`` and ``ros2 param get`` ask: ListParameters and GetParameters."""

from __future__ import annotations

import pytest
from rclpy.executors import SingleThreadedExecutor
from rclpy.node import Node
from rclpy.parameter_client import AsyncParameterClient

from depot_manager.node import DepotManagerNode
from swarm_controllers.center_node import CenterNode
from swarm_controllers.controller_node import ControllerConfig, ControllerNode
from swarm_msgs_py import topics
from swarm_msgs_py.qos import SENSOR_LOCKSTEP
from swarm_sim.nodes.server_node import ServerNodeConfig
from test_nodes import SMALL, _observation_bytes


def _spin_until(executor, future, timeout=20.0):
    executor.spin_until_future_complete(future, timeout_sec=timeout)
    assert future.done(), "no answer from the parameter service"
    return future.result()


def _first_tick(node: ControllerNode, peer: Node, executor) -> None:
    """Feed the controller one tick's observations (its parameter services start then)."""
    pubs = {n: peer.create_publisher(topics.type_of(n), f"/{node.robot}/{n}", SENSOR_LOCKSTEP)
            for n in (topics.ODOM, topics.SCAN, topics.RESOURCES, topics.GRIPPER)}
    for _ in range(200):
        executor.spin_once(timeout_sec=0.02)
        if all(p.get_subscription_count() for p in pubs.values()):
            break
    for name, data in _observation_bytes(node.scenario, node.robot, 0).items():
        pubs[name].publish(data)
    for _ in range(200):
        executor.spin_once(timeout_sec=0.02)
        if node._answered_stamp == 0:
            return
    raise AssertionError("the controller did not tick")


@pytest.mark.parametrize("make, name, seed", [
    (lambda ctx: ControllerNode("robot_1", ControllerConfig("cpfa", SMALL, 7), context=ctx),
     "/robot_1/controller", 7),
    (lambda ctx: DepotManagerNode(ServerNodeConfig("queue_qmt", ("robots.count=2",), 5), context=ctx),
     "/depot_manager", 5),
    (lambda ctx: CenterNode(ServerNodeConfig("mdbsa_d", ("robots.count=2",), 3), context=ctx), "/center", 3),
], ids=["controller", "depot_manager", "center"])
def test_param_list_and_get_answer_on_every_node(context, make, name, seed):
    node = make(context)
    client_node = Node("ros2cli_param", context=context)
    executor = SingleThreadedExecutor(context=context)
    executor.add_node(node)
    executor.add_node(client_node)
    try:
        client = AsyncParameterClient(client_node, name)
        if isinstance(node, ControllerNode):
            assert not client.wait_for_services(timeout_sec=1.0)  # not while the run starts up
            _first_tick(node, client_node, executor)
        assert client.wait_for_services(timeout_sec=20.0), f"{name}: no parameter services"
        listed = _spin_until(executor, client.list_parameters()).result.names
        assert {"scenario", "overrides", "seed", "use_sim_time"} <= set(listed), listed
        values = _spin_until(executor, client.get_parameters(["seed", "scenario", "use_sim_time"])).values
        assert values[0].integer_value == seed
        assert values[1].string_value in ("cpfa", "queue_qmt", "mdbsa_d")
        assert values[2].bool_value is True
    finally:
        executor.shutdown()
        node.destroy_node()
        client_node.destroy_node()

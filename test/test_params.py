"""`ros2 param list/get` on every node: the controller node and the server node (as the depot
manager and as the center) serve the standard parameter services (as the world does). A client node asks them
over DDS what ``ros2 param list`` and ``ros2 param get`` ask: ListParameters and GetParameters."""

from __future__ import annotations

import pytest
from rclpy.executors import SingleThreadedExecutor
from rclpy.node import Node
from rclpy.parameter import Parameter
from rclpy.parameter_client import AsyncParameterClient
from test_nodes import SMALL

from swarm_sim.nodes.controller_node import ControllerConfig, ControllerNode
from swarm_sim.nodes.server_node import ServerNode, ServerNodeConfig


def _spin_until(executor, future, timeout=20.0):
    executor.spin_until_future_complete(future, timeout_sec=timeout)
    assert future.done(), "no answer from the parameter service"
    return future.result()


@pytest.mark.parametrize("make, name, seed", [
    (lambda ctx: ControllerNode("robot_1", ControllerConfig("cpfa", SMALL, 7), context=ctx),
     "/robot_1/controller", 7),
    (lambda ctx: ServerNode("depot", ServerNodeConfig("queue_qmt", ("robots.count=2",), 5), context=ctx),
     "/depot_manager", 5),
    (lambda ctx: ServerNode("center", ServerNodeConfig("mdbsa_d", ("robots.count=2",), 3), context=ctx),
     "/center", 3),
], ids=["controller", "depot_manager", "center"])
def test_param_list_and_get_answer_on_every_node(context, make, name, seed):
    node = make(context)
    client_node = Node("ros2cli_param", context=context)
    executor = SingleThreadedExecutor(context=context)
    executor.add_node(node)
    executor.add_node(client_node)
    try:
        client = AsyncParameterClient(client_node, name)
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


def test_a_controller_without_parameter_services_still_holds_its_parameters(context):
    """``--no-parameter-services`` (issue 27: fewer endpoints at scale): no service endpoints, the
    parameters declared all the same."""
    with_services = ControllerNode("robot_0", ControllerConfig("cpfa", SMALL, 7), context=context)
    without = ControllerNode("robot_1", ControllerConfig("cpfa", SMALL, 7), context=context, parameter_services=False)
    try:
        services = lambda node: {n for n, _ in node.get_service_names_and_types_by_node(node.get_name(),  # noqa: E731
                                                                                       node.get_namespace())}
        assert "/robot_0/controller/list_parameters" in services(with_services)
        assert not any("parameter" in s for s in services(without))
        assert without.get_parameter("seed").value == 7
    finally:
        with_services.destroy_node()
        without.destroy_node()


def test_a_controller_refuses_ros2_param_set_and_has_no_parameter_events_writer(context):
    """A robot reads its parameters once, when it is made: ``ros2 param set`` is refused (read-only)
    rather than taking a value that would change nothing; with nothing ever to announce, the node
    has no ``/parameter_events`` writer, one DDS endpoint a robot fewer (issue 40, lever 4). The
    server nodes keep theirs."""
    node = ControllerNode("robot_2", ControllerConfig("cpfa", SMALL, 7), context=context)
    server = ServerNode("depot", ServerNodeConfig("queue_qmt", ("robots.count=2",), 5), context=context)
    client_node = Node("ros2cli_param", context=context)
    executor = SingleThreadedExecutor(context=context)
    for n in (node, server, client_node):
        executor.add_node(n)
    try:
        client = AsyncParameterClient(client_node, "/robot_2/controller")
        assert client.wait_for_services(timeout_sec=20.0)
        result = _spin_until(executor, client.set_parameters([Parameter("seed", value=9)])).results[0]
        assert not result.successful and "read-only" in result.reason, result
        assert _spin_until(executor, client.get_parameters(["seed"])).values[0].integer_value == 7
        writes = lambda n: {t for t, _ in client_node.get_publisher_names_and_types_by_node(  # noqa: E731
            n.get_name(), n.get_namespace())}
        assert "/robot_2/status" in writes(node) and "/parameter_events" not in writes(node)
        assert "/parameter_events" in writes(server)
    finally:
        executor.shutdown()
        for n in (node, server, client_node):
            n.destroy_node()

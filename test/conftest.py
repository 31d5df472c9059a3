"""Shared test set-up: every ROS-using test runs on loopback and a private domain, and the test
plug-ins of this tree are the ones imported."""

from __future__ import annotations

import fcntl
import os
import sys
import tempfile
from pathlib import Path

# The test plug-ins (test/plugins/*) are found through the entry points of their installed copy
# (scripts/test installs them editable); the modules those entry points name are imported from
# this tree, in this process and in the processes the tests start, even when the installed copy
# is another checkout's (a git worktree sharing one virtual environment).
_PLUGINS = [str(p) for p in sorted((Path(__file__).parent / "plugins").iterdir()) if (p / "pyproject.toml").exists()]
sys.path[:0] = _PLUGINS
os.environ["PYTHONPATH"] = os.pathsep.join([*_PLUGINS, *filter(None, [os.environ.get("PYTHONPATH")])])

# Before anything imports rclpy: loopback only (sockets bound to 127.0.0.1, launch_py.dds), and
# a domain reserved for this session (`launch_py.dds.reserve_free_domain`: the lock is held while
# pytest lives), so concurrent suites and `--domain-id auto` runs never pick it too. A pytest-xdist
# worker is a session of its own: it inherits the controller's ROS_DOMAIN_ID, so it reserves a
# domain of its own (two workers on one domain would hear each other's runs, and the second run
# on it would refuse to start).
from launch_py.dds import apply_to_current_process, loopback_env, reserve_free_domain  # noqa: E402

if os.environ.get("PYTEST_XDIST_WORKER") or "ROS_DOMAIN_ID" not in os.environ:
    _DOMAIN, _RESERVATION = reserve_free_domain()
    os.environ["ROS_DOMAIN_ID"] = str(_DOMAIN)

apply_to_current_process(loopback_env(int(os.environ["ROS_DOMAIN_ID"]), processes=2))

# Hypothesis times its own input generation; on a loaded 2-core machine (CI, parallel runs) the
# first draw of a strategy can take seconds, which says nothing about the code under test.
from hypothesis import HealthCheck, settings  # noqa: E402

settings.register_profile("swarmforage", deadline=None, suppress_health_check=[HealthCheck.too_slow])
settings.load_profile("swarmforage")


import pytest  # noqa: E402


@pytest.fixture
def context():
    """A fresh rclpy context for a node test (node tests never share the global one)."""
    import rclpy

    ctx = rclpy.Context()
    rclpy.init(context=ctx)
    yield ctx
    ctx.try_shutdown()


_GRAPH_WORDS = ("graph_helpers", "graph_bag", "launch_py.run", "launch_py.hosts", "rclpy")
"""A test module naming one of these starts DDS participants or the real graph."""


def pytest_configure(config) -> None:
    config.addinivalue_line("markers", "graph: starts DDS participants or the real graph (swarm-run, nodes); "
                                       "`scripts/test -m 'not graph'` runs the fast core")
    config.addinivalue_line("markers", "network: the network stage (test/network: hosts as network namespaces, root)")
    config.addinivalue_line("markers", "slow: a test of more than ~20 s on an idle 2-core machine")
    config.addinivalue_line("markers", "alone: under pytest-xdist, never beside another worker's graph test")
    if config.getoption("dist", "no") == "loadgroup" and pytest.version_tuple[:2] >= (9, 2):
        # pytest 9.2's node ids are structured; pytest-xdist 3.8 still renames `_nodeid` to mark a
        # group, so every test goes anywhere and each worker makes a module's shared run
        # (pytest-xdist#1386, open). setup.py asks for pytest<9.2.
        raise pytest.UsageError(f"pytest {pytest.__version__}: pytest-xdist's --dist loadgroup does not group "
                                "tests with it (pytest-xdist#1386); install pytest<9.2 (scripts/setup does)")


def pytest_collection_modifyitems(config, items) -> None:
    """`graph` and `network` by module (its text names the graph or it lies in test/network)."""
    graph: dict[str, bool] = {}
    for item in items:
        path = Path(str(item.fspath))
        if "network" in path.parts:
            item.add_marker(pytest.mark.network)
        if str(path) not in graph:
            text = path.read_text(encoding="utf-8") if path.suffix == ".py" else ""
            graph[str(path)] = any(word in text for word in _GRAPH_WORDS)
        if graph[str(path)]:
            item.add_marker(pytest.mark.graph)
    if os.environ.get("PYTEST_XDIST_WORKER"):
        # Under pytest-xdist (scripts/test), the longest tests first: the `slow` ones, then the
        # other graph runs, then the rest, so that no worker is left with a long test at the end
        # while the other has nothing to do; the `alone` ones last, when the other worker is on
        # tests that start no graph. (Each worker collects in this same order.)
        items.sort(key=lambda item: 3 if item.get_closest_marker("alone") else 0 if item.get_closest_marker("slow")
                   else 1 if item.get_closest_marker("graph") else 2)


@pytest.fixture(autouse=True)
def _alone(request):
    """Under pytest-xdist, an `alone` test (a hundred DDS processes) never runs beside another
    worker's graph test: it holds this session's lock file exclusively, a graph test holds it
    shared. (A CPFA conformance run started during the 112-robot run's start-up on the other
    worker once had its four controllers never answer; the cause is not known.)"""
    run = os.environ.get("PYTEST_XDIST_TESTRUNUID")
    kind = fcntl.LOCK_EX if request.node.get_closest_marker("alone") else fcntl.LOCK_SH
    if run is None or (kind == fcntl.LOCK_SH and request.node.get_closest_marker("graph") is None):
        yield
        return
    with open(Path(tempfile.gettempdir()) / f"swarmforage-tests-{run}.lock", "a") as lock:
        fcntl.flock(lock, kind)  # waits for the other worker's test
        yield

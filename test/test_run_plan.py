"""What swarm-run makes of its options before it starts anything (`launch_py.run.plan_run`,
`commands`): pure, no process, no DDS."""

from __future__ import annotations

from pathlib import Path

import pytest

from launch_py.run import PARAMETER_SERVICES_UP_TO, Refused, build_parser, commands, plan_run, scenario_args


def _controller_commands(argv: list[str]) -> list[list[str]]:
    args = build_parser().parse_args(argv)
    plan = plan_run(args)
    common = scenario_args(args, plan.scenario)
    return [cmd for _, cmd in commands(args, plan, Path("bag"), common, common).controllers]


@pytest.mark.parametrize("robots, flags, served", [
    (112, [], True),  # the papers' largest swarm: ros2 param, as ever
    (PARAMETER_SERVICES_UP_TO, [], True),
    (PARAMETER_SERVICES_UP_TO + 1, [], False),  # beyond: the start-up's endpoints
    (PARAMETER_SERVICES_UP_TO + 1, ["--parameter-services"], True),  # asked for: whatever the size
    (16, ["--no-parameter-services"], False),
])
def test_controllers_serve_ros2_param_up_to_the_papers_swarms_unless_told(robots, flags, served):
    cmds = _controller_commands(["--robots", str(robots), "--controller-processes", "2", *flags])
    assert len(cmds) == 2
    for cmd in cmds:
        assert ("--no-parameter-services" not in cmd) is served, cmd


def test_asking_for_and_against_parameter_services_at_once_is_refused(capsys):
    with pytest.raises(SystemExit) as exit_:
        build_parser().parse_args(["--parameter-services", "--no-parameter-services"])
    assert exit_.value.code == 2
    assert "not allowed with argument" in capsys.readouterr().err


def test_publishing_shards_go_to_the_world_count_as_processes_and_no_more_than_the_robots(capsys):
    args = build_parser().parse_args(["--robots", "8", "--controller-processes", "2", "--publish-shards", "3"])
    plan = plan_run(args)
    assert plan.processes == 2 + 1 + 3  # controllers, the world, its shards
    world = commands(args, plan, Path("bag"), [], []).world
    assert world[world.index("--publish-shards") + 1] == "3"
    plain = build_parser().parse_args(["--robots", "8"])
    assert "--publish-shards" not in commands(plain, plan_run(plain), Path("bag"), [], []).world  # today's world
    with pytest.raises(Refused, match="--publish-shards 9: more shards than the run's 8 robots"):
        plan_run(build_parser().parse_args(["--robots", "8", "--publish-shards", "9"]))
    with pytest.raises(SystemExit) as exit_:
        build_parser().parse_args(["--publish-shards", "-1"])
    assert exit_.value.code == 2
    assert "--publish-shards: -1 is outside [0, inf]" in capsys.readouterr().err

"""What swarm-run makes of its options before it starts anything (`launch_py.run.plan_run`,
`commands`): pure, no process, no DDS."""

from __future__ import annotations

from pathlib import Path

import pytest

from launch_py.run import PARAMETER_SERVICES_UP_TO, build_parser, commands, plan_run, scenario_args


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

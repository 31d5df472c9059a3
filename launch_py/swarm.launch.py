"""ROS 2 launch file equivalent of `swarm-run`, for users with a full ROS 2 Jazzy install.

    ros2 launch swarmforage swarm.launch.py robots:=16 scenario:=cpfa seed:=0 bag:=bags/run1

Starts the world node (which records the bag), one controller process hosting every robot's
controller node and a server node (``swarm-server --channel ...``) for each server the scenario
needs (console scripts on PATH). `swarm-run` does the same without ros2launch; nothing in the
tests needs this.
"""

from launch import LaunchDescription
from launch.actions import DeclareLaunchArgument, ExecuteProcess, OpaqueFunction
from launch.substitutions import LaunchConfiguration

from swarm_sim import registry
from swarm_sim.scenario import load_scenario


def _nodes(context):
    robots = int(LaunchConfiguration("robots").perform(context))
    scenario = LaunchConfiguration("scenario").perform(context)
    seed = LaunchConfiguration("seed").perform(context)
    bag = LaunchConfiguration("bag").perform(context)
    common = ["--scenario", scenario, "--seed", seed, "--set", f"robots.count={robots}"]
    servers = registry.of(load_scenario(scenario, [f"robots.count={robots}"])).servers
    return [
        *[ExecuteProcess(cmd=["swarm-server", "--channel", spec.channel, *common], output="screen")
          for spec in servers],
        ExecuteProcess(cmd=["swarm-controllers", "--robots",
                            *[f"robot_{i}" for i in range(robots)], *common], output="screen"),
        ExecuteProcess(cmd=["swarm-world", *common, "--bag", bag], output="screen"),
    ]


def generate_launch_description():
    return LaunchDescription([
        DeclareLaunchArgument("robots", default_value="16"),
        DeclareLaunchArgument("scenario", default_value=registry.default_scenario()),
        DeclareLaunchArgument("seed", default_value="0"),
        DeclareLaunchArgument("bag", default_value="bags/launch_run"),
        OpaqueFunction(function=_nodes),
    ])

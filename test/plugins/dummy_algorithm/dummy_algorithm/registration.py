"""The dummy algorithm's registry record, loaded through its ``swarmforage.algorithms`` entry
point: its own behaviour, world task (a beacon, a field of ``/<robot>/sense``), server (a ping
counter), message family (``/dummy/pings``) and metric."""

from swarm_sim.registry import Algorithm, Metric, Panel, ServerSpec, TaskSpec, register, register_task

register_task(TaskSpec(name="beacon", core="dummy_algorithm.task:BeaconTask",
                       sensing="dummy_algorithm.codec:SENSING"))
register(Algorithm(
    name="dummy",
    paper="none: a test of the registry",
    behaviour="dummy_algorithm.behaviour:DummyBehaviour",
    task="beacon",
    servers=(ServerSpec(channel="counter", core="dummy_algorithm.server:CounterServer",
                        family="dummy_algorithm.codec:PINGS", outputs="dummy_algorithm.codec:OUTPUTS"),),
    metrics=(Metric("pings_heard", "dummy_algorithm.server:pings_heard"),),
    panels=(Panel("collision time per robot", "collision time [s]", "collision_time_s_by_robot"),),
))

"""swarmforage: installable with pip (the README's way) or colcon in a ROS 2 Jazzy workspace."""

from glob import glob

from setuptools import find_packages, setup

PACKAGE = "swarmforage"

setup(
    name=PACKAGE,
    version="0.1.0",
    description="Swarm foraging methods on a ROS 2 Jazzy node graph with a pybullet world",
    license="Apache-2.0",
    python_requires=">=3.10",
    packages=find_packages(include=["swarm_sim*", "swarm_controllers*", "swarm_msgs_py*",
                                    "depot_manager*", "launch_py*"]),
    package_data={"swarm_controllers": ["*/scenarios/*.yaml"], "launch_py": ["*.xml", "*.json"]},
    data_files=[
        ("share/ament_index/resource_index/packages", [f"resource/{PACKAGE}"]),
        (f"share/{PACKAGE}", ["package.xml"]),
        (f"share/{PACKAGE}/launch", glob("launch_py/*.launch.py")),
        (f"share/{PACKAGE}/scenarios", glob("swarm_controllers/*/scenarios/*.yaml")),
    ],
    install_requires=[
        "numpy",
        "numba",  # compiled world kernels (swarm_sim.world.jit): the scan, its robot pairs
        "pybullet",
        "pyyaml",
        "mcap",
        "mcap-ros2-support",
        "rosbags",
        "matplotlib",
        "scipy",
        "foxglove-sdk",  # swarm-run --foxglove: the official Foxglove WebSocket server
        "imageio",  # swarm-analyze --video
        "imageio-ffmpeg",  # its ffmpeg (a binary inside the wheel) for .mp4
        "tqdm",  # sweep progress bars
    ],
    extras_require={
        "ros": [
            "ros-jazzy-rclpy",
            "ros-jazzy-common-interfaces",
            "ros-jazzy-rmw-fastrtps-cpp",
        ],
        "dask": ["distributed"],  # sweeps on a Dask cluster (--scheduler, --dask-local)
        # pytest-xdist: `scripts/test` runs the suite on two workers (`-n 2 --dist loadgroup`): one
        # test at a time keeps about one of a 2-core machine's cores busy (7 min; two workers: 4.5).
        # pytest below 9.2: there, xdist's loadgroup silently stops grouping (pytest-xdist#1386, open),
        # and a module's shared run is made once per worker; test/conftest.py refuses that case.
        "test": ["pytest<9.2", "pytest-xdist", "hypothesis", "websockets", "distributed"],
        # The documentation site (mkdocs.yml, docs/): MkDocs, the standard, well-kept static site
        # builder for Markdown; its --strict build is a test (test/test_docs.py).
        "docs": ["mkdocs"],
    },
    entry_points={
        # Every paper registers itself as a third-party plug-in would (swarm_sim.registry).
        "swarmforage.algorithms": [
            "core = swarm_sim.world.tasks.registration",
            "cpfa = swarm_controllers.cpfa.registration",
            "queue = swarm_controllers.queue.registration",
            "spiral = swarm_controllers.spiral.registration",
            "drtm = swarm_controllers.drtm.registration",
            "caging = swarm_controllers.caging.registration",
        ],
        "console_scripts": [
            "swarm-run = launch_py.run:main",
            "swarm-batch = swarm_sim.batch:main",
            "swarm-analyze = swarm_sim.analysis.cli:main",
            "swarm-world = launch_py.hosts:world",
            "swarm-controllers = launch_py.hosts:controllers",
            "swarm-server = launch_py.hosts:server",
            "swarm-compare = swarm_sim.compare.cli:main",
        ],
    },
)

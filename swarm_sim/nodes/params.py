"""Declare a node's parameters once, from a frozen config dataclass.

Each field becomes a ROS parameter with the field's default; the node reads the whole config
back as the dataclass, so there is no declare/get pair per field in any node.
"""

from __future__ import annotations

import dataclasses
from typing import Any, TypeVar

from rcl_interfaces.msg import ParameterDescriptor, ParameterType
from rclpy.node import Node

T = TypeVar("T")


def declare_config(node: Node, cls: type[T], defaults: T | None = None, *, read_only: bool = False) -> T:
    """Declare every field of `cls` as a parameter and return the configured instance;
    `read_only`: ``ros2 param set`` is refused (for a node that reads its parameters only once)."""
    base = defaults if defaults is not None else cls()
    values: dict[str, Any] = {}
    for f in dataclasses.fields(cls):  # type: ignore[arg-type]
        default = getattr(base, f.name)
        declared = list(default) if isinstance(default, tuple) else default
        if isinstance(default, tuple) and not default:
            node.declare_parameter(
                f.name, [""], ParameterDescriptor(type=ParameterType.PARAMETER_STRING_ARRAY, read_only=read_only)
            )
            value = [v for v in node.get_parameter(f.name).value if v]
        else:
            value = node.declare_parameter(f.name, declared, ParameterDescriptor(read_only=read_only)).value
        values[f.name] = tuple(value) if isinstance(default, tuple) else value
    return cls(**values)

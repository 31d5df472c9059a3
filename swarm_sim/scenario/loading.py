"""Loading a scenario: YAML in, overrides applied, frozen dataclasses built, then validated.

`load_scenario` reads a scenario file (`resolve_path`: a name shipped by a registered package, or
a path), applies the CLI's overrides, builds `swarm_sim.scenario.schema.Scenario` from the mapping
and validates it (`swarm_sim.scenario.validation`). Unknown keys and wrong types are refused with
a `ScenarioError` naming the key (``resources.count: expected int, got 'many'``).

The sections that tasks and algorithms declare in their registry records are built here: a
top-level key that is not a field of `Scenario` must name a registered world section
(`swarm_sim.registry.world_sections`), a key under ``controller`` that is not a field of
`ControllerConfig` a registered controller section (`swarm_sim.registry.config_sections`).
Sections the file leaves out are not filled in: ``TheSection.of(scenario)`` gives their defaults.
"""

from __future__ import annotations

import copy
import dataclasses
import math
import re
import sys
import types
import typing
from collections.abc import Callable, Iterable
from pathlib import Path
from typing import Any, Literal, get_args, get_origin

import yaml

from swarm_sim import registry
from swarm_sim.robots import BODY_FIELDS, SENSOR_FIELDS, apply_model
from swarm_sim.scenario.schema import ControllerConfig, Scenario, ScenarioError
from swarm_sim.scenario.validation import validate

MAX_FILE_BYTES = 1 << 20
"""A scenario file larger than this is refused (ours are ~1 KB)."""
MAX_MAGNITUDE = 1e9
"""The largest magnitude a scenario float may have: sizes [m], times [s], speeds, all far below
(a 1e300 speed was accepted silently)."""
MAX_INT = 2**63 - 1
"""The largest magnitude of a scenario int (a seed, a count): what numpy and the codecs hold."""


def _type_name(tp: Any) -> str:
    return getattr(tp, "__name__", None) or str(tp).replace("typing.", "")


_FLOAT_TEXT = re.compile(r"[-+]?(\d+\.?\d*|\.\d+)([eE][-+]?\d+)?")


def _short(value: Any) -> str:
    """`value` for an error line: its repr cut to 40 characters (an int's of up to 4300 digits)."""
    text = repr(value) if not isinstance(value, int) or abs(value) < 10**40 else f"an integer of {len(str(value))} digits"
    return text if len(text) <= 40 else text[:37] + "..."


def _unreadable(exc: BaseException) -> str:
    """Why PyYAML could not build a value (its constructors raise plain ValueErrors)."""
    if isinstance(exc, RecursionError):
        return "nested too deeply"
    if "integer string conversion" in str(exc):
        return f"an integer of more than {sys.get_int_max_str_digits()} digits"
    return str(exc)[:80]


def _convert(value: Any, tp: Any, key: str) -> Any:
    """Convert a YAML value to the annotated type, or raise naming `key`."""
    origin = get_origin(tp)
    if tp is Any:
        return value
    if dataclasses.is_dataclass(tp):
        if not isinstance(value, dict):
            raise ScenarioError(f"{key}: expected a mapping, got {value!r}")
        return _build(tp, value, key)
    if origin is Literal:
        if value not in get_args(tp):
            choices = ", ".join(repr(a) for a in get_args(tp))
            raise ScenarioError(f"{key}: expected one of {choices}, got {value!r}")
        return value
    if origin in (typing.Union, types.UnionType):
        errors = []
        for arg in get_args(tp):
            if arg is type(None):
                if value is None:
                    return None
                continue
            try:
                return _convert(value, arg, key)
            except ScenarioError as exc:
                errors.append(str(exc))
        raise ScenarioError(errors[0] if errors else f"{key}: bad value {value!r}")
    if origin is tuple:
        args = get_args(tp)
        if not isinstance(value, (list, tuple)):
            raise ScenarioError(f"{key}: expected a list, got {value!r}")
        if len(args) == 2 and args[1] is Ellipsis:
            return tuple(_convert(v, args[0], f"{key}[{i}]") for i, v in enumerate(value))
        if len(value) != len(args):
            raise ScenarioError(f"{key}: expected {len(args)} values, got {len(value)}")
        return tuple(_convert(v, a, f"{key}[{i}]") for i, (v, a) in enumerate(zip(value, args)))
    if tp is float:
        if isinstance(value, str) and _FLOAT_TEXT.fullmatch(value.strip()):
            value = float(value)  # YAML 1.1 reads 1e30 (no dot) as a string
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            raise ScenarioError(f"{key}: expected a number, got {value!r}")
        if not math.isfinite(value) or abs(value) > MAX_MAGNITUDE:
            raise ScenarioError(f"{key}: expected a finite number within +-{MAX_MAGNITUDE:g}, got {_short(value)}")
        return float(value)
    if tp is int:
        if isinstance(value, bool) or not isinstance(value, int):
            raise ScenarioError(f"{key}: expected int, got {_short(value)}")
        if abs(value) > MAX_INT:
            raise ScenarioError(f"{key}: expected an integer within +-(2**63 - 1), got {_short(value)}")
        return value
    if tp is bool:
        if not isinstance(value, bool):
            raise ScenarioError(f"{key}: expected true or false, got {value!r}")
        return value
    if tp is str:
        if not isinstance(value, str):
            raise ScenarioError(f"{key}: expected a string, got {value!r}")
        return value
    raise ScenarioError(f"{key}: unsupported type {_type_name(tp)}")


def _build(cls: type, data: dict[str, Any], prefix: str) -> Any:
    if cls is ControllerConfig:
        data = _with_sections(data, prefix, cls, registry.config_sections(), registry.config_section)
    elif cls is Scenario:
        data = _with_sections(data, prefix, cls, registry.world_sections(), registry.world_section)
    hints = typing.get_type_hints(cls)
    names = {f.name for f in dataclasses.fields(cls)}
    unknown = sorted(set(data) - names)
    if unknown:
        where = f"{prefix}." if prefix else ""
        raise ScenarioError(
            f"unknown key {where}{unknown[0]} (known keys: {', '.join(sorted(names))})"
        )
    kwargs = {}
    for name, value in data.items():
        key = f"{prefix}.{name}" if prefix else name
        kwargs[name] = _convert(value, hints[name], key)
    try:
        return cls(**kwargs)
    except TypeError as exc:  # a field without default left out
        raise ScenarioError(f"{prefix or 'scenario'}: {exc}") from None


def _with_sections(
    data: dict[str, Any], prefix: str, cls: type, declared: dict[str, str], section_class: Callable[[str], type],
) -> dict[str, Any]:
    """The mapping of `cls` (`Scenario` or `ControllerConfig`) with the sections built into its
    ``sections``: every key that is not a field of `cls` must name a section in `declared`
    (name -> ``module:Dataclass``), built as `section_class` (name) says."""
    fixed = {f.name for f in dataclasses.fields(cls)} - {"sections"}
    out = {k: v for k, v in data.items() if k in fixed}
    sections = []
    for name in sorted(set(data) - fixed):
        key = f"{prefix}.{name}" if prefix else name
        if name not in declared:
            known = ", ".join(sorted(fixed | set(declared)))
            raise ScenarioError(f"unknown key {key} (known keys: {known})")
        value = data[name] if data[name] is not None else {}
        sections.append((name, _convert(value, section_class(name), key)))
    if sections:
        out["sections"] = tuple(sections)
    return out


def _set_path(data: dict[str, Any], dotted: str, value: Any) -> None:
    parts = dotted.split(".")
    node = data
    for part in parts[:-1]:
        child = node.setdefault(part, {})
        if not isinstance(child, dict):
            raise ScenarioError(f"--set {dotted}: {part} is not a mapping")
        node = child
    node[parts[-1]] = value


def parse_override(text: str) -> tuple[str, Any]:
    """``"robots.count=8"`` -> ``("robots.count", 8)``; the value is parsed as YAML."""
    key, sep, raw = text.partition("=")
    if not sep or not key.strip():
        raise ScenarioError(f"--set {text!r}: expected KEY=VALUE, e.g. robots.count=8")
    try:
        return key.strip(), yaml.safe_load(raw)
    except yaml.YAMLError as exc:
        raise ScenarioError(f"--set {key}: cannot parse value {raw[:40]!r}: {' '.join(str(exc).split())}") from None
    except (ValueError, RecursionError) as exc:  # an int of more than 4300 digits; nesting
        raise ScenarioError(f"--set {key}: cannot parse value {raw[:40]!r}: {_unreadable(exc)}") from None


def resolve_path(name_or_path: str) -> Path:
    """A scenario name (``cpfa``, shipped by a registered package: `registry.scenario_files`) or a
    path to a YAML file."""
    path = Path(name_or_path)
    if path.suffix in (".yaml", ".yml") or path.exists():
        if not path.is_file():
            raise ScenarioError(f"scenario file {path} does not exist")
        return path
    try:
        shipped = registry.scenario_files()
    except ValueError as exc:
        raise ScenarioError(str(exc)) from None
    if name_or_path not in shipped:
        raise ScenarioError(f"unknown scenario {name_or_path!r} (known: {', '.join(shipped)})")
    return shipped[name_or_path]


def load_scenario(
    name_or_path: str | None = None,
    overrides: Iterable[str] = (),
    **fields: Any,
) -> Scenario:
    """Load, override, build and validate a scenario (None or '': `registry.default_scenario`).

    `overrides` are ``a.b=VALUE`` strings (the CLI's ``--set``); `fields` are dotted keys
    with ``__`` for dots, e.g. ``robots__count=8`` (the CLI's ``--robots``).
    """
    path = resolve_path(name_or_path or registry.default_scenario())
    data = read_yaml(path)
    given = [parse_override(text) for text in overrides]
    given += [(key.replace("__", "."), value) for key, value in fields.items() if value is not None]
    for key, value in given:
        _set_path(data, key, value)
    return _finish(_build(Scenario, _moved(data, carry=False), ""), given)


def _leaves(key: str, value: Any) -> Iterable[tuple[str, Any]]:
    if isinstance(value, dict):
        for k, v in value.items():
            yield from _leaves(f"{key}.{k}", v)
    else:
        yield key, value


def _at(scenario: Scenario, key: str) -> Any:
    node: Any = scenario
    for part in key.split("."):
        node = getattr(node, part, _MISSING)
        if node is _MISSING:
            break
    return node


def _refuse_replaced(before: Scenario, after: Scenario, given: Iterable[tuple[str, Any]]) -> None:
    """ScenarioError for a value the user set that the robot model then replaced (the foot-bot's
    ring fixes ``sensors.scan.rays``, say): a ``--set`` must not be dropped in silence."""
    for key, value in (leaf for pair in given for leaf in _leaves(*pair)):
        was, now = _at(before, key), _at(after, key)
        if was is _MISSING or was == now:
            continue
        hint = (f"vary it with robots.platform.{_PLATFORM[key]}" if key in _PLATFORM
                else "robots.model=generic takes it as given")
        raise ScenarioError(f"{key}={_short(value)}: the {after.robots.model} robot model sets it to "
                            f"{_short(now)} ({hint})")


_MISSING = object()
_PLATFORM = {f"robots.{f}": f for f in BODY_FIELDS} | {f"sensors.{k}": f for f, k in SENSOR_FIELDS.items()}
"""A key a platform model fixes -> the ``robots.platform`` field that varies it."""


def _finish(scenario: Scenario, given: Iterable[tuple[str, Any]] = ()) -> Scenario:
    """Validated as written, then with the robot model's values written in
    (`swarm_sim.robots.apply_model`) and validated again: a platform model replaces some values
    (the foot-bot's ring, say), and a bad one the file or ``--set`` gave is refused all the same,
    as is a good one the user `given` that the model would replace."""
    validate(scenario)
    try:
        modelled = apply_model(scenario)
    except ValueError as exc:
        raise ScenarioError(str(exc)) from None
    _refuse_replaced(scenario, modelled, given)
    validate(modelled)
    return modelled


class _StrictLoader(yaml.SafeLoader):
    """safe_load that refuses duplicate keys (YAML says they are an error; PyYAML keeps the last)."""

    def construct_mapping(self, node, deep=False):  # noqa: ANN001 - PyYAML's signature
        seen = set()
        for key_node, _ in node.value:
            key = self.construct_object(key_node, deep=True)
            if isinstance(key, str) and key in seen:
                raise ScenarioError(f"duplicate key {key!r} (line {key_node.start_mark.line + 1})")
            seen.add(key)
        return super().construct_mapping(node, deep)


def read_yaml(path: Path) -> dict[str, Any]:
    """A scenario file's mapping; ScenarioError naming the file and the problem for anything
    that is not a non-empty, UTF-8, YAML mapping without duplicate keys."""
    try:
        raw = path.read_bytes()
    except OSError as exc:
        raise ScenarioError(f"{path}: cannot read: {exc.strerror}") from None
    if len(raw) > MAX_FILE_BYTES:
        raise ScenarioError(f"{path}: {len(raw)} bytes is larger than a scenario file can be ({MAX_FILE_BYTES})")
    try:
        text = raw.decode("utf-8")
    except UnicodeDecodeError as exc:
        raise ScenarioError(f"{path}: not UTF-8 text (byte {exc.start})") from None
    try:
        data = yaml.load(text, Loader=_StrictLoader)  # noqa: S506 - a SafeLoader subclass
    except ScenarioError as exc:
        raise ScenarioError(f"{path}: {exc}") from None
    except yaml.YAMLError as exc:
        raise ScenarioError(f"{path}: not valid YAML: {' '.join(str(exc).split())}") from None
    except RecursionError:
        raise ScenarioError(f"{path}: nested too deeply") from None
    except ValueError as exc:  # an int of more than 4300 digits (Python's conversion limit)
        raise ScenarioError(f"{path}: {_unreadable(exc)}") from None
    if data is None:
        raise ScenarioError(f"{path}: the file is empty")
    if not isinstance(data, dict):
        raise ScenarioError(f"{path}: the top level must be a mapping")
    return data


def scenario_to_dict(scenario: Scenario) -> dict[str, Any]:
    """Plain-data form (for bag metadata and JSON results); `_build` accepts it back."""

    def plain(value: Any) -> Any:
        if dataclasses.is_dataclass(value):
            return {f.name: plain(getattr(value, f.name)) for f in dataclasses.fields(value)}
        if isinstance(value, tuple):
            return [plain(v) for v in value]
        return value

    data = plain(scenario)
    for where in (data, data["controller"]):
        for name, section in where.pop("sections"):
            where[name] = section
    return data


def scenario_from_dict(data: dict[str, Any]) -> Scenario:
    """The scenario `scenario_to_dict` wrote (bag metadata), built and validated again; keys a
    world section has taken over since the bag was recorded (`WorldSection.MOVED`) are carried
    into it first, so an old recording still reads."""
    return _finish(_build(Scenario, _moved(data, carry=True), ""))


def _moved(data: dict[str, Any], carry: bool) -> dict[str, Any]:
    """`data` with every key a declared world section lists in its ``MOVED`` put into that
    section (a copy; the section's own value wins where both are given), or, unless `carry`,
    a ScenarioError naming the first such key and where it lives now (a scenario file)."""
    out = copy.deepcopy(data) if carry else data
    for name in registry.world_sections():
        for old, field_name in registry.world_section(name).MOVED.items():
            *parents, leaf = old.split(".")
            where: Any = out
            for part in parents:
                where = where.get(part) if isinstance(where, dict) else None
            if not (isinstance(where, dict) and leaf in where):
                continue
            if not carry:
                raise ScenarioError(f"{old}: moved to {name}.{field_name}")
            value = where.pop(leaf)
            section = out.setdefault(name, {})
            if isinstance(section, dict):
                section.setdefault(field_name, value)
    return out

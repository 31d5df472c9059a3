"""The tree's shape: each paper's names stay in its own package, the packages in layers that
import one way only (the wire vocabulary `swarm_msgs_py` at the bottom, the ROS-free core
`swarm_sim` on it, the ROS edge the one folder `swarm_sim/nodes/`), no import circles among the
project's modules, and no function-local import of a project module without a comment saying why.

Walks the source as text (ast and tokenize), the way test_core_is_ros_free walks the packages, so a
new module is checked without being listed."""

from __future__ import annotations

import ast
import dataclasses
import io
import re
import tokenize
import typing
from collections.abc import Iterable, Iterator
from importlib.metadata import entry_points
from pathlib import Path

from swarm_sim import registry
from swarm_sim.outputs import outputs_of
from swarm_sim.scenario import Scenario

ROOT = Path(__file__).resolve().parents[1]
PACKAGES = ("swarm_sim", "swarm_controllers", "swarm_msgs_py", "depot_manager", "launch_py")
SHARED = ("swarm_sim", "swarm_msgs_py", "launch_py")
EDGE = "swarm_sim.nodes"
"""The ROS edge: the one folder whose modules may import rclpy or a message package (the nodes,
the controller node, QoS, the executor, parameters, markers); only it and the launcher above it
import it (`test_core_is_ros_free` runs everything else with ROS blocked)."""
LAYERS = ("swarm_msgs_py", "swarm_sim", "depot_manager", "swarm_controllers", "launch_py")
"""The packages from the bottom up: each imports only those below it (``TYPE_CHECKING`` and
function-local imports counted)."""
ROS_ROOTS = ("rclpy", "rosidl_runtime_py", "rcl_interfaces")
"""What only the edge imports, with every ``*_msgs`` / ``*_srvs`` / ``*_interfaces`` package."""
"""Packages that hold no paper (plus swarm_controllers' own top-level modules)."""
COMMON_WORDS = {
    "depot": "the shared core's central place (the scenario's depot section, the `depot` delivery kind) "
             "as well as the queue paper's server channel",
    "center": "the spiral paper's server channel, and a plain word (a disc's centre, matplotlib's loc)",
}
"""Names a paper uses that are also the shared core's own words, and why."""
LAZY = "lazy:"
"""What the comment on (or just above) a function-local import of a project module starts with."""


def _modules() -> dict[str, Path]:
    out = {}
    for package in PACKAGES:
        for path in sorted((ROOT / package).rglob("*.py")):
            parts = path.relative_to(ROOT).with_suffix("").parts
            out[".".join(parts[:-1] if parts[-1] == "__init__" else parts)] = path
    return out


MODULES = _modules()


def _target(name: str) -> str | None:
    """The project module an import of `name` loads (its longest known prefix)."""
    while name:
        if name in MODULES:
            return name
        name = name.rpartition(".")[0]
    return None


def _type_checking(node: ast.AST) -> bool:
    return isinstance(node, ast.If) and "TYPE_CHECKING" in ast.unparse(node.test)


def _imports(tree: ast.Module, type_checking: bool = False) -> Iterator[tuple[ast.stmt, str, bool]]:
    """(statement, imported project module, at module level) for every import, those inside
    ``if TYPE_CHECKING:`` blocks only if `type_checking`."""

    def walk(node: ast.AST, top: bool) -> Iterator[tuple[ast.stmt, str, bool]]:
        for child in ast.iter_child_nodes(node):
            if _type_checking(child) and not type_checking:
                continue
            if isinstance(child, ast.Import):
                for alias in child.names:
                    if (t := _target(alias.name)) is not None:
                        yield child, t, top
            elif isinstance(child, ast.ImportFrom) and child.level == 0 and child.module:
                for alias in child.names:
                    if (t := _target(f"{child.module}.{alias.name}") or _target(child.module)) is not None:
                        yield child, t, top
            top_child = top and not isinstance(child, (ast.FunctionDef, ast.AsyncFunctionDef, ast.Lambda))
            yield from walk(child, top_child)

    yield from walk(tree, True)


def _runs(importer: str, target: str) -> set[str]:
    """What importing `target` from `importer` runs: the target and the packages above it (their
    ``__init__``), but not the importer's own packages (initialised or initialising already)."""
    parts = target.split(".")
    chain = {".".join(parts[:k]) for k in range(1, len(parts) + 1)}
    return {m for m in chain & set(MODULES) if not importer.startswith(m + ".") and m != importer}


def _graph(type_checking: bool = False) -> dict[str, set[str]]:
    """Module -> what importing it runs; with `type_checking`, module -> the modules it names in
    any import (a ``TYPE_CHECKING`` import runs nothing, so no package ``__init__`` on the way)."""
    graph: dict[str, set[str]] = {m: set() for m in MODULES}
    for module, path in MODULES.items():
        for _, target, _ in _imports(ast.parse(path.read_text()), type_checking):
            graph[module] |= {target} - {module} if type_checking else _runs(module, target)
    return graph


def _cycles(graph: dict[str, set[str]]) -> list[list[str]]:
    """Strongly connected components of more than one module (Tarjan)."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on: set[str] = set()
    out: list[list[str]] = []

    def visit(v: str) -> None:
        index[v] = low[v] = len(index)
        stack.append(v)
        on.add(v)
        for w in graph[v]:
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            component = []
            while True:
                w = stack.pop()
                on.discard(w)
                component.append(w)
                if w == v:
                    break
            if len(component) > 1:
                out.append(sorted(component))

    for v in sorted(graph):
        if v not in index:
            visit(v)
    return out


def test_no_import_circles():
    """No circle, a package's ``__init__`` included, nor one closed by a ``TYPE_CHECKING`` import
    (an annotation's import is a dependency a reader follows too); the scenario schema and the
    registry sit at the bottom (the loader and validation call the registry, never the other way
    round)."""
    graph = _graph()
    assert _cycles(graph) == []
    assert _cycles(_graph(type_checking=True)) == []
    assert graph["swarm_sim.scenario.schema"] <= {"swarm_sim"}
    assert "swarm_sim.scenario" not in graph["swarm_sim.registry"]


def _members(tree: ast.Module, cls: str) -> set[str]:
    """The names a class of `tree` defines (its methods and properties)."""
    [node] = [n for n in tree.body if isinstance(n, ast.ClassDef) and n.name == cls]
    return {n.name for n in node.body if isinstance(n, ast.FunctionDef)}


def test_world_loop_uses_only_its_host_interface():
    """The world loop reaches the world node only through `LoopHost` (and its settings through
    `LoopSettings`): every ``host.X`` it reads is declared there, and it assigns none."""
    tree = ast.parse(MODULES["swarm_sim.nodes.world_loop"].read_text())
    host, settings = _members(tree, "LoopHost"), _members(tree, "LoopSettings")
    used, config, assigned = set(), set(), []
    for node in ast.walk(tree):
        if isinstance(node, ast.Attribute) and isinstance(node.value, (ast.Name, ast.Attribute)):
            owner = ast.unparse(node.value)
            if owner in ("host", "self.host"):
                used.add(node.attr)
                if isinstance(node.ctx, ast.Store):
                    assigned.append(node.attr)
            elif owner in ("host.config", "self.host.config", "cfg"):
                config.add(node.attr)
    assert used and used <= host, sorted(used - host)
    assert config and config <= settings, sorted(config - settings)
    assert assigned == []


def test_function_local_imports_of_project_modules_say_why():
    unexplained = []
    for module, path in MODULES.items():
        lines = path.read_text().splitlines()
        for stmt, target, top in _imports(ast.parse(path.read_text())):
            here = lines[stmt.lineno - 1]
            above = lines[stmt.lineno - 2].strip() if stmt.lineno > 1 else ""
            if not top and f"# {LAZY}" not in here and not above.startswith(f"# {LAZY}"):
                unexplained.append(f"{module}:{stmt.lineno} imports {target}")
    assert unexplained == []


def _field_names(cls: type) -> set[str]:
    """The field names of a section's dataclass and of the dataclasses among its fields' types."""
    hints = typing.get_type_hints(cls)
    out = set()
    for f in dataclasses.fields(cls):
        out.add(f.name)
        for tp in (hints[f.name], *typing.get_args(hints[f.name])):
            if isinstance(tp, type) and dataclasses.is_dataclass(tp):
                out |= _field_names(tp)
    return out


CORE_FIELDS = _field_names(Scenario)
"""The shared scenario's own field names: a paper's section may reuse them (a ``radius``)."""


def _paper_names() -> dict[str, tuple[set[str], set[str]]]:
    """Per paper (the entry point that registers it), the names only it may use: (names code may
    not spell as a string: its algorithms, world tasks, config and world sections, server
    channels and absolute topics; names it may not use at all: its metric fields). Channels and
    sections are often plain words (a server's ``center``), so only a string can switch on them."""
    names: dict[str, tuple[set[str], set[str]]] = {}

    def add_sections(paper: str, sections: Iterable[tuple[str, str]]) -> None:
        names.setdefault(paper, (set(), set()))[0].update(section for section, _ in sections)

    for a in registry.algorithms():
        paper = registry.origin("algorithm", a.name)
        strings, fields = names.setdefault(paper, (set(), set()))
        strings |= {a.name, *(s.channel for s in a.servers)}
        add_sections(paper, (*a.config, *a.world))
        fields |= {m.name for m in a.metrics}
        families = [registry.resolve(f) for f in (*a.peers, *(s.family for s in a.servers))]
        strings |= {t for f in families for t in f.topics.values()}
        for out in map(outputs_of, a.servers):
            strings |= {st.topic for st in out.state} | ({out.markers.topic} if out.markers else set())
        if registry.origin("task", a.task) == paper:
            task = registry.task(a.task)
            strings.add(task.name)
            strings |= {t.topic for t in registry.resolve(task.state)} if task.state else set()
            add_sections(paper, task.world)
    for kind in map(registry.delivery_kind, registry.delivery_kinds()):
        if registry.origin("delivery", kind.name) in names:
            add_sections(registry.origin("delivery", kind.name), kind.world)
    assert "core" not in names, f"the core registers algorithms: {names.get('core')}"
    return names


def _section_fields() -> dict[str, set[str]]:
    """Per paper, the field names of its config and world sections that shared code may use
    nowhere, docstrings and comments included: those of more than one word (a bare ``step`` or
    ``order`` is everyone's word), the shared scenario's own left out."""
    out: dict[str, set[str]] = {}
    records = [(registry.origin("algorithm", a.name), (*a.config, *a.world)) for a in registry.algorithms()]
    records += [(registry.origin("task", t.name), t.world) for t in {registry.task(a.task) for a in registry.algorithms()}]
    records += [(registry.origin("delivery", k.name), k.world)
                for k in map(registry.delivery_kind, registry.delivery_kinds())]
    for paper, sections in records:
        for _, path in sections:
            fields = _field_names(registry.resolve(path)) - CORE_FIELDS
            out.setdefault(paper, set()).update(f for f in fields if "_" in f)
    out.pop("core", None)
    return out


def _code_words(path: Path) -> tuple[set[str], set[str]]:
    """(identifiers, string literals) of a file, docstrings and comments left out."""
    source = path.read_text()
    docstrings = set()
    for node in ast.walk(ast.parse(source)):
        if isinstance(node, (ast.Module, ast.ClassDef, ast.FunctionDef, ast.AsyncFunctionDef)):
            body = node.body
            if body and isinstance(body[0], ast.Expr) and isinstance(body[0].value, ast.Constant):
                docstrings.add(body[0].lineno)
        if isinstance(node, ast.Expr) and isinstance(node.value, ast.Constant) and isinstance(node.value.value, str):
            docstrings.add(node.lineno)  # attribute docstrings
    names, strings = set(), set()
    for tok in tokenize.generate_tokens(io.StringIO(source).readline):
        if tok.type == tokenize.NAME:
            names.add(tok.string)
        elif tok.type == tokenize.STRING and tok.start[0] not in docstrings:
            try:
                value = ast.literal_eval(tok.string)
            except (ValueError, SyntaxError):
                continue  # an f-string part
            if isinstance(value, str):
                strings.add(value)
    return names, strings


def _doc_words(path: Path) -> set[str]:
    """The words of a file's docstrings and comments."""
    source = path.read_text()
    texts = [node.value.value for node in ast.walk(ast.parse(source))
             if isinstance(node, ast.Expr) and isinstance(node.value, ast.Constant) and isinstance(node.value.value, str)]
    texts += [tok.string for tok in tokenize.generate_tokens(io.StringIO(source).readline) if tok.type == tokenize.COMMENT]
    return set(re.findall(r"[A-Za-z_][A-Za-z0-9_]*", " ".join(texts)))


def test_no_paper_name_outside_its_package():
    """Shared code spells no paper's names, uses none of its metric fields, and names none of its
    sections' fields, not even in a docstring or a comment (the queue paper's docks once sat in
    the shared depot section)."""
    papers, sections = _paper_names(), _section_fields()
    assert {"dock_radius", "perimeter_radius", "lane_spacing"} <= sections["queue"]
    assert {"cpfa", "queue", "spiral", "drtm", "caging"} <= set(papers)
    found = []
    for module, path in MODULES.items():
        shared = module.split(".")[0] in SHARED or module.count(".") == 1 and module.startswith("swarm_controllers.")
        if not shared:
            continue
        identifiers, strings = _code_words(path)
        words = identifiers | strings | _doc_words(path)
        for paper, (spelt, fields) in papers.items():
            hits = ((spelt | fields) & strings | fields & identifiers | sections.get(paper, set()) & words) - set(COMMON_WORDS)
            # an absolute topic inside a longer string too (a script, a command line)
            hits |= {t for t in spelt if t.startswith("/") for text in strings if t in text}
            if hits:
                found.append(f"{module}: {paper}'s {', '.join(sorted(hits))}")
    assert found == []


def _packages(record: registry.Algorithm) -> set[str]:
    """The packages an algorithm's record names code in (``swarm_controllers.queue``,
    ``depot_manager``), shared ones left out."""
    paths = [record.behaviour, *(p for _, p in record.config), *record.checks, *record.peers,
             *(x for s in record.servers for x in (s.core, s.family)), *(m.function for m in record.metrics),
             *(x for x in (record.paths, record.comparison, record.figures) if x)]
    out = set()
    for path in paths:
        parts = path.partition(":")[0].split(".")
        package = ".".join(parts[:2]) if parts[0] == "swarm_controllers" else parts[0]
        if parts[0] in PACKAGES and parts[0] not in SHARED:
            out.add(package)
    return out


def test_a_paper_names_only_itself_and_the_papers_it_builds_on():
    """A paper's package may use another paper's names only if its records use that paper's code
    (the queue strategies search as the CPFA does)."""
    papers = _paper_names()
    homes = {e.name: e.value.rpartition(".")[0] for e in entry_points(group=registry.ENTRY_POINT_GROUP)}
    used: dict[str, set[str]] = {}
    for a in registry.algorithms():
        used.setdefault(registry.origin("algorithm", a.name), set()).update(_packages(a))
    owner = {homes[paper]: paper for paper in used}
    for paper, packages in sorted(used.items()):
        for package in packages:
            owner.setdefault(package, paper)  # a package no paper calls home: the one that uses it
    found = []
    for module, path in MODULES.items():
        parts = module.split(".")
        paper = owner.get(".".join(parts[:2]) if parts[0] == "swarm_controllers" else parts[0])
        if paper is None:
            continue
        allowed = {owner[p] for p in used[paper]} | {paper}
        identifiers, strings = _code_words(path)
        for other, (spelt, fields) in papers.items():
            hits = sorted(((spelt | fields) & strings | fields & identifiers) - set(COMMON_WORDS))
            if other not in allowed and hits:
                found.append(f"{module} ({paper}): {other}'s {', '.join(hits)}")
    assert found == []


def test_the_checks_can_fail(tmp_path):
    assert _cycles({"a": {"b"}, "b": {"a"}, "c": set()}) == [["a", "b"]]
    bad = tmp_path / "bad.py"
    bad.write_text('"""doc queue"""\nx = "queue"  # depot\n')
    assert _code_words(bad) == ({"x"}, {"queue"})
    assert _doc_words(bad) == {"doc", "queue", "depot"}
    ros = tmp_path / "ros.py"
    ros.write_text("import os\ndef f():\n    from std_msgs.msg import Header\n    import rclpy.node\n")
    assert _ros_imports(ros) == ["std_msgs.msg", "rclpy.node"]
    hidden = ast.parse("from typing import TYPE_CHECKING\nif TYPE_CHECKING:\n    from swarm_sim import registry\n")
    assert [t for _, t, _ in _imports(hidden)] == []
    assert [t for _, t, _ in _imports(hidden, type_checking=True)] == ["swarm_sim.registry"]


def _package_arrows() -> set[tuple[str, str]]:
    """(importer's package, imported package) for every import between two project packages,
    ``TYPE_CHECKING`` and function-local ones counted."""
    return {(m.split(".")[0], t.split(".")[0]) for m, targets in _graph(type_checking=True).items()
            for t in targets if m.split(".")[0] != t.split(".")[0]}


def test_packages_import_one_way():
    """Each package imports only the packages below it in `LAYERS`: no arrow back up, so no
    circle between packages either."""
    up = sorted((a, b) for a, b in _package_arrows() if LAYERS.index(b) > LAYERS.index(a))
    assert up == []


def _ros_imports(path: Path) -> list[str]:
    out = []
    for node in ast.walk(ast.parse(path.read_text())):
        names = ([a.name for a in node.names] if isinstance(node, ast.Import)
                 else [node.module] if isinstance(node, ast.ImportFrom) and node.level == 0 and node.module else [])
        for name in names:
            root = name.split(".")[0]
            if root in ROS_ROOTS or root.endswith(("_msgs", "_srvs", "_interfaces")):
                out.append(name)
    return out


def test_the_ros_edge_is_one_folder():
    """Only modules under `EDGE` import rclpy or a message package (function-local imports
    included), and only the edge itself and the launcher import the edge."""
    outside = [f"{m} imports {', '.join(names)}" for m, path in MODULES.items()
               if not (m == EDGE or m.startswith(EDGE + ".")) and (names := _ros_imports(path))]
    assert outside == []
    into = [f"{m} -> {t}" for m, targets in _graph(type_checking=True).items() for t in targets
            if (t == EDGE or t.startswith(EDGE + ".")) and not m.startswith((EDGE, "launch_py"))]
    assert into == []

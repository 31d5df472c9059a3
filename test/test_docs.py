"""The documentation: the README stays a front door, every link of the README and the docs
resolves (files and anchors), the MkDocs site builds without a warning, and the tutorial
(docs/your_algorithm.md) runs as written: its package from its code blocks, its commands in a
shell, from the batch run to the graph run, the bag and its figures."""

from __future__ import annotations

import os
import re
import shlex
import signal
import subprocess
import sys
import tomllib
import unicodedata
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[1]
DOCS = REPO / "docs"
PAGES = [REPO / "README.md", REPO / "benchmarks" / "README.md", *sorted(DOCS.glob("*.md"))]
"""Every Markdown file the documentation consists of: the README, the benchmarks' figures, the site's pages."""

_FENCE = re.compile(r"^(```|~~~)")
_LINK = re.compile(r"!?\[(?:[^\]\[]|\[[^\]]*\])*\]\(([^)\s]+)(?:\s+\"[^\"]*\")?\)")
_HEADING = re.compile(r"^(#{1,6})\s+(.*?)\s*#*\s*$")


def _outside_fences(text: str) -> list[tuple[int, str]]:
    """(line number, line) of `text` outside fenced code blocks."""
    out, fenced = [], False
    for number, line in enumerate(text.splitlines(), 1):
        if _FENCE.match(line.lstrip()):
            fenced = not fenced
        elif not fenced:
            out.append((number, line))
    return out


def _prose(text: str) -> list[tuple[int, str]]:
    """(line number, line) of `text` outside fenced code blocks, inline code spans blanked."""
    return [(number, re.sub(r"`[^`]*`", "``", line)) for number, line in _outside_fences(text)]


def _heading_text(raw: str) -> str:
    """A heading's text as rendered: code spans' content kept, links' text kept, emphasis dropped."""
    text = re.sub(r"\[([^\]]*)\]\([^)]*\)", r"\1", raw)
    return text.replace("`", "").replace("**", "").replace("*", "")


def github_anchor(heading: str) -> str:
    """GitHub's anchor of a heading: lower case, punctuation but '-' and '_' dropped, spaces -> '-'."""
    text = _heading_text(heading).strip().lower()
    return re.sub(r"[^\w\- ]", "", text).replace(" ", "-")


def mkdocs_anchor(heading: str) -> str:
    """MkDocs's (Python-Markdown toc's `slugify`) anchor of a heading."""
    text = unicodedata.normalize("NFKD", _heading_text(heading)).encode("ascii", "ignore").decode()
    text = re.sub(r"[^\w\s-]", "", text).strip().lower()
    return re.sub(r"[-\s]+", "-", text)


def anchors(path: Path, slug) -> set[str]:
    """The anchors of `path`'s headings by `slug`, repeated headings numbered as both renderers do."""
    seen: dict[str, int] = {}
    out = set()
    for _, line in _outside_fences(path.read_text()):
        match = _HEADING.match(line)
        if match:
            base = slug(match.group(2))
            n = seen.get(base, 0)
            seen[base] = n + 1
            out.add(base if n == 0 else f"{base}_{n}" if slug is mkdocs_anchor else f"{base}-{n}")
    return out


def broken_links(page: Path) -> list[str]:
    """Every link of `page` that does not resolve: a missing file, or an anchor no heading of its
    target has. Anchors into the site's pages must hold for GitHub and MkDocs alike (the pages are
    read in both); anchors into other Markdown files, for GitHub."""
    problems = []
    for number, line in _prose(page.read_text()):
        for target in _LINK.findall(line):
            if re.match(r"^[a-z][a-z0-9+.-]*:", target):  # http:, https:, mailto:
                continue
            where, _, anchor = target.partition("#")
            file = (page.parent / where).resolve() if where else page
            name = f"{page.name}:{number}: {target}"
            if not file.exists():
                problems.append(f"{name}: no such file")
                continue
            if not anchor:
                continue
            if file.suffix != ".md":
                problems.append(f"{name}: an anchor into a file that is not Markdown")
                continue
            slugs = [github_anchor, mkdocs_anchor] if file.parent == DOCS else [github_anchor]
            for slug in slugs:
                if anchor not in anchors(file, slug):
                    problems.append(f"{name}: no heading with the anchor #{anchor} ({slug.__name__})")
    return problems


# ---------------------------------------------------------------------------- the front door


def test_the_readme_is_a_front_door():
    text = (REPO / "README.md").read_text()
    assert len(text.splitlines()) <= 250
    for command in ("scripts/run", "scripts/test"):  # the two commands stay in the README
        assert re.search(rf"^{command}\b", text, re.M), f"README.md lost the command {command}"


# ---------------------------------------------------------------------------- links


@pytest.mark.parametrize("page", PAGES, ids=lambda p: str(p.relative_to(REPO)))
def test_every_link_resolves(page):
    assert broken_links(page) == []


def test_the_link_check_finds_broken_links(tmp_path):
    (tmp_path / "other.md").write_text("# Other page\n\n## A `code` section: the rest\n")
    page = tmp_path / "page.md"
    page.write_text(
        "# Page\n\n[fine](other.md#a-code-section-the-rest) [fine](#page) [web](https://example.org/x)\n"
        "[gone](missing.md) ![gone too](missing.png) [bad anchor](other.md#nowhere) [self](#nowhere)\n"
        "```\n[in a code block](not-checked.md)\n```\n`[in code](not-checked.md)`\n"
    )
    found = broken_links(page)
    assert [p.split(": ", 1)[1] for p in found] == [
        "missing.md: no such file", "missing.png: no such file",
        "other.md#nowhere: no heading with the anchor #nowhere (github_anchor)",
        "#nowhere: no heading with the anchor #nowhere (github_anchor)",
    ]


def test_anchors_follow_github_and_mkdocs():
    assert github_anchor("`bench_network.py`") == mkdocs_anchor("`bench_network.py`") == "bench_networkpy"
    assert github_anchor("Across hosts: controllers, robots' own computers") == \
        "across-hosts-controllers-robots-own-computers"
    assert github_anchor("a - b") == "a---b" and mkdocs_anchor("a - b") == "a-b"


# ---------------------------------------------------------------------------- the site


def test_the_site_builds_without_a_warning(tmp_path):
    try:
        import mkdocs  # noqa: F401
    except ImportError:
        pytest.skip("mkdocs is not installed (scripts/setup installs it: the `docs` extra of setup.py)")
    result = subprocess.run(
        [sys.executable, "-m", "mkdocs", "build", "--strict", "--config-file", str(REPO / "mkdocs.yml"),
         "--site-dir", str(tmp_path / "site")],
        capture_output=True, text=True, timeout=120, cwd=REPO,
    )
    assert result.returncode == 0, result.stdout + result.stderr
    assert "WARNING" not in result.stdout + result.stderr
    for page in DOCS.glob("*.md"):  # every page is in the site
        built = tmp_path / "site" / ("index.html" if page.stem == "index" else f"{page.stem}/index.html")
        assert built.exists(), f"{page.name} was not built"


# ---------------------------------------------------------------------------- the tutorial

_MARKED = re.compile(r"^<!-- (file: (?P<file>\S+)|(?P<kind>install|run|run: fails)) -->\s*\n"
                     r"```[a-z]*\n(?P<body>.*?)^```", re.M | re.S)
"""A code block of the tutorial marked for the test by the HTML comment before it (invisible in
the rendered page): a file to write, the install command, a command to run, one that must fail."""


def tutorial_blocks(text: str) -> list[tuple[str, str, str]]:
    """The tutorial's marked code blocks in order: ('file', path, content), ('install', '', commands),
    ('run', '', commands) and ('run: fails', '', commands)."""
    return [("file", m["file"], m["body"]) if m["file"] else (m["kind"], "", m["body"])
            for m in _MARKED.finditer(text)]


def _register(project: Path, site: Path) -> None:
    """What `pip install -e ./<project>` leaves for the registry: the distribution's metadata with
    its entry points (read from the project's pyproject.toml) on the path, the package importable
    from the project folder. Done without pip, which would need the network to build."""
    meta = tomllib.loads((project / "pyproject.toml").read_text())["project"]
    info = site / f"{meta['name']}-{meta['version']}.dist-info"
    info.mkdir(parents=True)
    (info / "METADATA").write_text(f"Metadata-Version: 2.1\nName: {meta['name']}\nVersion: {meta['version']}\n")
    groups = meta.get("entry-points", {})
    (info / "entry_points.txt").write_text("".join(
        f"[{group}]\n" + "".join(f"{name} = {value}\n" for name, value in entries.items())
        for group, entries in groups.items()))


def _shell(command: str, cwd: Path, env: dict[str, str], timeout: float = 300.0) -> subprocess.CompletedProcess:
    """Run one command line in its own session; whatever is left of it is killed on a timeout."""
    proc = subprocess.Popen(["bash", "-c", command], cwd=cwd, env=env, stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True, start_new_session=True)
    try:
        out, err = proc.communicate(timeout=timeout)
    except subprocess.TimeoutExpired:
        os.killpg(proc.pid, signal.SIGKILL)
        proc.communicate()
        raise
    return subprocess.CompletedProcess(command, proc.returncode, out, err)


def test_the_tutorial_runs_as_written(tmp_path):
    blocks = tutorial_blocks((DOCS / "your_algorithm.md").read_text())
    kinds = [kind for kind, _, _ in blocks]
    assert kinds.count("install") == 1 and kinds.count("run") >= 3 and "run: fails" in kinds
    work, site = tmp_path / "work", tmp_path / "site"
    work.mkdir()
    for kind, path, body in blocks:
        if kind == "file":
            (work / path).parent.mkdir(parents=True, exist_ok=True)
            (work / path).write_text(body)
    (install,) = [body for kind, _, body in blocks if kind == "install"]
    assert shlex.split(install) == ["pip", "install", "-e", "./wanderer"]
    _register(work / "wanderer", site)
    env = {**os.environ,
           "PATH": os.pathsep.join([str(Path(sys.executable).parent), os.environ["PATH"]]),
           "PYTHONPATH": os.pathsep.join([str(site), str(work / "wanderer"), os.environ.get("PYTHONPATH", "")])}
    outputs = []
    for kind, _, body in blocks:
        if not kind.startswith("run"):
            continue
        result = _shell(body, work, env)
        if kind == "run: fails":  # one line naming the key, exit 2, nothing run
            assert result.returncode == 2, result.stdout + result.stderr
            assert result.stderr.strip().splitlines() == [
                "swarm-batch: controller.wanderer.leg_time: 0.0 is not > 0"]
            continue
        assert result.returncode == 0, f"{body}\n{result.stdout[-3000:]}\n{result.stderr[-3000:]}"
        outputs.append(result.stdout + result.stderr)
    batch, graph, analysis = outputs[:3]
    # The batch run of seed 0 found and delivered resources.
    delivered = re.search(r"wanderer_demo seed=0 robots=8: .*?resources_delivered (\d+) resources", batch)
    assert delivered and int(delivered[1]) > 0, batch
    # The bag tells the run it recorded. On a loaded machine a controller may answer a tick late
    # (a stale tick): the run then says so and may differ from the batch run; else it is the
    # batch run of its seed.
    stale = re.search(r"^\s+stale_ticks\s+(\d+)$", graph, re.M)
    on_graph = re.search(r"^\s+resources_delivered\s+(\d+) resources$", graph, re.M)
    assert stale and on_graph, graph
    for text in (graph, analysis):
        assert re.search(r"^\s+run_ended\s+complete$", text, re.M), text
    assert re.search(rf"^\s+resources_delivered\s+{on_graph[1]} resources$", analysis, re.M), analysis
    if stale[1] == "0":
        assert on_graph[1] == delivered[1], (batch, graph)
    else:
        assert "lockstep ticks answered late" in graph, graph
    (bag,) = (work / "runs" / "wanderer").iterdir()
    assert (bag / "summary.png").stat().st_size > 0 and (bag / "trajectories.png").stat().st_size > 0
    assert outputs[3].strip().splitlines()[-1] == "['ros_free', 'determinism', 'codecs']"

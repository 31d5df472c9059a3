"""``--help`` is complete on every command: each command's description is whole (not a first
line cut mid-sentence) and every option and positional argument says what it is. The commands
are read from setup.py's console scripts, so a new command is checked without being listed."""

from __future__ import annotations

import argparse
import ast
import importlib
from pathlib import Path

import pytest

SETUP = Path(__file__).resolve().parents[1] / "setup.py"


def _console_scripts() -> list[tuple[str, str]]:
    """(command, module:function) from setup.py."""
    tree = ast.parse(SETUP.read_text())
    for node in ast.walk(tree):
        if isinstance(node, ast.Dict):
            for key, value in zip(node.keys, node.values):
                if isinstance(key, ast.Constant) and key.value == "console_scripts":
                    entries = [e.value for e in value.elts]
                    return [tuple(part.strip() for part in e.split("=")) for e in entries]
    raise AssertionError("no console_scripts in setup.py")


@pytest.mark.parametrize(("command", "target"), _console_scripts())
def test_every_option_of_every_command_has_help(command, target, monkeypatch, capsys):
    unexplained: list[str] = []
    descriptions: list[str] = []
    add_argument, init = argparse._ActionsContainer.add_argument, argparse.ArgumentParser.__init__

    def checked_add(self, *args, **kwargs):
        action = add_argument(self, *args, **kwargs)
        if action.help is None and not isinstance(action, argparse._HelpAction):
            unexplained.append("/".join(action.option_strings) or action.dest)
        return action

    def checked_init(self, *args, **kwargs):
        init(self, *args, **kwargs)
        descriptions.append(self.description or "")

    monkeypatch.setattr(argparse._ActionsContainer, "add_argument", checked_add)
    monkeypatch.setattr(argparse.ArgumentParser, "__init__", checked_init)
    module, _, function = target.partition(":")
    with pytest.raises(SystemExit) as done:
        getattr(importlib.import_module(module), function)(["--help"])
    assert done.value.code == 0
    assert capsys.readouterr().out.startswith("usage:")
    assert unexplained == [], f"{command}: options without help: {unexplained}"
    assert descriptions and all(d.rstrip().endswith((".", ")")) for d in descriptions if d), descriptions

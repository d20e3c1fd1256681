"""The README's examples work as printed: Python blocks run, CLI commands exit 0, and a shown
plain-text output matches what the command prints."""
from __future__ import annotations

import re
import shlex
from pathlib import Path

import pytest

from studies.cli import main

README = (Path(__file__).parent.parent / "README.md").read_text()
PY_BLOCKS = re.findall(r"```python\n(.*?)```", README, re.S)
CONSOLE = re.findall(r"```console\n(.*?)```", README, re.S)


def _commands():
    """(argv, expected output or None) for every `$ rmt ...` line of the README."""
    out = []
    for block in CONSOLE:
        lines = block.splitlines()
        for i, line in enumerate(lines):
            if not line.startswith("$ rmt "):
                continue
            cmd = line[2:].split("#")[0]
            shown = []
            for nxt in lines[i + 1:]:
                if nxt.startswith("$ "):
                    break
                shown.append(nxt)
            text = "\n".join(shown)
            out.append((shlex.split(cmd)[1:], None if ("..." in text or not text) else text))
    return out


def test_readme_has_examples():
    assert len(PY_BLOCKS) >= 2 and len(_commands()) >= 6


@pytest.mark.parametrize("i", range(len(PY_BLOCKS)))
def test_python_block_runs(i):
    namespace: dict = {"__name__": f"readme_block_{i}"}
    exec(compile(PY_BLOCKS[i], f"README python block {i}", "exec"), namespace)
    # a block that is a test file (the planning.testing example): its tests must pass as shown
    for name, fn in namespace.items():
        if name.startswith("test_") and callable(fn):
            fn()


@pytest.fixture(scope="module")
def workdir(tmp_path_factory):
    """One directory for all README commands, run in order: later ones read what earlier ones wrote."""
    return tmp_path_factory.mktemp("readme")


@pytest.mark.parametrize("argv, shown", _commands(), ids=lambda x: " ".join(x) if isinstance(x, list) else "")
def test_cli_example(argv, shown, capsys, workdir, monkeypatch):
    monkeypatch.chdir(workdir)           # `rmt study` writes out/ here, `rmt plan --out` its CSV
    assert main(argv) == 0
    out = capsys.readouterr().out
    if shown is not None:
        assert out.strip() == shown.strip()

"""The repository is ruff-clean with the configuration of pyproject.toml ([tool.ruff]): ``ruff check``
over the whole tree exits 0."""
from __future__ import annotations

import importlib.util
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent


def test_ruff_check_passes():
    if importlib.util.find_spec("ruff") is None:
        pytest.skip("ruff is not installed: pip install -e '.[test]' (the test extra has it)")
    run = subprocess.run([sys.executable, "-m", "ruff", "check", str(ROOT)], cwd=ROOT, capture_output=True,
                         text=True, timeout=300)
    assert run.returncode == 0, f"ruff check failed (exit {run.returncode}):\n{run.stdout}{run.stderr}"

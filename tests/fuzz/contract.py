"""The command line's contract, checked on any argument vector (issue 8 §5):

* exit 0 or 1 with finite output — JSON (with ``--json``) parses strictly, without NaN or infinity;
* or exit 2 with exactly one line on stderr, ``rmt: error: …``;
* never an exception out of ``main`` (a traceback), never another exit code;
* no file written anywhere but the paths the command was asked to write.

:func:`run_contract` runs ``studies.cli.main(argv)`` in-process inside a working directory and
checks all of it; the fuzz tests feed it generated robot files, tool paths, joint paths, study
files and argument vectors.
"""
from __future__ import annotations

import contextlib
import io
import json
import os
import re
from pathlib import Path

from hypothesis import HealthCheck, settings

from studies.cli import main

#: the fuzz suite's settings: few, reproducible examples, no per-example deadline (CI stability)
FUZZ = settings(max_examples=30, deadline=None, derandomize=True, database=None,
                suppress_health_check=[HealthCheck.too_slow, HealthCheck.filter_too_much,
                                       HealthCheck.data_too_large])


def tree(root: Path) -> dict[str, int]:
    """Every file and directory below ``root`` → its size (directories: -1)."""
    out = {}
    for p in root.rglob("*"):
        out[str(p.relative_to(root))] = -1 if p.is_dir() else p.stat().st_size
    return out


def _strict_json(text: str):
    def refuse(c):
        raise AssertionError(f"non-finite number {c} in JSON output")
    return json.loads(text, parse_constant=refuse)


def run_contract(argv: list[str], cwd: Path, allowed_outputs: tuple[str, ...] = ()) -> tuple[int, str, str]:
    """Run ``main(argv)`` in ``cwd`` and assert the contract; ``allowed_outputs`` are paths (relative
    to ``cwd``) the command may create or change — a directory allows everything below it."""
    before = tree(cwd)
    out, err = io.StringIO(), io.StringIO()
    old = os.getcwd()
    os.chdir(cwd)
    try:
        with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
            code = main(argv)
    finally:
        os.chdir(old)
    stdout, stderr = out.getvalue(), err.getvalue()
    assert code in (0, 1, 2), (argv, code, stderr)
    assert "Traceback" not in stderr, (argv, stderr)
    if code == 2:
        assert stderr.count("\n") == 1 and stderr.startswith("rmt: error: "), (argv, stderr)
    else:
        if "--json" in argv and stdout.strip():
            _strict_json(stdout)
        assert not re.search(r"\bnan\b", stdout, re.IGNORECASE), (argv, stdout)
    after = tree(cwd)
    changed = {k for k in set(before) | set(after) if before.get(k) != after.get(k)}
    allowed = {str(Path(a)) for a in allowed_outputs}

    def ok(path: str) -> bool:
        parts = Path(path).parts
        return any(Path(*parts[:i]).as_posix() in allowed for i in range(1, len(parts) + 1)) or any(
            a.startswith(path + "/") for a in allowed)          # a parent directory created for an output
    stray = sorted(k for k in changed if not ok(k))
    assert not stray, (argv, stray)
    return code, stdout, stderr

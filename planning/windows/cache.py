"""Built windows kept on disk, so that a command that only needs them does not rebuild them.

A window is a function of the robot, its factor and the width (:mod:`planning.windows`), so a built
:class:`~planning.windows.WindowSet` can be stored under a key made of exactly those: the chain's
content (frozen DH table, joint types, convention, base, tool, limits, units, task rows), the width
request (for example ``{"margin": 0.05}`` in the robot file's units, or ``{"sigma_min": 0.02}``),
the version of the window rule (:data:`RULE_VERSION`, raised whenever the construction changes) and
the version of sympy (which prints the factors).  Files live under
``<kin.compiled.cache_dir()>/windows/``; a file records its key and is read back with the full
validation of :meth:`WindowSet.from_dict` (JSON, never code), and used only when it holds that key
and was built for the same robot (:meth:`WindowSet.check_robot`) — a damaged, foreign or misplaced
file is ignored and rebuilt.  A hit returns what a rebuild gives — except for a chain whose exact
analysis did not finish within its budget: its windows come from the numeric analysis this machine
could do when they were first built (delete the folder to retry).
"""
from __future__ import annotations

import hashlib
import json
import re
from importlib import metadata
from pathlib import Path
from typing import Callable

from kin.compiled import cache_dir
from kin.errors import RmtError
from planning.windows.model import WindowSet, robot_key

__all__ = ["RULE_VERSION", "window_key", "cache_path", "load_cached", "store", "cached"]

#: raised whenever the construction of a window changes (old files are then simply not found)
RULE_VERSION = 4
#: a cache file larger than this is not read
MAX_BYTES = 256 << 20


def _version(name: str) -> str:
    try:
        return metadata.version(name)
    except metadata.PackageNotFoundError:     # pragma: no cover - sympy is a dependency
        return "?"


def window_key(robot, request: dict) -> str:
    """Hash of everything the windows of ``robot`` for ``request`` (plain JSON data) depend on."""
    content = {"rule": RULE_VERSION, "sympy": _version("sympy"), "request": request, "robot": robot_key(robot),
               "name": robot.chain.name}
    return hashlib.sha256(json.dumps(content, sort_keys=True).encode()).hexdigest()[:32]


def cache_path(robot, key: str) -> Path:
    """Where the windows of ``robot`` under ``key`` are stored."""
    label = re.sub(r"[^A-Za-z0-9_]", "_", robot.chain.name)[:40]
    return cache_dir() / "windows" / f"{label}_{key}.json"


def load_cached(robot, key: str) -> WindowSet | None:
    """The stored windows of ``robot`` under ``key``, or None when absent, damaged, foreign or
    written under another key."""
    path = cache_path(robot, key)
    try:
        if not path.is_file() or path.stat().st_size > MAX_BYTES:
            return None
        d = json.loads(path.read_text(encoding="utf-8"))
        if not isinstance(d, dict) or d.get("cache_key") != key:
            return None
        ws = WindowSet.from_dict(d, str(path))
        ws.check_robot(robot)
    except (OSError, UnicodeDecodeError, ValueError, RecursionError, RmtError):
        return None
    return ws


def store(robot, key: str, windows: WindowSet) -> Path | None:
    """Write ``windows`` under ``key`` (atomically, :func:`kin.output.write_output`; the file records
    its key); None when the cache directory is not writable (the windows are then rebuilt next time)."""
    from kin.output import write_output
    text = json.dumps({"cache_key": key, **windows.to_dict()}, allow_nan=False)
    try:
        return write_output(cache_path(robot, key), text + "\n")
    except (OSError, RmtError):
        return None


def cached(robot, request: dict, build: Callable[[], WindowSet],
           unstored: Callable[[str], None] | None = None) -> WindowSet:
    """The windows of ``robot`` for ``request`` from the cache, or ``build()`` stored for next time;
    ``unstored(message)`` is told when they could not be stored (they are then rebuilt next time)."""
    key = window_key(robot, request)
    ws = load_cached(robot, key)
    if ws is None:
        ws = build()
        if store(robot, key, ws) is None and unstored is not None:
            unstored(f"the windows could not be stored in {cache_path(robot, key).parent} (not a writable "
                     "directory): they are rebuilt on every run; set RMTKIT_CACHE to a writable directory")
    return ws

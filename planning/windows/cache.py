"""Built windows kept on disk, so that a command that only needs them does not rebuild them.

A window is a function of the robot, its factor and the width (:mod:`planning.windows`), so a built
:class:`~planning.windows.WindowSet` can be stored under a key made of exactly those: the chain's
content (frozen DH table, joint types, convention, base, tool, limits, units, task rows), the width
request (for example ``{"margin": 0.05}`` in the robot file's units, or ``{"sigma_min": 0.02}``),
the version of the window rule (:data:`RULE_VERSION`, raised whenever the construction changes) and
the version of sympy (which prints the factors).  Files live under
``<kin.compiled.cache_dir()>/windows/``; a file is read back with the full validation of
:meth:`WindowSet.load` (JSON, never code) and used only when it names the same robot and key — a
damaged or foreign file is ignored and rebuilt.  The cache never changes a window: a hit returns
what a rebuild would.
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

from planning.windows.model import WindowSet

__all__ = ["RULE_VERSION", "window_key", "cache_path", "load_cached", "store", "cached"]

#: raised whenever the construction of a window changes (old files are then simply not found)
RULE_VERSION = 3
#: a cache file larger than this is not read
MAX_BYTES = 256 << 20


def _version(name: str) -> str:
    try:
        return metadata.version(name)
    except metadata.PackageNotFoundError:     # pragma: no cover - sympy is a dependency
        return "?"


def window_key(robot, request: dict) -> str:
    """Hash of everything the windows of ``robot`` for ``request`` (plain JSON data) depend on."""
    chain = robot.chain.frozen()
    content = {"rule": RULE_VERSION, "sympy": _version("sympy"), "request": request,
               "convention": chain.convention, "types": list(chain.joint_types),
               "dh": [[repr(float(x)) for x in row] for row in chain.dh_table()],
               "base": [repr(float(x)) for x in chain.base.matrix.ravel()],
               "tool": [repr(float(x)) for x in chain.tool.matrix.ravel()],
               "limits": [[repr(float(lo)), repr(float(hi))] for lo, hi in zip(chain.lower, chain.upper)],
               "units": [repr(float(chain.angle_scale)), repr(float(chain.length_scale))],
               "rows": [int(r) for r in robot.task_rows], "name": chain.name}
    return hashlib.sha256(json.dumps(content, sort_keys=True).encode()).hexdigest()[:32]


def cache_path(robot, key: str) -> Path:
    """Where the windows of ``robot`` under ``key`` are stored."""
    label = re.sub(r"[^A-Za-z0-9_]", "_", robot.chain.name)[:40]
    return cache_dir() / "windows" / f"{label}_{key}.json"


def load_cached(robot, key: str) -> WindowSet | None:
    """The stored windows of ``robot`` under ``key``, or None when absent, damaged or foreign."""
    path = cache_path(robot, key)
    try:
        if not path.is_file() or path.stat().st_size > MAX_BYTES:
            return None
        ws = WindowSet.load(path)
    except (OSError, RmtError):
        return None
    if ws.robot != robot.name or ws.n != robot.n:
        return None
    return ws


def store(robot, key: str, windows: WindowSet) -> Path | None:
    """Write ``windows`` under ``key`` (atomically, :func:`kin.output.write_output`); None when the
    cache directory is not writable (the windows are then simply rebuilt next time)."""
    try:
        return windows.save(cache_path(robot, key))
    except (OSError, RmtError):
        return None


def cached(robot, request: dict, build: Callable[[], WindowSet]) -> WindowSet:
    """The windows of ``robot`` for ``request`` from the cache, or ``build()`` stored for next time."""
    key = window_key(robot, request)
    ws = load_cached(robot, key)
    if ws is None:
        ws = build()
        store(robot, key, ws)
    return ws

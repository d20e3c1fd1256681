"""The disk cache of exact analyses: one JSON file per chain, keyed by the chain's content
(:func:`kin.singular.exact.content_key`), in ``singular/`` under the compiled-code cache directory
(:func:`kin.compiled.cache_dir`).  A file holds the factored determinant as monomial lists, each
factor's display form as an expression tree and the roots of one-joint factors — data, never
expression text to evaluate.

A file is trusted only after :func:`kin.singular.exact.validate_structure` accepts it and its key
matches, and the analysis then checks its display forms and roots against its polynomials
numerically; a corrupted, truncated, foreign or inconsistent file is ignored (and replaced by the
next store).
Writes are atomic (a temporary file in the same directory, then a rename).
"""
from __future__ import annotations

import json
import os
import re
import tempfile
from pathlib import Path

from kin.compiled import cache_dir
from kin.singular.exact import StructureError, validate_structure

#: a cache file larger than this is not read
MAX_BYTES = 64 << 20


def cache_path(robot, key: str) -> Path:
    """Where the exact analysis of ``robot`` (content hash ``key``) is stored."""
    label = re.sub(r"[^A-Za-z0-9_]", "_", robot.chain.name)[:40]
    return cache_dir() / "singular" / f"{label}_{key}.json"


def load_cached(robot, key: str) -> dict | None:
    """The cached structure for ``robot``, or None when absent or not trustworthy."""
    path = cache_path(robot, key)
    try:
        if not path.is_file() or path.stat().st_size > MAX_BYTES:
            return None
        record = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, UnicodeDecodeError, ValueError, RecursionError):
        return None
    if not isinstance(record, dict) or record.get("key") != key:
        return None
    try:
        return validate_structure(record.get("structure"), robot.n, tuple(robot.task_rows))
    except StructureError:
        return None


def store(robot, key: str, structure: dict) -> Path | None:
    """Write the structure for ``robot``; None when the cache directory is not writable."""
    path = cache_path(robot, key)
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=f".{path.stem}.", suffix=".tmp")
        try:
            with os.fdopen(fd, "w", encoding="utf-8") as fh:
                json.dump({"key": key, "structure": structure}, fh)
            os.replace(tmp, path)
        except BaseException:
            Path(tmp).unlink(missing_ok=True)
            raise
    except OSError:
        return None
    return path

"""One bounded reader for every file a command reads.

:func:`read_bytes` accepts a regular file only (a FIFO, a device such as ``/dev/zero`` or a
directory is refused before it is opened for reading) and checks the size cap before reading —
and again while reading, so a file that grows under the reader is still bounded.
:func:`read_text` decodes UTF-8 (a leading byte-order mark is accepted and dropped) and reports a
decoding error in one line naming the file and the byte offset.  :func:`read_json` parses JSON with
its nesting depth bounded before the parser runs (no ``RecursionError``), integers bounded in
digits and ``NaN``/``Infinity``/overflowing floats refused.

Every error is a :class:`FileReadError` (a :class:`kin.RmtError`) whose message is one line:
``<path>: <what is wrong>``; ``reason`` holds the part after the path, for callers that wrap it in
their own error class.
"""
from __future__ import annotations

import json
import math
import os
import re
import stat
from pathlib import Path
from typing import Any

import numpy as np

from kin.errors import RmtError

__all__ = ["FileReadError", "read_bytes", "read_text", "read_json", "json_depth", "named_file",
           "MAX_JSON_DEPTH", "MAX_INT_DIGITS"]

#: default nesting bound of :func:`read_json` (every rmtkit JSON file nests a handful of levels)
MAX_JSON_DEPTH = 64
#: default digit bound of a JSON integer (< 10**15: exact as a float and in an int64)
MAX_INT_DIGITS = 15
_CHUNK = 1 << 22
_STRING = re.compile(rb'"(?:[^"\\]|\\.)*"', re.S)


class FileReadError(RmtError):
    """A file a command reads is missing, not a regular file, too large or not valid text/JSON.
    ``path`` is the file, ``reason`` the message without it."""

    def __init__(self, path: str | Path, reason: str):
        self.path, self.reason = str(path), reason
        super().__init__(f"{path}: {reason}")


def named_file(name_or_path: str | Path, directory: Path) -> tuple[Path, bool]:
    """Where a bundled file's name or a path points: ``(path, given)``.  It is a path (``given``) when it
    looks like one — a ``.toml`` suffix, an existing file, or a "/" in it — else ``directory/NAME.toml``.
    The file may not exist: the caller words that error for its kind of file."""
    p = Path(name_or_path)
    if p.suffix == ".toml" or p.exists() or "/" in str(name_or_path):
        return p, True
    return Path(directory) / f"{name_or_path}.toml", False


def _size_text(n: int) -> str:
    return f"{n / 2**20:.1f} MB" if n >= 2**20 else f"{n} bytes"


def _cap_text(n: int) -> str:
    return f"{n / 2**20:g} MB" if n >= 2**16 else f"{n} bytes"


def read_bytes(path: str | Path, what: str, max_bytes: int) -> bytes:
    """The bytes of the regular file ``path``, at most ``max_bytes``; ``what`` names the kind of file
    in messages ("joint-path file", "task file", …)."""
    p = Path(path)
    try:
        st = os.stat(p)
    except FileNotFoundError:
        raise FileReadError(p, f"no such {what}") from None
    except OSError as e:
        raise FileReadError(p, f"cannot read the {what} ({e.strerror or e})") from None
    if not stat.S_ISREG(st.st_mode):
        kind = "a directory, not a regular file" if stat.S_ISDIR(st.st_mode) else "not a regular file"
        raise FileReadError(p, f"{kind}; a {what} must be a regular file")
    if st.st_size > max_bytes:
        raise FileReadError(p, f"{_size_text(st.st_size)}; a {what} may have at most {_cap_text(max_bytes)}")
    try:
        # O_NONBLOCK: should the path have been swapped for a FIFO since the stat, open does not hang
        fd = os.open(p, os.O_RDONLY | getattr(os, "O_NONBLOCK", 0))
    except OSError as e:
        raise FileReadError(p, f"cannot read the {what} ({e.strerror or e})") from None
    with os.fdopen(fd, "rb") as f:
        try:
            if not stat.S_ISREG(os.fstat(fd).st_mode):
                raise FileReadError(p, f"not a regular file; a {what} must be a regular file")
            data = f.read(max_bytes + 1)
        except OSError as e:
            raise FileReadError(p, f"cannot read the {what} ({e.strerror or e})") from None
    if len(data) > max_bytes:
        raise FileReadError(p, f"more than {_cap_text(max_bytes)}; a {what} may have at most {_cap_text(max_bytes)}")
    return data


def read_text(path: str | Path, what: str, max_bytes: int, error: type | None = None) -> str:
    """The UTF-8 text of ``path`` (:func:`read_bytes`); a leading byte-order mark is dropped, a byte
    that is not UTF-8 is reported with its offset.  ``error``: a caller's error class, built as
    ``error(reason, str(path))``, that a :class:`FileReadError` is raised as instead."""
    try:
        data = read_bytes(path, what, max_bytes)
        try:
            return data.decode("utf-8-sig")
        except UnicodeDecodeError as e:
            line = data.count(b"\n", 0, e.start) + 1
            raise FileReadError(path, f"not UTF-8 text (byte 0x{data[e.start]:02x} at offset {e.start}, line "
                                      f"{line}); a {what} must be UTF-8 text") from None
    except FileReadError as e:
        if error is None:
            raise
        raise error(e.reason, str(path)) from None


def json_depth(text: str | bytes) -> int:
    """The deepest nesting of ``[``/``{`` in JSON text (brackets inside strings not counted), found
    without recursion."""
    b = text.encode("utf-8", "surrogatepass") if isinstance(text, str) else text
    b = _STRING.sub(b'""', b)
    a = np.frombuffer(b, dtype=np.uint8)
    deepest = level = 0
    for k in range(0, len(a), _CHUNK):            # chunks: bounded memory on a 100 MB file
        c = a[k:k + _CHUNK]
        step = ((c == 91) | (c == 123)).astype(np.int32) - ((c == 93) | (c == 125))   # [ { minus ] }
        run = level + np.cumsum(step)
        deepest = max(deepest, int(run.max(initial=level)))
        level = int(run[-1]) if len(run) else level
    return deepest


def read_json(path: str | Path, what: str, max_bytes: int, max_depth: int = MAX_JSON_DEPTH,
              max_int_digits: int = MAX_INT_DIGITS) -> Any:
    """The JSON value of ``path`` (:func:`read_text`): nesting at most ``max_depth`` levels, integers
    of at most ``max_int_digits`` digits, every number finite (no NaN, Infinity or 1e999)."""
    text = read_text(path, what, max_bytes)
    depth = json_depth(text)
    if depth > max_depth:
        raise FileReadError(path, f"JSON nested {depth} levels deep; a {what} may nest at most {max_depth}")

    def parse_int(s: str) -> int:
        if len(s.lstrip("-")) > max_int_digits:
            raise FileReadError(path, f"integer {s[:20]}{'…' if len(s) > 20 else ''} has {len(s.lstrip('-'))} "
                                      f"digits; a {what} allows at most {max_int_digits}")
        return int(s)

    def parse_float(s: str) -> float:
        v = float(s)
        if not math.isfinite(v):
            raise FileReadError(path, f"number {s[:40]} overflows a float; a {what} needs finite numbers")
        return v

    def parse_constant(s: str):
        raise FileReadError(path, f"{s} is not a finite number; a {what} needs finite numbers")

    try:
        return json.loads(text, parse_int=parse_int, parse_float=parse_float, parse_constant=parse_constant)
    except json.JSONDecodeError as e:
        raise FileReadError(path, f"not JSON ({e.msg}, line {e.lineno} column {e.colno})") from None
    except RecursionError:      # the depth check makes this unreachable; kept as the last guard
        raise FileReadError(path, f"JSON nested too deeply; a {what} may nest at most {max_depth}") from None

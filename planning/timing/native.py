"""The compiled reachability passes: the C of :mod:`planning.timing.reach_source` compiled on first
use with the project's compiler (:func:`kin.compiled.evaluator.find_compiler`; ``RMTKIT_CC=none``
disables it) and cached in :func:`kin.compiled.evaluator.cache_dir` under a hash of the source, the
compiler and its flags, as the kinematics kernels are.  :func:`load_reach` returns None when no
compiler is available or compiling fails (with a warning); the caller then uses the numpy passes.
"""
from __future__ import annotations

import ctypes
import hashlib
import os
import subprocess
import sys
import tempfile
import threading
import warnings
from pathlib import Path

from kin.native import cache_dir, find_compiler
from kin.errors import CompileError
from planning.timing.reach_source import REACH_SOURCE

__all__ = ["load_reach", "CFLAGS"]

CFLAGS = ["-O2", "-fPIC", "-shared", "-fno-math-errno", "-std=c99"]
_lock = threading.Lock()
_loaded: dict[str, ctypes._CFuncPtr] = {}


def _compile(source: str, compiler: str, path: Path) -> None:
    path.parent.mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory(dir=path.parent) as tmp:
        c_file = Path(tmp) / "reach.c"
        c_file.write_text(source)
        so = Path(tmp) / "reach.so"
        proc = subprocess.run([compiler, *CFLAGS, str(c_file), "-o", str(so), "-lm"], capture_output=True,
                              text=True, timeout=120)
        if proc.returncode != 0:
            err = proc.stderr.strip().splitlines()
            raise CompileError(f"{compiler} failed on the reachability passes: {err[-1] if err else proc.returncode}")
        os.replace(so, path)    # atomic: a concurrent reader sees no file or the whole new one


def load_reach():
    """The ctypes function ``rmt_reach`` (see :mod:`planning.timing.reach_source`), or None without a
    working compiler."""
    compiler = find_compiler()
    if compiler is None:
        return None
    with _lock:
        if compiler in _loaded:
            return _loaded[compiler]
        key = hashlib.sha256("\0".join([REACH_SOURCE, compiler, " ".join(CFLAGS), sys.platform]).encode()
                             ).hexdigest()[:20]
        path = cache_dir() / f"rmt_timing_reach_{key}.so"
        try:
            if not path.is_file():
                _compile(REACH_SOURCE, compiler, path)
            f = ctypes.CDLL(str(path)).rmt_reach
        except (CompileError, OSError, subprocess.SubprocessError) as e:
            warnings.warn(f"rmtkit: compiling the timing passes failed, using numpy instead ({e})", RuntimeWarning,
                          stacklevel=3)
            _loaded[compiler] = None
            return None
        p = ctypes.c_void_p
        f.argtypes = [ctypes.c_longlong] + [p] * 10
        f.restype = ctypes.c_int
        _loaded[compiler] = f
        return f

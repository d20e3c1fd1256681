"""The compiled reachability passes: ``reach.c`` beside this module, built on first use by
:func:`kin.native.build` (the project's compiler, ``RMTKIT_CC=none`` disables it; cached under
``cache_dir()/native`` like the kinematics kernels).  :func:`load_reach` returns None when no
compiler is available or compiling fails (with a warning); the caller then uses the numpy passes.
"""
from __future__ import annotations

import ctypes
import threading
import warnings
from pathlib import Path

from kin.errors import CompileError
from kin.native import build, find_compiler

__all__ = ["load_reach", "REACH_SOURCE"]

#: the C source of the two passes (see its first comment)
REACH_SOURCE = Path(__file__).resolve().with_name("reach.c")
_lock = threading.Lock()
_loaded: dict[str, ctypes._CFuncPtr] = {}


def load_reach():
    """The ctypes function ``rmt_reach`` (see ``reach.c``), or None without a working compiler."""
    compiler = find_compiler()
    if compiler is None:
        return None
    with _lock:
        if compiler in _loaded:
            return _loaded[compiler]
        try:
            lib = build("timing_reach", REACH_SOURCE, compiler=compiler, what="the reachability passes")
            f = ctypes.CDLL(str(lib.path)).rmt_reach
        except (CompileError, OSError) as e:
            warnings.warn(f"rmtkit: compiling the timing passes failed, using numpy instead ({e})", RuntimeWarning,
                          stacklevel=3)
            _loaded[compiler] = None
            return None
        p = ctypes.c_void_p
        f.argtypes = [ctypes.c_longlong] + [p] * 10
        f.restype = ctypes.c_int
        _loaded[compiler] = f
        return f

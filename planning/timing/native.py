"""The compiled timing kernels: the reachability passes (``reach.c``) and the jerk pass (``jerk_ipm.c``)
beside this module, built on first use by
:func:`kin.native.build` (the project's compiler, ``RMTKIT_CC=none`` disables it; cached under
``cache_dir()/native`` like the kinematics kernels).  :func:`load_reach` returns None when no
compiler is available or compiling fails (with a warning); the caller then uses the numpy passes
(:func:`load_jerk` likewise for the jerk pass).
"""
from __future__ import annotations

import ctypes
import threading
import warnings
from pathlib import Path

from kin.errors import CompileError
from kin.native import build, find_compiler

__all__ = ["load_reach", "load_jerk", "REACH_SOURCE", "JERK_SOURCE"]

#: the C source of the two passes (see its first comment)
REACH_SOURCE = Path(__file__).resolve().with_name("reach.c")
#: the C source of the jerk pass (see its first comment)
JERK_SOURCE = Path(__file__).resolve().with_name("jerk_ipm.c")
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


def load_jerk():
    """The ctypes functions ``(rmt_jerk, rmt_prune)`` (see ``jerk_ipm.c``), or None without a working
    compiler."""
    compiler = find_compiler()
    if compiler is None:
        return None
    key = ("jerk", compiler)
    with _lock:
        if key in _loaded:
            return _loaded[key]
        try:
            lib = build("timing_jerk", JERK_SOURCE, compiler=compiler, what="the jerk pass")
            dll = ctypes.CDLL(str(lib.path))
        except (CompileError, OSError) as e:
            warnings.warn(f"rmtkit: compiling the jerk pass failed, using numpy instead ({e})", RuntimeWarning,
                          stacklevel=3)
            _loaded[key] = None
            return None
        p, i64 = ctypes.c_void_p, ctypes.c_longlong
        jerk, prune = dll.rmt_jerk, dll.rmt_prune
        jerk.argtypes = [i64, i64, p, p, p, i64, p, p, p, p, p, p, p, p, p, i64, ctypes.c_double, i64, p]
        jerk.restype = ctypes.c_int
        prune.argtypes = [i64, p, p, p, p, p, p, p, p]
        prune.restype = None
        _loaded[key] = (jerk, prune)
        return _loaded[key]

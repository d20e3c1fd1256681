"""The settings of native builds, read from the environment at each use: compiler, architecture,
thread count, cache directory, and what the CPU and interpreter contribute to a library's identity.

* ``RMTKIT_CC`` — the C compiler (``none`` disables compiling), else ``$CC``, ``cc``, ``gcc``, ``clang``;
* ``RMTKIT_ARCH`` — ``native`` (default: ``-march=native``) or ``portable`` (the architecture's baseline);
* ``RMTKIT_THREADS`` — threads of a batch call (1..256), by default the CPUs this process may run on
  (``os.sched_getaffinity``: a Dask worker or ``taskset`` pinned to one CPU gets one thread);
* ``RMTKIT_CACHE`` — the cache directory (default ``$XDG_CACHE_HOME/rmtkit`` or ``~/.cache/rmtkit``).
"""
from __future__ import annotations

import os
import platform
import re
import shutil
import sysconfig
from functools import lru_cache
from pathlib import Path

from kin.errors import SettingError

ARCH_FLAGS = {"native": ["-march=native"], "portable": []}
MAX_THREADS = 256


def cache_dir() -> Path:
    """Directory of rmtkit's caches: ``$RMTKIT_CACHE`` or ``$XDG_CACHE_HOME/rmtkit`` or ``~/.cache/rmtkit``."""
    env = os.environ.get("RMTKIT_CACHE")
    if env:
        return Path(env)
    xdg = os.environ.get("XDG_CACHE_HOME")
    return (Path(xdg) if xdg else Path.home() / ".cache") / "rmtkit"


def find_compiler() -> str | None:
    """The C compiler to use: ``$RMTKIT_CC`` (``none`` disables compiling), else ``$CC``, cc, gcc, clang.
    Looked up once per value of those variables and of ``PATH`` (the planner asks on every call)."""
    return _find_compiler(os.environ.get("RMTKIT_CC"), os.environ.get("CC"), os.environ.get("PATH"))


@lru_cache(maxsize=16)
def _find_compiler(env: str | None, cc: str | None, path: str | None) -> str | None:
    if env is not None:
        return None if env.strip().lower() in ("", "none", "0", "false") else shutil.which(env)
    for cand in (cc, "cc", "gcc", "clang"):
        if cand and shutil.which(cand):
            return shutil.which(cand)
    return None


def requested_arch() -> str:
    """``RMTKIT_ARCH``: ``native`` (default) or ``portable``."""
    v = os.environ.get("RMTKIT_ARCH", "native").strip().lower() or "native"
    if v not in ARCH_FLAGS:
        raise SettingError(f"RMTKIT_ARCH = {v!r}; allowed: native, portable")
    return v


def default_threads() -> int:
    """Threads of a batch call: ``RMTKIT_THREADS`` (1..256), else the CPUs this process may use."""
    env = os.environ.get("RMTKIT_THREADS", "").strip()
    if env:
        try:
            k = int(env)
        except ValueError:
            raise SettingError(f"RMTKIT_THREADS = {env!r}; allowed: an integer 1..{MAX_THREADS}") from None
        if not 1 <= k <= MAX_THREADS:
            raise SettingError(f"RMTKIT_THREADS = {k}; allowed: 1..{MAX_THREADS}")
        return k
    return _available_cpus()


def _available_cpus() -> int:
    try:
        return max(1, min(MAX_THREADS, len(os.sched_getaffinity(0))))
    except (AttributeError, OSError):  # not Linux
        return max(1, min(MAX_THREADS, os.cpu_count() or 1))


@lru_cache(maxsize=1)
def cpu_fingerprint() -> str:
    """What ``-march=native`` depends on: the CPU model and feature flags (Linux), else the platform."""
    try:
        text = Path("/proc/cpuinfo").read_text()
        keep = [ln for ln in text.splitlines() if re.match(r"(model name|flags|Features|CPU part)\s*:", ln)]
        return " ".join(sorted(set(keep)))
    except OSError:
        return f"{platform.machine()} {platform.processor()}"


def compiler_identity(compiler: str) -> str:
    """The compiler as far as a library depends on it: its path, the file it resolves to, and that
    file's size and modification time (a compiler upgraded in place builds anew; no process is run)."""
    real = os.path.realpath(compiler)
    try:
        st = os.stat(real)
        return f"{compiler} -> {real} {st.st_size} {st.st_mtime_ns}"
    except OSError:
        return compiler


@lru_cache(maxsize=1)
def python_extension_flags() -> tuple[str, ...]:
    """Flags that make a library also a CPython extension module (``-DRMT_PYEXT`` and the include
    directories of this interpreter and of numpy), or () when those C headers are missing."""
    import numpy as np

    py_inc = Path(sysconfig.get_paths()["include"])
    np_inc = Path(np.get_include())
    if not (py_inc / "Python.h").is_file() or not (np_inc / "numpy" / "arrayobject.h").is_file():
        return ()
    return ("-DRMT_PYEXT", f"-I{py_inc}", f"-I{np_inc}")

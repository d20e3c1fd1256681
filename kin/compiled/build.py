"""Building the kernel library: compiler, flags (native or portable), on-disk cache, thread count.

Two builds of the same source exist:

* ``native`` — ``-O3 -march=native``: the compiler targets this machine's vector width (AVX2,
  AVX-512, NEON); the cache key then includes a fingerprint of the CPU, so a shared cache directory
  never hands one machine's library to another;
* ``portable`` — ``-O3`` for the architecture's baseline (SSE2 on x86-64).

``RMTKIT_ARCH`` chooses (``native``, the default, or ``portable``); a compiler that rejects
``-march=native`` gets the portable build.  Libraries are cached under ``$RMTKIT_CACHE`` (default
``$XDG_CACHE_HOME/rmtkit`` or ``~/.cache/rmtkit``) by a hash of source, compiler, flags and CPU.

Threads: batch calls use ``RMTKIT_THREADS`` threads, by default as many as the CPUs this process may
run on (``os.sched_getaffinity``; a Dask worker or ``taskset`` pinned to one CPU gets one thread).
The kernel starts POSIX threads per call and joins them (a blocking wait, no spinning pool), so a
second busy process on the machine slows a call down by its share of the CPUs, not by spinning.
"""
from __future__ import annotations

import hashlib
import os
import platform
import re
import shutil
import subprocess
import sys
import sysconfig
import tempfile
from functools import lru_cache
from pathlib import Path

import casadi as ca

from kin.errors import CompileError, SettingError

# -ffp-contract=off: no fused multiply-adds, so a·b − a·b cancels exactly (a pose at zero net
# rotation prints 0, not 3e-17) and native and portable builds give the same numbers
COMMON_FLAGS = ["-O3", "-fPIC", "-shared", "-pthread", "-fopenmp-simd", "-fno-math-errno", "-ffp-contract=off",
                "-std=gnu99"]
ARCH_FLAGS = {"native": ["-march=native"], "portable": []}
KERNEL_VERSION = "4-soa"
MAX_THREADS = 256


def cache_dir() -> Path:
    """Directory of compiled libraries: ``$RMTKIT_CACHE`` or ``$XDG_CACHE_HOME/rmtkit`` or ``~/.cache/rmtkit``."""
    env = os.environ.get("RMTKIT_CACHE")
    if env:
        return Path(env)
    xdg = os.environ.get("XDG_CACHE_HOME")
    return (Path(xdg) if xdg else Path.home() / ".cache") / "rmtkit"


def find_compiler() -> str | None:
    """The C compiler to use: ``$RMTKIT_CC`` (``none`` disables compiling), else ``$CC``, cc, gcc, clang."""
    env = os.environ.get("RMTKIT_CC")
    if env is not None:
        return None if env.strip().lower() in ("", "none", "0", "false") else shutil.which(env)
    for cand in (os.environ.get("CC"), "cc", "gcc", "clang"):
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


@lru_cache(maxsize=1)
def python_extension_flags() -> tuple[str, ...]:
    """Flags that make the library also a CPython extension module (the single-call path), or ()
    when this interpreter's or numpy's C headers are missing."""
    import numpy as np

    py_inc = Path(sysconfig.get_paths()["include"])
    np_inc = Path(np.get_include())
    if not (py_inc / "Python.h").is_file() or not (np_inc / "numpy" / "arrayobject.h").is_file():
        return ()
    return ("-DRMT_PYEXT", f"-I{py_inc}", f"-I{np_inc}")


def library_path(source: str, compiler: str, arch: str, label: str, directory: Path, extra: tuple[str, ...] = ()
                 ) -> Path:
    """Cache path of the library built from ``source`` with ``compiler`` for ``arch`` (plus ``extra`` flags)."""
    import numpy as np

    parts = [source, compiler, " ".join(COMMON_FLAGS + ARCH_FLAGS[arch] + list(extra)), KERNEL_VERSION,
             ca.__version__, sys.platform, cpu_fingerprint() if arch == "native" else platform.machine()]
    if extra:  # an extension module is tied to the interpreter's and numpy's ABI
        parts += [sys.version, np.__version__]
    key = hashlib.sha256("\0".join(parts).encode()).hexdigest()[:20]
    label = re.sub(r"[^A-Za-z0-9_]", "_", label)[:40]  # the key identifies the library; the label is for people
    return directory / f"rmt_{label}_{arch}_{key}.so"


def compile_library(source: str, compiler: str, arch: str, path: Path, what: str, extra: tuple[str, ...] = ()) -> None:
    """Compile ``source`` into the shared library ``path`` (atomically replaced)."""
    path.parent.mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory(dir=path.parent) as tmp:
        c_file = Path(tmp) / "kernel.c"
        c_file.write_text(source)
        so = Path(tmp) / "kernel.so"
        try:
            proc = subprocess.run([compiler, *COMMON_FLAGS, *ARCH_FLAGS[arch], *extra, str(c_file), "-o", str(so), "-lm"],
                                  capture_output=True, text=True, timeout=300)
        except subprocess.TimeoutExpired:
            raise CompileError(f"{compiler} took over 300 s on the generated kernel of {what}") from None
        if proc.returncode != 0:
            err = proc.stderr.strip()
            raise CompileError(f"{compiler} ({arch} build) failed on the generated kernel of {what}: "
                               f"{err.splitlines()[-1] if err else proc.returncode}")
        os.replace(so, path)  # atomic: a concurrent reader sees the old file or the whole new one

"""Compiling and caching a native kernel: the one place where rmtkit runs a C compiler.

A kernel is a C file shipped with the package (``kin/compiled/kernel.c``, ``kin/ik/ik.c``,
``planning/timing/reach.c``) that includes the shared headers of ``kin/native/include`` and, where it
is specialised per robot, ``rmt_generated.h``: a header of numbers and tables written by
:mod:`kin.native.header` (joint count, task rows, the CasADi graph as an instruction table).
:func:`build` turns (source, generated header, flags) into a shared library:

* flags: :data:`COMMON_FLAGS` plus ``-march=native`` (``RMTKIT_ARCH=native``, the default) or none
  (``portable``); a compiler that refuses the native build gets the portable one;
* cache: ``cache_dir()/native/<kernel>_<arch>-<key>.so``, the key a hash of the C source and every
  shared header, the generated header, the compiler (its file, size and date), the flags and the
  CPU (native builds) or the machine type (portable ones), so a shared cache never hands a library
  built for one CPU to another; a second call — in any process — loads the file instead of compiling;
* concurrency: a lock file per library (:mod:`kin.native.lock`) so that processes starting together
  (sweep workers, Dask) compile it once, the others waiting and then loading it; the compiler writes
  into a temporary directory beside the cache and the library is renamed into place, so nobody ever
  loads a half-written file; a path taken by something other than a regular file is never replaced;
* one time-out, :data:`NATIVE_TIMEOUT`, per compiler run;
* errors: :class:`~kin.errors.CompileError` with one line (the compiler's first error line).

Threads: every kernel that runs in parallel does so through ``include/rmt_parallel.h`` — POSIX
threads started for the call and joined before it returns, no OpenMP runtime, no environment.
"""
from __future__ import annotations

import hashlib
import os
import platform
import re
import subprocess
import sys
import tempfile
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

from kin.errors import ArgumentError, CompileError
from kin.native.lock import file_lock
from kin.native.settings import ARCH_FLAGS, cache_dir, compiler_identity, cpu_fingerprint, find_compiler, requested_arch

#: the shared headers (rmt_common.h, rmt_parallel.h, rmt_graph.h)
INCLUDE_DIR = Path(__file__).resolve().with_name("include")
#: the name under which a kernel includes its generated header
GENERATED_HEADER = "rmt_generated.h"
#: seconds one compiler run may take; waiting for another process's build may take a minute more
NATIVE_TIMEOUT = 300.0
# -ffp-contract=off: no fused multiply-adds, so a·b − a·b cancels exactly (a pose at zero net
# rotation prints 0, not 3e-17) and native and portable builds give the same numbers (GCC 12's
# straight-line vectoriser may still fuse a few: see IK_FLAGS in kin/ik/compiled.py).
# -fopenmp-simd honours `omp simd` pragmas only: no OpenMP runtime is linked.
COMMON_FLAGS = ["-O3", "-fPIC", "-shared", "-pthread", "-fopenmp-simd", "-fno-math-errno", "-ffp-contract=off",
                "-std=gnu99"]


@dataclass(frozen=True)
class Library:
    """A built (or cached) library: its ``path``, the ``arch`` it was built for, whether it was
    ``cached`` (loaded, not compiled by this call)."""

    path: Path
    arch: str
    cached: bool

    @property
    def module_name(self) -> str:
        """A C identifier unique to this library (``RMT_LIBRARY_NAME`` in its C source)."""
        return _module_name(self.path)


def library_dir() -> Path:
    """Where libraries are cached: ``cache_dir()/native``."""
    return cache_dir() / "native"


def build(kernel: str, source: Path, header: str = "", *, flags: Sequence[str] = (), key: Sequence[str] = (),
          arch: str | None = None, compiler: str | None = None, directory: Path | None = None,
          what: str | None = None, include_dirs: Sequence[Path] = ()) -> Library:
    """The library of ``source`` (a C file) specialised by ``header`` (the text of ``rmt_generated.h``).

    ``kernel``: the file name's readable part (any text; letters, digits and ``_`` kept);
    ``flags``: further compiler flags; ``key``: further strings the library depends on (e.g. the
    interpreter's version for an extension module); ``arch``: ``native`` or ``portable`` (default
    ``RMTKIT_ARCH``), native falling back to portable when the compiler refuses it; ``compiler``
    (default :func:`~kin.native.settings.find_compiler`); ``directory`` (default :func:`library_dir`);
    ``what``: how errors name the kernel; ``include_dirs``: further directories the source includes
    from (their ``.c`` and ``.h`` files are part of the library's key: the motion checker includes the
    clearance kernel).
    """
    compiler = compiler or find_compiler()
    what = what or kernel
    if compiler is None:
        raise CompileError(f"no C compiler found for {what} (set CC or RMTKIT_CC)")
    directory = Path(directory) if directory is not None else library_dir()
    source = Path(source)
    arch = arch or requested_arch()
    if arch not in ARCH_FLAGS:
        raise ArgumentError(f"arch {arch!r} unknown; allowed: {', '.join(ARCH_FLAGS)}")
    args = (kernel, source, header, tuple(flags), tuple(key), tuple(Path(d) for d in include_dirs))
    if arch != "portable":
        try:
            return _build_one(*args, arch, compiler, directory, what)
        except _CompilerFailedError:
            pass  # e.g. a compiler that does not know -march=native: the portable build below
    return _build_one(*args, "portable", compiler, directory, what)


class _CompilerFailedError(CompileError):
    """The compiler ran and refused (the only failure the portable build is tried after)."""


def _sources(source: Path, include_dirs: Sequence[Path] = ()) -> list[str]:
    """The text of ``source`` and of every file it may include (shared headers, headers beside it, the
    sources and headers of ``include_dirs``), named."""
    try:
        files = [source, *sorted(INCLUDE_DIR.glob("*.h")), *sorted(source.parent.glob("*.h"))]
        for d in include_dirs:
            files += [*sorted(Path(d).glob("*.h")), *sorted(Path(d).glob("*.c"))]
        return [f"{f.name}\n{f.read_text()}" for f in files]
    except OSError as e:
        raise CompileError(f"cannot read the C source {source}: {e.strerror or e}") from None


def library_key(source: Path, header: str, flags: Sequence[str], key: Sequence[str], arch: str, compiler: str,
                include_dirs: Sequence[Path] = ()) -> str:
    """The hash that names a library (see the module docstring)."""
    parts = [*_sources(source, include_dirs), header, compiler_identity(compiler),
             " ".join([*COMMON_FLAGS, *ARCH_FLAGS[arch], *flags]), sys.platform,
             cpu_fingerprint() if arch == "native" else platform.machine(), *key]
    return hashlib.sha256("\0".join(parts).encode()).hexdigest()[:20]


def _module_name(path: Path) -> str:
    return path.stem.replace("-", "_")


def _refuse_irregular(path: Path) -> None:
    if os.path.lexists(path) and not path.is_file():
        raise CompileError(f"{path} exists and is not a regular file; rmtkit never replaces it (remove it, "
                           "or set RMTKIT_CACHE elsewhere)")


def _build_one(kernel: str, source: Path, header: str, flags: tuple[str, ...], key: tuple[str, ...],
               include_dirs: tuple[Path, ...], arch: str, compiler: str, directory: Path, what: str) -> Library:
    label = re.sub(r"[^A-Za-z0-9_]", "_", kernel)[:48]
    path = directory / f"{label}_{arch}-{library_key(source, header, flags, key, arch, compiler, include_dirs)}.so"
    if path.is_file():
        return Library(path, arch, True)
    _refuse_irregular(path)
    try:
        directory.mkdir(parents=True, exist_ok=True)
        with file_lock(path.with_suffix(".lock"), NATIVE_TIMEOUT + 60, what):
            if path.is_file():  # another process built it while this one waited
                return Library(path, arch, True)
            _refuse_irregular(path)
            with tempfile.TemporaryDirectory(dir=directory, prefix=".build-") as tmp:
                (Path(tmp) / GENERATED_HEADER).write_text(header)
                so = Path(tmp) / "lib.so"
                cmd = [compiler, *COMMON_FLAGS, *ARCH_FLAGS[arch], *flags, f"-DRMT_LIBRARY_NAME={_module_name(path)}",
                       f"-I{tmp}", f"-I{source.parent}", *(f"-I{d}" for d in include_dirs), f"-I{INCLUDE_DIR}",
                       str(source), "-o", str(so), "-lm"]
                _run(cmd, compiler, arch, what)
                _refuse_irregular(path)
                os.replace(so, path)  # atomic: a concurrent reader sees no file or the whole new one
    except OSError as e:
        raise CompileError(f"building {what} in {directory}: {e.strerror or e}") from None
    return Library(path, arch, False)


def _run(cmd: list[str], compiler: str, arch: str, what: str) -> None:
    name = Path(compiler).name
    try:
        proc = subprocess.run(cmd, capture_output=True, text=True, timeout=NATIVE_TIMEOUT)
    except subprocess.TimeoutExpired:
        raise CompileError(f"{name} took over {NATIVE_TIMEOUT:.0f} s on {what} ({arch} build)") from None
    except OSError as e:
        raise CompileError(f"cannot run the C compiler {compiler}: {e.strerror or e}") from None
    if proc.returncode != 0:
        raise _CompilerFailedError(f"{name} ({arch} build) failed on {what}: "
                              f"{first_error(proc.stderr) or f'exit status {proc.returncode}'}")


def first_error(stderr: str) -> str:
    """The line of a compiler's messages that says what went wrong: the first naming an error,
    else the last one; ``""`` when there are none."""
    lines = [ln.strip() for ln in stderr.splitlines() if ln.strip()]
    for ln in lines:
        if re.search(r"\berror\b", ln, re.IGNORECASE):
            return ln
    return lines[-1] if lines else ""

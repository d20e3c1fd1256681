"""Fast evaluators: CasADi-generated C compiled once, cached on disk, called through ctypes.

:class:`CompiledEvaluator` compiles the chain's ``fkj`` function together with the batch kernel of
:mod:`kin.compiled.kernel_source` into a shared library.  The library is cached under
``$RMTKIT_CACHE`` (default ``~/.cache/rmtkit``) by a hash of the generated source and compiler
flags, so a second start only loads it.  Without a working C compiler (or with
``RMTKIT_CC=none``) :func:`make_evaluator` returns a :class:`VMEvaluator`, which runs the same
CasADi functions in CasADi's virtual machine and computes the measures with numpy; both give the
same numbers.

All evaluators share one interface: ``evaluate(Q, P, want)`` with Q (N, n), P (n_p,) or (N, n_p)
returns a dict with any of ``T`` (N, 4, 4), ``J`` (N, 6, n), ``measures`` (N, 4) — columns
manipulability, σ_min, condition number, det (NaN for a non-square task Jacobian).
"""
from __future__ import annotations

import ctypes
import hashlib
import os
import re
import shutil
import subprocess
import sys
import tempfile
import threading
import warnings
from pathlib import Path

import casadi as ca
import numpy as np

from kin.errors import CompileError
from kin.compiled.kernel_source import KERNEL_TEMPLATE
from kin.symbolic import SymbolicChain

WANT_T, WANT_J, WANT_MANIP, WANT_SIGMA = 1, 2, 4, 8
WANT_ALL = WANT_T | WANT_J | WANT_MANIP | WANT_SIGMA
CFLAGS = ["-O3", "-fPIC", "-shared", "-fopenmp", "-fno-math-errno", "-std=c99"]
KERNEL_VERSION = "2"


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


class VMEvaluator:
    """Evaluates in CasADi's virtual machine (no compiler needed); measures computed with numpy."""

    backend = "vm"

    def __init__(self, sym: SymbolicChain):
        self.sym = sym
        self.n = sym.n
        self.rows = list(sym.task_rows)
        self._f = sym.fkj_function
        self._maps: dict[int, ca.Function] = {}

    def _mapped(self, N: int) -> ca.Function:
        if N not in self._maps:
            self._maps[N] = self._f.map(N, "serial")
        return self._maps[N]

    def evaluate(self, Q: np.ndarray, P: np.ndarray, want: int = WANT_ALL) -> dict[str, np.ndarray]:
        N, n = Q.shape
        chunk = 4096
        Ts, Js = [], []
        for s in range(0, N, chunk):
            q = Q[s:s + chunk]
            k = len(q)
            p = np.broadcast_to(P if P.ndim == 1 else P[s:s + chunk], (k, P.shape[-1]))
            # mapped functions exist for powers of two only (padded with the last row), so that
            # batches of ever-changing size (IK's active sets) reuse at most 13 of them
            m = 1 << (k - 1).bit_length()
            if m != k:
                q = np.vstack([q, np.repeat(q[-1:], m - k, axis=0)])
                p = np.vstack([p, np.repeat(p[-1:], m - k, axis=0)])
            T, J = self._mapped(m)(q.T, p.T)
            Ts.append(np.asarray(T).reshape(4, m, 4).transpose(1, 0, 2)[:k])
            Js.append(np.asarray(J).reshape(6, m, n).transpose(1, 0, 2)[:k])
        out: dict[str, np.ndarray] = {}
        J = np.concatenate(Js) if Js else np.zeros((0, 6, n))
        if want & WANT_T:
            out["T"] = np.concatenate(Ts) if Ts else np.zeros((0, 4, 4))
        if want & WANT_J:
            out["J"] = J
        if want & (WANT_MANIP | WANT_SIGMA):
            out["measures"] = numpy_measures(J[:, self.rows, :])
        return out


def numpy_measures(Jt: np.ndarray) -> np.ndarray:
    """Manipulability, σ_min, condition, det of task Jacobians Jt (N, m, n) → (N, 4), numpy."""
    N, m, n = Jt.shape
    out = np.full((N, 4), np.nan)
    if N == 0:
        return out
    s = np.linalg.svd(Jt, compute_uv=False)
    out[:, 1] = s[:, -1]
    with np.errstate(divide="ignore"):
        out[:, 2] = np.where(s[:, -1] > 0, s[:, 0] / np.where(s[:, -1] > 0, s[:, -1], 1.0), np.inf)
    if m == n:
        d = np.linalg.det(Jt)
        out[:, 3] = d
        out[:, 0] = np.abs(d)
    else:
        # |Π r_ii| of the QR factor of the tall matrix, accurate at singularities (see kin.compiled.kernel_source)
        A = Jt if m >= n else Jt.transpose(0, 2, 1)
        R = np.linalg.qr(A, mode="r")
        out[:, 0] = np.abs(np.prod(np.diagonal(R, axis1=-2, axis2=-1), axis=-1))
    return out


class CompiledEvaluator:
    """Evaluates through a compiled shared library (see module docstring)."""

    backend = "compiled"

    def __init__(self, sym: SymbolicChain, compiler: str, directory: Path | None = None):
        self.sym = sym
        self.n = sym.n
        self.n_p = sym.p.shape[0]
        source = self.source()
        key = hashlib.sha256("\0".join([source, compiler, " ".join(CFLAGS), KERNEL_VERSION, ca.__version__,
                                        sys.platform]).encode()).hexdigest()[:20]
        directory = directory or cache_dir()
        # the chain name only labels the file (the key identifies it); a programmatic Chain may have any name
        label = re.sub(r"[^A-Za-z0-9_]", "_", sym.chain.name)[:40]
        self.path = directory / f"rmt_{label}_{key}.so"
        self.cached = self.path.is_file()
        if not self.cached:
            self._compile(source, compiler, directory)
        # the batch entry releases the GIL (CDLL); the single-configuration entry keeps it (PyDLL),
        # which is cheaper per call and, with the lock, keeps the shared buffers consistent
        self._lib = ctypes.CDLL(str(self.path))
        f = self._lib.rmt_eval
        f.argtypes = [ctypes.c_void_p, ctypes.c_void_p, ctypes.c_longlong, ctypes.c_longlong, ctypes.c_void_p,
                      ctypes.c_void_p, ctypes.c_void_p, ctypes.c_int, ctypes.c_int]
        f.restype = ctypes.c_int
        self._eval = f
        pylib = ctypes.PyDLL(str(self.path))
        self._eval_g = pylib.rmt_eval_g
        self._eval_g.argtypes = [ctypes.c_int]
        self._eval_g.restype = ctypes.c_int
        buf = lambda name, size: np.frombuffer((ctypes.c_double * size).in_dll(pylib, name), dtype=float)
        self.q1 = buf("rmt_gq", self.n)
        self.p1 = buf("rmt_gp", max(self.n_p, 1))
        self.T1 = buf("rmt_gT", 16).reshape(4, 4)
        self.J1 = buf("rmt_gJ", 6 * self.n).reshape(6, self.n)
        self.m1 = buf("rmt_gm", 4)
        if self.n_p:
            self.p1[:] = sym.chain.parameter_values
        self.lock = threading.Lock()
        self.threads = int(os.environ.get("RMTKIT_THREADS", "0"))

    def source(self) -> str:
        """C source: CasADi's generated ``fkj`` plus the batch kernel."""
        f = self.sym.fkj_cs_function
        cg = ca.CodeGenerator("rmt_kernel.c", {"with_header": False, "casadi_real": "double",
                                                "casadi_int": "long long int"})
        cg.add(f)
        rows = self.sym.task_rows
        kernel = KERNEL_TEMPLATE.format(n=self.n, m=len(rows), np_=self.n_p, sz_w=f.sz_w(), sz_iw=f.sz_iw(),
                                        sz_arg=max(f.sz_arg(), 2), sz_res=max(f.sz_res(), 2),
                                        rows=", ".join(str(r) for r in rows))
        return "#ifdef _OPENMP\n#include <omp.h>\n#endif\n" + cg.dump() + kernel

    def _compile(self, source: str, compiler: str, directory: Path) -> None:
        directory.mkdir(parents=True, exist_ok=True)
        with tempfile.TemporaryDirectory(dir=directory) as tmp:
            c_file = Path(tmp) / "kernel.c"
            c_file.write_text(source)
            so = Path(tmp) / "kernel.so"
            proc = subprocess.run([compiler, *CFLAGS, str(c_file), "-o", str(so), "-lm"],
                                  capture_output=True, text=True)
            if proc.returncode != 0:
                raise CompileError(f"{compiler} failed on the generated kernel of {self.sym.chain.name}: "
                                   f"{proc.stderr.strip().splitlines()[-1] if proc.stderr.strip() else proc.returncode}")
            os.replace(so, self.path)  # atomic: a concurrent reader sees the old file or the whole new one

    def evaluate(self, Q: np.ndarray, P: np.ndarray, want: int = WANT_ALL) -> dict[str, np.ndarray]:
        N = Q.shape[0]
        Q = np.ascontiguousarray(Q, dtype=float)
        if self.n_p == 0:
            P, pstride = self.p1, 0
        else:
            P = np.ascontiguousarray(P, dtype=float)
            pstride = 0 if P.ndim == 1 else self.n_p
        out: dict[str, np.ndarray] = {}
        T = np.empty((N, 4, 4)) if want & WANT_T else None
        J = np.empty((N, 6, self.n)) if want & WANT_J else None
        M = np.full((N, 4), np.nan) if want & (WANT_MANIP | WANT_SIGMA) else None
        self._eval(Q.ctypes.data, P.ctypes.data, N, pstride, None if T is None else T.ctypes.data,
                   None if J is None else J.ctypes.data, None if M is None else M.ctypes.data, want, self.threads)
        if T is not None:
            out["T"] = T
        if J is not None:
            out["J"] = J
        if M is not None:
            out["measures"] = M
        return out

    def one(self, q, want: int) -> int:
        """Single configuration, nominal parameters, into the library's buffers ``T1 J1 m1``.

        Call with :attr:`lock` held and copy the results out before releasing it.  Returns 0, or
        −(1 + i) when joint i of ``q`` is not finite.
        """
        self.q1[:] = q
        return self._eval_g(want)


def make_evaluator(sym: SymbolicChain, backend: str = "auto") -> CompiledEvaluator | VMEvaluator:
    """A compiled evaluator when a C compiler works, else the CasADi-VM one.

    ``backend``: ``"auto"`` (compiled, falling back to the VM with a warning), ``"compiled"`` (raise
    :class:`CompileError` instead of falling back) or ``"vm"``.
    """
    if backend not in ("auto", "compiled", "vm"):
        raise ValueError(f"backend {backend!r} unknown; allowed: auto, compiled, vm")
    if backend == "vm":
        return VMEvaluator(sym)
    compiler = find_compiler()
    if compiler is None:
        if backend == "compiled":
            raise CompileError("no C compiler found (set CC or RMTKIT_CC)")
        return VMEvaluator(sym)
    try:
        return CompiledEvaluator(sym, compiler)
    except (CompileError, OSError) as e:
        if backend == "compiled":
            raise CompileError(str(e)) from None
        warnings.warn(f"rmtkit: compiling the kernel failed, using CasADi's VM instead ({e})", RuntimeWarning,
                      stacklevel=2)
        return VMEvaluator(sym)

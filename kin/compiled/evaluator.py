"""Fast evaluators: the batch kernel ``kernel.c`` specialised for a chain, compiled once and cached
on disk, called through ctypes.

:class:`CompiledEvaluator` writes the chain's numbers — joint count, task rows, joint types and the
FK/Jacobian graph as an instruction table (:mod:`kin.native.graph`) — into the generated header of
``kin/compiled/kernel.c`` and builds it with :func:`kin.native.build` (native or portable flags,
cache, lock; threads as in ``kin/native/include/rmt_parallel.h``).  Without a working C compiler
(or with ``RMTKIT_CC=none``) :func:`make_evaluator` returns a :class:`VMEvaluator`, which runs the
same CasADi function in CasADi's virtual machine and computes the measures with numpy; both give
the same numbers.

All evaluators share one interface: ``evaluate(Q, P, want, out=None)`` with Q (N, n), P (n_p,) or
(N, n_p) returns a dict with any of ``T`` (N, 4, 4), ``J`` (N, 6, n), ``measures`` (N, 4) — columns
manipulability, σ_min, condition number, det (NaN for a non-square task Jacobian).  ``out`` may hand
in the arrays to fill: ``T``, ``J``, ``measures``, or single measure columns ``manipulability``,
``sigma_min``, ``condition``, ``det`` (N,) — float64, C-contiguous, writeable, of exactly that shape
(:class:`~kin.errors.OutBufferError` otherwise).
"""
from __future__ import annotations

import ctypes
import threading
from pathlib import Path
from typing import Protocol, runtime_checkable

import numpy as np

from kin.chain import MAX_PRISMATIC
from kin.errors import OutBufferError
from kin.native import (
    Header,
    build_with_extension,
    default_threads,
    graph_table,
    with_fallback,
)
from kin.symbolic import SymbolicChain
from kin.vmmap import map_rows

#: the batch kernel's C source (headers beside it: measures.h, pyext.h; shared: rmt_sincos.h and the rest)
KERNEL = Path(__file__).resolve().with_name("kernel.c")

WANT_T, WANT_J, WANT_MANIP, WANT_SIGMA = 1, 2, 4, 8
WANT_ALL = WANT_T | WANT_J | WANT_MANIP | WANT_SIGMA
MEASURE_NAMES = ("manipulability", "sigma_min", "condition", "det")
_MEASURE_WANT = (WANT_MANIP, WANT_SIGMA, WANT_SIGMA, WANT_MANIP)


def check_out(arr, shape: tuple[int, ...], name: str) -> np.ndarray:
    """``arr`` if it is a writeable C-contiguous float64 ndarray of ``shape``, else :class:`OutBufferError`."""
    if type(arr) is not np.ndarray:
        raise OutBufferError(f"out[{name!r}] is a {type(arr).__name__}; "
                             f"expected a numpy float64 array of shape {shape}")
    if arr.dtype != np.float64 or arr.shape != shape:
        raise OutBufferError(f"out[{name!r}] has dtype {arr.dtype} and shape {arr.shape}; expected float64 {shape}")
    if not arr.flags.c_contiguous or not arr.flags.writeable:
        raise OutBufferError(f"out[{name!r}] must be C-contiguous and writeable")
    return arr


def output_arrays(N: int, n: int, want: int, out: dict | None) -> dict[str, np.ndarray]:
    """The arrays a call with ``want`` fills: the validated ``out`` entries, the rest newly allocated."""
    out = dict(out or {})
    unknown = set(out) - {"T", "J", "measures", *MEASURE_NAMES}
    if unknown:
        raise OutBufferError(f"out has unknown key(s) {sorted(unknown)}; allowed: T, J, measures, "
                          + ", ".join(MEASURE_NAMES))
    res: dict[str, np.ndarray] = {}
    if want & WANT_T:
        res["T"] = check_out(out["T"], (N, 4, 4), "T") if "T" in out else np.empty((N, 4, 4))
    if want & WANT_J:
        res["J"] = check_out(out["J"], (N, 6, n), "J") if "J" in out else np.empty((N, 6, n))
    cols = [k for k in MEASURE_NAMES if k in out]
    if cols and "measures" in out:
        raise OutBufferError("out holds both 'measures' and single measure columns; give one or the other")
    for k in cols:
        res[k] = check_out(out[k], (N,), k)
    if want & (WANT_MANIP | WANT_SIGMA) and not cols:
        res["measures"] = check_out(out["measures"], (N, 4), "measures") if "measures" in out else np.empty((N, 4))
        res["measures"].fill(np.nan)
    return res


@runtime_checkable
class Evaluator(Protocol):
    """What :class:`kin.Robot` needs of an evaluator: ``backend`` (``"compiled"`` or ``"vm"``), ``n``
    joints, ``p_nominal`` design parameters, ``evaluate(Q, P, want, out)`` for a batch (N, n) →
    the arrays ``want`` asks for, and ``single_call``: whether it also evaluates one configuration
    into its own buffers (``one(q, want)`` filling ``T1``, ``J1``, ``m1`` under ``lock``)."""

    backend: str
    n: int
    single_call: bool

    def evaluate(self, Q: np.ndarray, P: np.ndarray, want: int = WANT_ALL, out: dict | None = None
                 ) -> dict[str, np.ndarray]: ...


class VMEvaluator:
    """Evaluates in CasADi's virtual machine (no compiler needed); measures computed with numpy."""

    backend = "vm"
    single_call = False

    def __init__(self, sym: SymbolicChain):
        self.sym = sym
        self.n = sym.n
        self.rows = list(sym.task_rows)
        self._f = sym.fkj_function
        self._maps: dict = {}

    def evaluate(self, Q: np.ndarray, P: np.ndarray, want: int = WANT_ALL, out: dict | None = None
                 ) -> dict[str, np.ndarray]:
        N, n = Q.shape
        res = output_arrays(N, n, want, out)
        Pn = np.broadcast_to(P, (N, P.shape[-1]))
        for s, k, (T, J) in map_rows(self._f, [Q, Pn], self._maps):
            if "T" in res:
                res["T"][s:s + k] = T
            if "J" in res:
                res["J"][s:s + k] = J
            if want & (WANT_MANIP | WANT_SIGMA):
                M = numpy_measures(J[:, self.rows, :])
                for c, name in enumerate(MEASURE_NAMES):
                    if "measures" in res and want & _MEASURE_WANT[c]:
                        res["measures"][s:s + k, c] = M[:, c]
                    elif name in res:
                        res[name][s:s + k] = M[:, c]
        return res


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
        # |Π r_ii| of the QR factor of the tall matrix, accurate at singularities (see kin/compiled/measures.h)
        A = Jt if m >= n else Jt.transpose(0, 2, 1)
        R = np.linalg.qr(A, mode="r")
        out[:, 0] = np.abs(np.prod(np.diagonal(R, axis1=-2, axis2=-1), axis=-1))
    return out


class CompiledEvaluator:
    """Evaluates through a compiled shared library (see module docstring).

    ``arch``: ``"native"`` or ``"portable"`` (default ``RMTKIT_ARCH``, else native); a native
    build the compiler rejects becomes a portable one (:attr:`arch` says which was built).
    ``threads``: threads of a batch call; ``None`` reads ``RMTKIT_THREADS`` / the CPU affinity
    at each call.  :attr:`last_threads` is how many the last batch call ran.
    """

    backend = "compiled"
    single_call = True

    def __init__(self, sym: SymbolicChain, compiler: str, directory: Path | None = None, arch: str | None = None,
                 block: int = 16):
        self.sym = sym
        self.n = sym.n
        self.n_p = sym.p.shape[0]
        self.threads: int | None = None
        self.last_threads = 0
        header = self.header(block)
        name = sym.chain.name
        lib, self.single = build_with_extension(f"fk_{name}", KERNEL, header, arch=arch, compiler=compiler,
                                                directory=directory, what=f"the batch kernel of {name}")
        self.path, self.arch, self.cached = lib.path, lib.arch, lib.cached
        # the batch entry releases the GIL (CDLL); the single-configuration entry keeps it (PyDLL),
        # which is cheaper per call and, with the lock, keeps the shared buffers consistent
        self._lib = ctypes.CDLL(str(self.path))
        f = self._lib.rmt_eval
        vp, ll = ctypes.c_void_p, ctypes.c_longlong
        f.argtypes = [vp, vp, ll, ll, vp, vp, vp, vp, vp, vp, ll, ctypes.c_int, ctypes.c_int]
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
        #: nominal design parameters, float64 (n_p,) (the single-call paths' parameters)
        self.p_nominal = np.ascontiguousarray(sym.chain.parameter_values, dtype=float)
        self.lock = threading.Lock()

    #: the library as a Python extension module (``fk(q, p)``, ``jacobian(q, p)``,
    #: ``fk_jacobian(q, p)``, ``measures(q, p, want)``, p = :attr:`p_nominal`; see
    #: ``kin/compiled/pyext.h``), or None when built without it
    single = None

    def header(self, block: int = 16) -> str:
        """The generated header of ``kernel.c`` for this chain: sizes, task rows, joint types and the
        FK/Jacobian graph (inputs cos q, sin q, q, p) as an instruction table."""
        sym = self.sym
        h = Header("the chain's numbers for kin/compiled/kernel.c")
        h.define("RMT_N", self.n).define("RMT_M", len(sym.task_rows)).define("RMT_NP", self.n_p)
        h.define("RMT_B", block).define("RMT_PRISMATIC_MAX", float(MAX_PRISMATIC))
        # a chain whose tool point never moves has no task rows: C has no empty arrays, and with
        # RMT_M = 0 the kernel never reads this placeholder
        h.array("RMT_ROWS", "int", list(sym.task_rows) or [0])
        h.array("RMT_REVOLUTE", "int", [int(j.is_revolute) for j in sym.chain.joints])
        return graph_table(sym.fkj_cs_function, "RMT_GRAPH", ["c", "s", "q", "p"], ["T", "J"], h).text()

    def evaluate(self, Q: np.ndarray, P: np.ndarray, want: int = WANT_ALL, out: dict | None = None
                 ) -> dict[str, np.ndarray]:
        N = Q.shape[0]
        Q = np.ascontiguousarray(Q, dtype=float)
        if self.n_p == 0:
            P, pstride = self.p1, 0
        else:
            P = np.ascontiguousarray(P, dtype=float)
            pstride = 0 if P.ndim == 1 else self.n_p
        res = output_arrays(N, self.n, want, out)
        ptr = lambda k: res[k].ctypes.data if k in res else None
        if "measures" in res:
            base = res["measures"].ctypes.data
            m = [base + 8 * c if want & _MEASURE_WANT[c] else None for c in range(4)]
            mstride = 4
        else:
            m = [ptr(k) if want & _MEASURE_WANT[c] else None for c, k in enumerate(MEASURE_NAMES)]
            mstride = 1
        threads = self.threads if self.threads is not None else default_threads()
        self.last_threads = self._eval(Q.ctypes.data, P.ctypes.data, N, pstride, ptr("T"), ptr("J"), *m, mstride,
                                       want, threads)
        return res

    def one(self, q, want: int) -> int:
        """Single configuration, parameters :attr:`p_nominal`, into the library's buffers ``T1 J1 m1``.

        Call with :attr:`lock` held and copy the results out before releasing it.  Returns 0, or
        −(1 + i) when joint i of ``q`` is not finite or, prismatic, beyond ±:data:`kin.chain.MAX_PRISMATIC`.
        """
        self.q1[:] = q
        if self.n_p:  # the library is shared by chains of the same structure: parameters each call
            self.p1[:] = self.p_nominal
        return self._eval_g(want)


def make_evaluator(sym: SymbolicChain, backend: str = "auto") -> Evaluator:
    """A compiled evaluator when a C compiler works, else the CasADi-VM one.

    ``backend``: ``"auto"`` (compiled, falling back to the VM with a warning), ``"compiled"`` (raise
    :class:`CompileError` instead of falling back) or ``"vm"``.
    """
    return with_fallback(backend, lambda compiler: CompiledEvaluator(sym, compiler), lambda: VMEvaluator(sym),
                         "the kernel")

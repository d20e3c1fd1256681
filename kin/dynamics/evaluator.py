"""Evaluators of a chain's inverse dynamics: the kernel ``kin/dynamics/kernel.c`` specialised by the
chain's Newton–Euler graphs, built and cached by :func:`kin.native.build`, with CasADi's virtual
machine as the fallback.

:class:`CompiledDynamics` writes the five functions of :class:`~kin.dynamics.rnea.InverseDynamics`
— τ, M, g, c and the path coefficients [A B C] — as instruction tables (:mod:`kin.native.graph`)
into the generated header of ``kernel.c`` and builds it (native or portable flags, cache, lock;
threads as in ``kin/native/include/rmt_parallel.h``), also as a CPython extension module when this
interpreter's headers are there (:attr:`CompiledDynamics.single`: one configuration per call, with
the least overhead).  Without a working C compiler (or with ``RMTKIT_CC=none``)
:func:`make_dynamics_evaluator` returns a :class:`VMDynamics`, which runs the same CasADi functions
in CasADi's virtual machine; both give the same numbers to rounding (the kernel evaluates the same
operations in the same order, without fused multiply-adds, but its own vectorised sine and cosine,
``kin/native/include/rmt_sincos.h``, may differ from libm's in the last bit).

Both share one interface: ``evaluate(name, states, P)`` with ``name`` one of :data:`FUNCTIONS`,
``states`` the validated (N, n) arrays the function takes (:data:`STATES` of them: q, then q̇ and q̈,
or q′ and q″) and P (n_p,) or (N, n_p) → float64 (N, n, cols).
"""
from __future__ import annotations

import ctypes
from pathlib import Path

import casadi as ca
import numpy as np

from kin.chain import MAX_PRISMATIC
from kin.dynamics.rnea import InverseDynamics
from kin.errors import ArgumentError
from kin.native import (
    Header,
    build_with_extension,
    default_threads,
    graph_table,
    with_fallback,
)

__all__ = ["FUNCTIONS", "STATES", "CompiledDynamics", "VMDynamics", "make_dynamics_evaluator"]

#: the kernel's C source (its extension-module part beside it: pyext.h)
KERNEL = Path(__file__).resolve().with_name("kernel.c")

#: the functions, in the kernel's order (RMT_F_* of kernel.c), and the (N, n) state arrays each takes
FUNCTIONS = ("tau", "mass_matrix", "gravity", "coriolis", "path_coefficients")
STATES = {"tau": 3, "mass_matrix": 1, "gravity": 1, "coriolis": 2, "path_coefficients": 3}
_TABLES = ("RMT_TAU", "RMT_MASS", "RMT_GRAV", "RMT_CORI", "RMT_PATH")
_STATE_NAMES = ["q", "qd", "qdd"]


def _function(dyn: InverseDynamics, name: str) -> ca.Function:
    return getattr(dyn, "tau_function" if name == "tau" else f"{name}_function")


def _check_name(name: str) -> None:
    if name not in STATES:
        raise ArgumentError(f"dynamics function {name!r} unknown; allowed: {', '.join(FUNCTIONS)}")


class VMDynamics:
    """Evaluates in CasADi's virtual machine (:meth:`InverseDynamics.evaluate`; no compiler needed)."""

    backend = "vm"
    #: no single-call extension module
    single = None

    def __init__(self, dyn: InverseDynamics):
        self.dyn = dyn
        self.n = dyn.n
        self.n_p = int(dyn.p.shape[0])
        self.p_nominal = np.ascontiguousarray(dyn.chain.parameter_values, dtype=float)

    def evaluate(self, name: str, states: list[np.ndarray], P: np.ndarray) -> np.ndarray:
        _check_name(name)
        N = len(states[0])
        P = np.ascontiguousarray(np.broadcast_to(P, (N, self.n_p)), dtype=float)
        return self.dyn.evaluate(_function(self.dyn, name), [*states, P])


class CompiledDynamics:
    """Evaluates through the compiled kernel (see the module docstring).

    ``arch``: ``"native"`` or ``"portable"`` (default ``RMTKIT_ARCH``); ``block``: lanes per block.
    ``threads``: threads of a batch call; ``None`` reads ``RMTKIT_THREADS`` / the CPU affinity at each
    call.  :attr:`last_threads` is how many the last batch call ran.
    """

    backend = "compiled"

    def __init__(self, dyn: InverseDynamics, compiler: str, directory: Path | None = None, arch: str | None = None,
                 block: int = 8):
        self.dyn = dyn
        self.n = dyn.n
        self.n_p = int(dyn.p.shape[0])
        self.threads: int | None = None
        self.last_threads = 0
        header = self.header(block)
        name = dyn.chain.name
        lib, self.single = build_with_extension(f"dyn_{name}", KERNEL, header, arch=arch, compiler=compiler,
                                                directory=directory, what=f"the dynamics kernel of {name}")
        self.path, self.arch, self.cached = lib.path, lib.arch, lib.cached
        self._lib = ctypes.CDLL(str(self.path))  # releases the GIL during a batch
        f = self._lib.rmt_dyn_eval
        vp, ll = ctypes.c_void_p, ctypes.c_longlong
        f.argtypes = [ctypes.c_int, vp, vp, vp, vp, ll, ll, vp, ctypes.c_int]
        f.restype = ctypes.c_int
        self._eval = f
        #: nominal design parameters, float64 (n_p,) (the single-call path's parameters)
        self.p_nominal = np.ascontiguousarray(dyn.chain.parameter_values, dtype=float)
        self._p_empty = np.zeros(1)

    #: the library as a Python extension module — ``tau(q, qd, qdd, p)``, ``mass_matrix(q, p)``,
    #: ``gravity(q, p)``, ``coriolis(q, qd, p)``, ``path_coefficients(q, d1, d2, p)``, one
    #: configuration each, None for any argument it does not take as it comes (see
    #: ``kin/dynamics/pyext.h``) — or None when built without it
    single = None

    def header(self, block: int = 8) -> str:
        """The generated header of ``kernel.c``: sizes, joint types and the five functions of
        :attr:`InverseDynamics.cs_functions` as instruction tables (inputs c, s, q, qd, qdd, p; output o)."""
        dyn = self.dyn
        h = Header(f"the Newton-Euler functions of {dyn.chain.name} for kin/dynamics/kernel.c")
        h.define("RMT_N", self.n).define("RMT_NP", self.n_p).define("RMT_B", block)
        h.define("RMT_PRISMATIC_MAX", float(MAX_PRISMATIC))
        h.array("RMT_REVOLUTE", "int", [int(j.is_revolute) for j in dyn.chain.joints])
        for name, table in zip(FUNCTIONS, _TABLES):
            graph_table(dyn.cs_functions[name], table, ["c", "s", "q", *_STATE_NAMES[1:STATES[name]], "p"], ["o"], h)
        return h.text()

    def evaluate(self, name: str, states: list[np.ndarray], P: np.ndarray) -> np.ndarray:
        _check_name(name)
        fun = FUNCTIONS.index(name)
        X = [np.ascontiguousarray(x, dtype=float) for x in states]
        N = len(X[0])
        if self.n_p == 0:
            P, pstride = self._p_empty, 0
        else:
            P = np.ascontiguousarray(P, dtype=float)
            pstride = 0 if P.ndim == 1 else self.n_p
        cols = 3 if name == "path_coefficients" else self.n if name == "mass_matrix" else 1
        out = np.empty((N, self.n, cols))
        ptr = [x.ctypes.data for x in X] + [None] * (3 - len(X))
        threads = self.threads if self.threads is not None else default_threads()
        self.last_threads = self._eval(fun, *ptr, P.ctypes.data, N, pstride, out.ctypes.data, threads)
        return out


def make_dynamics_evaluator(dyn: InverseDynamics, backend: str = "auto") -> CompiledDynamics | VMDynamics:
    """A compiled evaluator when a C compiler works, else the CasADi-VM one.

    ``backend``: ``"auto"`` (compiled, falling back to the VM with a warning), ``"compiled"`` (raise
    :class:`CompileError` instead of falling back) or ``"vm"``.
    """
    return with_fallback(backend, lambda compiler: CompiledDynamics(dyn, compiler), lambda: VMDynamics(dyn),
                         "the dynamics kernel")

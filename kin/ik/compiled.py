"""The compiled IK solver: the Levenberg–Marquardt loop of ``kin/ik/ik.c`` around the chain's FK
and Jacobian, compiled to a shared library by :func:`kin.native.build`, cached like the FK kernels.

The chain enters the C through its generated header (joint count and the FK/Jacobian graph as an
instruction table, :mod:`kin.native.graph`); the library is built once per chain (cached on disk
under ``cache_dir()/native``), loaded with ctypes and called once per batch: the whole iteration,
every restart and every target run in C, targets spread over POSIX threads (``threads``; default
``$RMTKIT_THREADS`` or the CPUs this process may use).  No Python runs per iteration.  The method
(starts, stagnation, the reach test) is described at the top of ``ik.c``.
"""
from __future__ import annotations

import ctypes
import math
import threading
import weakref
from pathlib import Path

import numpy as np

from kin.errors import CompileError
from kin.ik.numeric import _length_scale
from kin.native import Header, build, default_threads, find_compiler, graph_table

#: the IK solver's C source
IK_SOURCE = Path(__file__).resolve().with_name("ik.c")
#: GCC 12's straight-line (SLP) vectoriser fuses a·b ± c into one rounding (vfmaddsub) despite
#: -ffp-contract=off; the IK iterates, so one such rounding changes iteration counts.  Without it
#: the native build gives the portable build's numbers exactly (and is ~10 % faster than it).
IK_FLAGS = ("-fno-tree-slp-vectorize",)
_dbl = ctypes.c_double
_ptr = ctypes.c_void_p


class ReachBound:
    """Upper bounds of how far the chain reaches, for the early "out of reach" verdict.

    From frame k's origin to frame m's (standard DH) the chain moves by Σ (d_i·z_{i−1} + a_i·x_i),
    i = k+1…m, with z_{i−1} ⟂ x_i and x_i ⟂ z_i: so the distance is at most Σ √(a_i² + d_i²) and
    also at most |d_{k+1}| + Σ √(a_i² + d_{i+1}²) + |a_m| (d over its range for a prismatic joint);
    the smaller sum is the bound (the second is exact for an elbow offset followed by a forearm).
    In modified DH the first sum is used.  The tool adds the length of its offset.

    A pose target fixes more than the tool point: for a standard-DH chain whose last joint is
    revolute, frame n − 1's origin o_{n−1} = o_n − a_n·x_n − d_n·z_{n−1} follows from the target
    (z_{n−1} = R_n·(0, sin α_n, cos α_n)), and it must lie within reach of rows 1…n−1 — for a
    spherical wrist, the wrist centre.  For a revolute first joint (standard DH) frame 1's origin lies
    on a circle of radius |a₁| at height d₁ about joint 1's axis, and the rest of the chain reaches
    from there: this sharpens either bound.
    """

    def __init__(self, chain, params: np.ndarray | None = None):
        tab = chain.dh_table(params)
        self.a = np.abs(tab[:, 0])
        d = np.abs(tab[:, 2])
        for i, j in enumerate(chain.joints):
            if not j.is_revolute:
                d[i] = max(abs(tab[i, 2] + j.limits[0]), abs(tab[i, 2] + j.limits[1]))
        self.d = d
        self.base, self.tool = chain.base.matrix, chain.tool.matrix
        self.standard = chain.convention == "standard"
        self.circle = self.standard and chain.joints[0].is_revolute
        self.a1, self.d1 = abs(tab[0, 0]), tab[0, 2]
        last = tab[-1]
        self.wrist = self.standard and chain.joints[-1].is_revolute and chain.n > 1
        self.last = (last[0], np.array([0.0, math.sin(last[1]), math.cos(last[1])]), last[2])

    def between(self, k: int, m: int) -> float:
        """Bound (m) of the distance from frame k's origin to frame m's (0: the base frame)."""
        if m <= k:
            return 0.0
        a, d = self.a[k:m], self.d[k:m]
        rows = float(np.hypot(a, d).sum())
        if not self.standard:
            return rows
        return min(rows, float(d[0] + np.hypot(a[:-1], d[1:]).sum() + a[-1]))

    def constants(self) -> np.ndarray:
        """The bound as the 62 numbers the C test reads: base⁻¹ (16, row-major), 16 unused, the bounds
        from the base of the tool point and of frame n − 1's origin, 0, |a₁|, d₁, circle and wrist
        flags, a_n, (0, sin α_n, cos α_n), d_n, the same two bounds from frame 1's origin, tool⁻¹ (16)."""
        a, zl, d = self.last
        n = len(self.a)
        tool = float(np.linalg.norm(self.tool[:3, 3]))
        return np.concatenate([np.linalg.inv(self.base).ravel(),
                               np.zeros(16),
                               [self.between(0, n) + tool, self.between(0, n - 1), 0.0, self.a1, self.d1,
                                float(self.circle), float(self.wrist), a, *zl, d,
                                self.between(1, n) + tool, self.between(1, n - 1)],
               np.linalg.inv(self.tool).ravel()])


class CompiledIK:
    """The compiled solver of one chain; build with :func:`compiled_ik`."""

    def __init__(self, robot, compiler: str, directory: Path | None = None):
        sym = robot.symbolic
        self.chain = robot.chain
        self.n = sym.n
        self.n_p = int(sym.p.shape[0])
        built = build(f"ik_{self.chain.name}", IK_SOURCE, self.header(sym), flags=IK_FLAGS, compiler=compiler,
                      directory=directory, what=f"the IK solver of {self.chain.name}")
        self.path, self.arch, self.cached = built.path, built.arch, built.cached
        lib = ctypes.CDLL(str(built.path))   # CDLL: the call releases the GIL
        f = lib.rmtik_solve
        f.argtypes = [_ptr, _ptr, _ptr, ctypes.c_longlong, _ptr, ctypes.c_longlong, _ptr, _ptr, _ptr,
                      ctypes.c_longlong, ctypes.c_int, _dbl, _dbl, _dbl, _dbl, ctypes.c_int, ctypes.c_int,
                      ctypes.c_ulonglong, ctypes.c_int, _ptr, _ptr, _ptr, _ptr, _ptr, _ptr]
        f.restype = ctypes.c_int
        self._solve = f
        self._lib = lib
        self.lo = np.ascontiguousarray(self.chain.lower, dtype=float)
        self.hi = np.ascontiguousarray(self.chain.upper, dtype=float)
        self._p0 = np.ascontiguousarray(self.chain.parameter_values if self.n_p else np.zeros(1))
        #: threads of a batch call; None: ``$RMTKIT_THREADS`` or the CPUs this process may use, at each call
        self.threads: int | None = None
        self._lo_p, self._hi_p = self.lo.ctypes.data, self.hi.ctypes.data
        self._rb = ReachBound(self.chain).constants()
        self._p0_p, self._rb_p = self._p0.ctypes.data, self._rb.ctypes.data
        self._one = None
        self.weight = _length_scale(self.chain)
        lib.rmtik_beyond_batch.argtypes = [_ptr, _ptr, _ptr, ctypes.c_longlong, _ptr]
        lib.rmtik_beyond_batch.restype = None

    @staticmethod
    def header(sym) -> str:
        """The generated header of ``ik.c``: the joint count and the graph of (q, p) → (T, J)."""
        h = Header("the chain's numbers for kin/ik/ik.c").define("RMT_N", sym.n)
        return graph_table(sym.fkj_function, "RMT_GRAPH", ["q", "p"], ["T", "J"], h).text()

    def beyond(self, Pt: np.ndarray, Rt: np.ndarray | None = None, params: np.ndarray | None = None) -> np.ndarray:
        """(N,) bool: the targets (positions (N, 3), rotations (N, 3, 3) or None) certainly out of reach
        (:class:`ReachBound`, evaluated by the C test the solver uses)."""
        Pt = np.ascontiguousarray(Pt, dtype=float)
        Rt = None if Rt is None else np.ascontiguousarray(Rt, dtype=float)
        rb = self._rb if params is None else ReachBound(self.chain, params).constants()
        out = np.zeros(len(Pt), np.uint8)
        self._lib.rmtik_beyond_batch(rb.ctypes.data, Pt.ctypes.data, None if Rt is None else Rt.ctypes.data,
                                     ctypes.c_longlong(len(Pt)), out.ctypes.data)
        return out.astype(bool)

    def solve(self, Pt: np.ndarray, Rt: np.ndarray | None, Q0: np.ndarray | None, P: np.ndarray | None = None, *,
              seed: int = 0, max_starts: int = 97, max_iter: int = 150, tol_position: float = 1e-6,
              tol_orientation: float = 1e-6, tol_cost: float | None = None, reach: bool = True,
              threads: int | None = None) -> dict[str, np.ndarray]:
        """Solve N targets in one call.

        Pt (N, 3) m; Rt (N, 3, 3) or None (position mode); Q0 (n,) or (N, n) first start (None: random
        starts only); P design parameters (n_p,) or (N, n_p), None nominal; ``tol_cost``: the
        squared weighted error at which a start stops (default 10⁻⁸ of the tolerances, squared);
        ``reach``: give targets beyond :class:`ReachBound` 8 starts only (per-target parameters
        skip the test).  Returns a dict of ``q`` (N, n), ``success`` (N,) bool, ``position_error``,
        ``orientation_error`` (N,), ``starts`` and ``iterations`` (N,) int.
        """
        N, n = len(Pt), self.n
        if N == 1 and P is None and Q0 is None and reach and tol_cost is None and threads is None:
            return self._solve_one(Pt[0], None if Rt is None else Rt[0], seed, max_starts, max_iter,
                                   tol_position, tol_orientation)
        Pt = np.ascontiguousarray(Pt, dtype=float)
        Rt = None if Rt is None else np.ascontiguousarray(Rt, dtype=float)
        rb = self._rb if reach else None
        if P is None or self.n_p == 0:
            P, pstride = self._p0, 0
        else:
            P = np.ascontiguousarray(P, dtype=float)
            pstride = self.n_p if P.ndim == 2 else 0
            if reach:
                rb = None if P.ndim == 2 else ReachBound(self.chain, P).constants()
        q0stride = 0
        if Q0 is not None:
            Q0 = np.ascontiguousarray(Q0, dtype=float)
            q0stride = n if Q0.ndim == 2 else 0
        if tol_cost is None:
            tol_cost = (min(tol_position, tol_orientation * self.weight) * 1e-4) ** 2
        # one output block: q (n), pe, oe, then three ints per target stored as doubles' worth of space
        q = np.empty((N, n))
        errs = np.empty((2, N))
        ints = np.empty((3, N), np.intc)
        ad = ints.ctypes.data
        self._solve(Pt.ctypes.data, None if Rt is None else Rt.ctypes.data, P.ctypes.data, pstride,
                    None if Q0 is None else Q0.ctypes.data, q0stride, self._lo_p, self._hi_p,
                    None if rb is None else rb.ctypes.data,
                    N, int(Rt is not None), self.weight, float(tol_position), float(tol_orientation),
                    float(tol_cost), int(max_iter), max(int(max_starts), 1), int(seed) & 0xFFFFFFFFFFFFFFFF,
                    self._threads(threads),
                    q.ctypes.data, errs.ctypes.data, errs.ctypes.data + 8 * N, ad, ad + 4 * N, ad + 8 * N)
        return {"q": q, "success": ints[0].astype(bool), "position_error": errs[0], "orientation_error": errs[1],
                "starts": ints[1], "iterations": ints[2]}


    def _threads(self, threads: int | None) -> int:
        k = self.threads if threads is None else int(threads)
        return k if k is not None and k > 0 else default_threads()

    def _solve_one(self, pt, R, seed, max_starts, max_iter, tol_position, tol_orientation) -> dict[str, np.ndarray]:
        """:meth:`solve` for one target without warm start, nominal parameters: through buffers whose
        addresses are known (numpy's ``.ctypes`` and allocations cost more than the C call's set-up)."""
        b = self._one
        if b is None:
            n = self.n
            arrs = (np.empty(3), np.empty(9), np.empty(n), np.empty(2), np.empty(3, np.intc))
            b = self._one = (arrs, tuple(a.ctypes.data for a in arrs), threading.Lock())
        (bp, bR, bq, be, bi), (ap, aR, aq, ae, ai), lock = b
        tol_cost = (min(tol_position, tol_orientation * self.weight) * 1e-4) ** 2
        with lock:
            bp[:] = pt
            if R is not None:
                bR[:] = R.ravel()
            self._solve(ap, None if R is None else aR, self._p0_p, 0, None, 0, self._lo_p, self._hi_p,
                        self._rb_p, 1, int(R is not None), self.weight, float(tol_position), float(tol_orientation),
                        tol_cost, int(max_iter), max(int(max_starts), 1), int(seed) & 0xFFFFFFFFFFFFFFFF, 1,
                        aq, ae, ae + 8, ai, ai + 4, ai + 8)
            q, e, i = bq.copy(), be.copy(), bi.copy()
        return {"q": q[None], "success": i[:1].astype(bool), "position_error": e[:1], "orientation_error": e[1:],
                "starts": i[1:2], "iterations": i[2:]}


_cache: weakref.WeakKeyDictionary[object, CompiledIK | None] = weakref.WeakKeyDictionary()
_lock = threading.Lock()


def compiled_ik(robot) -> CompiledIK | None:
    """The compiled solver of ``robot`` (built on first use, then kept), or None when there is no
    working C compiler (``RMTKIT_CC=none``), the robot asks for the ``vm`` backend, or compiling
    fails — the caller then uses the numpy solver."""
    try:
        return _cache[robot]
    except KeyError:
        pass
    with _lock:
        if robot in _cache:
            return _cache[robot]
        solver = None
        compiler = find_compiler()
        if compiler is not None and robot.backend_request != "vm":
            try:
                solver = CompiledIK(robot, compiler)
            except (CompileError, OSError):
                if robot.backend_request == "compiled":
                    raise
                solver = None
        _cache[robot] = solver
        return solver

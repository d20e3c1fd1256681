""":class:`MotionChecker`: is a configuration valid, is a straight joint motion proven valid — one native
call each (``motion.c`` beside this module; its first comment states the proof).

Valid means: inside the joint limits, outside every interval window (a slab lo ≤ q_j ≤ hi of one joint),
and, with a collision world (:class:`planning.collision.CollisionWorld`), every capsule of the robot
clear of the cell and of the bodies it is checked against by more than the world's margin.  A motion is
valid when it is *proven* so: states along it are placed so that no point of the robot moves more than
``step`` metres (first-order bound) between two of them, and the region each capsule sweeps between two
states is enclosed by a capsule around its chord, widened by a bound on the path's curvature
(:func:`kin.geometry.motion.curvature_bound`); an interval whose swept regions are not all clear is
cut into eight up to ``max_depth`` times.  A motion that is neither proven nor refuted within the budget is
reported as ``"unproven"`` (a planner treats it as invalid).

The library is built on first use as a CPython extension module when Python's headers are there, so
that OMPL's callbacks (:meth:`MotionChecker.ompl_state`, :meth:`MotionChecker.ompl_motion`) reach C in
one call; otherwise through ctypes.  Without a C compiler there is no checker (:func:`available` is
False) and the planner keeps its Python path.
"""
from __future__ import annotations

import ctypes
import functools
import math
import threading
import warnings
from pathlib import Path
from typing import NamedTuple

import numpy as np

import kin.geometry as kin_geometry
from kin.errors import CompileError
from kin.geometry.motion import _walks, capsule_radii
from kin.native import build_with_extension, find_compiler
from planning.errors import PlanningError

__all__ = ["MotionChecker", "MotionCheck", "available", "checker_for", "groups", "DEFAULT_STEP", "MAX_DEPTH",
           "MAX_EVALS", "MAX_STATES"]

SOURCE = Path(__file__).resolve().with_name("motion.c")
#: the clearance kernel's folder (motion.c includes clearance.c and clearance.h from it)
CLEARANCE_DIR = Path(kin_geometry.__file__).resolve().parent
#: m: the most any point of the robot moves (first-order bound) between two placed states of a motion
DEFAULT_STEP = 0.1
#: eightfold cuts of an interval between two placed states before it is left unproven (8⁻⁷ of it)
MAX_DEPTH = 7
#: most states placed in a motion's first pass (longer motions get wider intervals)
MAX_STATES = 4096
#: most states placed for one motion, refinement included (a motion that grazes its margin tangentially
#: can never be proven; this bounds what trying costs)
MAX_EVALS = 20_000
#: capsules per group of the hierarchy body ball → group balls → capsules
GROUP_SIZE = 4
#: random shortcuts tried at most, and failures in a row after which shortening stops
SHORTCUT_TRIES = 100
SHORTCUT_PATIENCE = 15
#: the longest path shortened (rows; shortcut.h)
MAX_ROWS = 4096
STATUS = {1: "clear", 0: "collision", -1: "unproven", -2: "bad", 2: "limits", 3: "window"}


class _Result(ctypes.Structure):
    _fields_ = [("status", ctypes.c_int), ("t", ctypes.c_double), ("evals", ctypes.c_longlong),
                ("states", ctypes.c_longlong), ("bound", ctypes.c_double)]


class MotionCheck(NamedTuple):
    """Outcome of :meth:`MotionChecker.check`: ``status`` (``"clear"`` — proven —, ``"collision"``,
    ``"unproven"``, ``"limits"``, ``"window"``, ``"bad"``: a value that is not finite or a prismatic
    value beyond its bound), ``t`` (the motion parameter of the violation found, NaN otherwise),
    ``evals`` (states placed), ``states`` (of the first pass), ``bound`` (with ``bound=True`` and a
    proven motion: a lower bound of the clearance along it, m; inf when nothing comes within the cap)."""

    status: str
    t: float
    evals: int
    states: int
    bound: float

    @property
    def proven(self) -> bool:
        return self.status == "clear"


_lock = threading.Lock()
_cache_lock = threading.RLock()
_loaded: dict[str, object] = {}


def _load():
    """(ctypes library, extension module or None) of the built checker, or None without a compiler."""
    compiler = find_compiler()
    if compiler is None:
        return None
    with _lock:
        if compiler in _loaded:
            return _loaded[compiler]
        try:
            from kin.native.builder import library_dir
            from kin.native.settings import requested_arch
            lib, ext = build_with_extension("planning_motion", SOURCE, "", arch=requested_arch(), compiler=compiler,
                                            directory=library_dir(), what="the motion checker",
                                            include_dirs=(CLEARANCE_DIR,))
            dll = ctypes.PyDLL(str(lib.path))
        except (CompileError, OSError) as e:
            warnings.warn(f"rmtkit: compiling the motion checker failed; planning checks motions in Python ({e})",
                          RuntimeWarning, stacklevel=3)
            _loaded[compiler] = None
            return None
        p, ll, d = ctypes.c_void_p, ctypes.c_longlong, ctypes.c_double
        dll.rmt_motion_new.argtypes = [p, ll, d, p, p, p, p, p, ll, p, ll, p, p, p, p, d, d, ll, ctypes.c_int, ll]
        dll.rmt_motion_new.restype = p
        dll.rmt_motion_free.argtypes = [p]
        dll.rmt_motion_free.restype = None
        dll.rmt_motion_state.argtypes = [p, p]
        dll.rmt_motion_state.restype = ctypes.c_int
        dll.rmt_motion_check.argtypes = [p, p, p, ctypes.c_int, ctypes.c_int, p]
        dll.rmt_motion_check.restype = ctypes.c_int
        dll.rmt_motion_shortcut.argtypes = [p, p, ll, ll, ctypes.c_ulonglong, ll, ll, p]
        dll.rmt_motion_shortcut.restype = ll
        _loaded[compiler] = (dll, ext)
        return _loaded[compiler]


def available() -> bool:
    """Whether the native checker can be built here (a working C compiler)."""
    return _load() is not None


def groups(model, size: int = GROUP_SIZE) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Each body's capsules (the kernel's order) split into groups of at most ``size`` nearby ones, each
    inside a ball: ``gbeg`` (B + 1,) — body b's groups are gbeg[b] … gbeg[b + 1] − 1; ``cbeg`` (G + 1,) —
    group g's capsules are gcap[cbeg[g]] … gcap[cbeg[g + 1] − 1]; ``gcap`` (C,) capsule indices, group by
    group; ``gball`` (G, 4): each group's ball (centre in its body's frame, radius, m), holding every
    capsule of the group.  Split by halves along the widest spread of the capsules' middles."""
    flat = model._flat
    cap = flat.cap
    B = flat.nbody
    gbeg, cbeg, gcap, balls = [0], [0], [], []

    def split(idx: np.ndarray) -> list[np.ndarray]:
        if len(idx) <= size:
            return [idx]
        mid = 0.5 * (cap[idx, :3] + cap[idx, 3:6])
        axis = int(np.argmax(mid.max(axis=0) - mid.min(axis=0)))
        order = idx[np.argsort(mid[:, axis], kind="stable")]
        h = len(order) // 2
        return split(order[:h]) + split(order[h:])

    for b in range(B):
        idx = np.arange(flat.body_cap[b], flat.body_cap[b + 1])
        for g in (split(idx) if len(idx) else []):
            ends = np.vstack([cap[g, :3], cap[g, 3:6]])
            centre = 0.5 * (ends.min(axis=0) + ends.max(axis=0))
            r = np.concatenate([cap[g, 6], cap[g, 6]])
            radius = float((np.linalg.norm(ends - centre, axis=1) + r).max()) * (1 + 1e-12) + 1e-9
            gcap.extend(int(c) for c in g)
            cbeg.append(len(gcap))
            balls.append([*centre, radius])
        gbeg.append(len(balls))
    return (np.array(gbeg, np.int64), np.array(cbeg, np.int64), np.array(gcap, np.int64).reshape(-1),
            np.array(balls, float).reshape(-1, 4))


def _ball_radii(chain, model, gball: np.ndarray, gbeg: np.ndarray) -> np.ndarray:
    """(n + 2 + G, n): the first-order bound R for every point of each body's bounding ball (the kernel's
    ``body_sphere``), then of each group's ball: the walk of :func:`kin.geometry.motion.reach_radii` plus
    the ball's reach."""
    n = chain.n
    W = _walks(chain)
    rev = chain.revolute_mask
    balls = model._flat.body_sphere
    body_of = np.repeat(np.arange(n + 2), np.diff(gbeg))
    rows = [(k, balls[k]) for k in range(n + 2)] + [(int(body_of[g]), gball[g]) for g in range(len(gball))]
    R = np.zeros((len(rows), n))
    for i, (k, ball) in enumerate(rows):
        reach = float(np.linalg.norm(ball[:3]) + ball[3])
        moved = min(k, n)                     # joints 1 … k move body k (the tool: all of them)
        R[i, :moved] = np.where(rev[:moved], W[:moved, k] + reach, 1.0)
    return R


_tables: dict[bytes, tuple] = {}


def _robot_tables(chain, model) -> tuple:
    """(R, gbeg, cbeg, gcap, gball, Rb) of a model: what depends on the robot and its tool only, made
    once per robot (a new cell, as each MotionBenchMaker problem has, reuses them)."""
    import hashlib
    flat = model._flat
    h = hashlib.sha1()
    for a in (flat.dh, flat.cap, flat.body_cap, flat.body_sphere, flat.capsule_index, flat.tool,
              chain.lower, chain.upper, chain.revolute_mask):
        h.update(np.ascontiguousarray(a).tobytes())
    h.update(chain.convention.encode())
    key = h.digest()
    with _cache_lock:
        hit = _tables.get(key)
    if hit is not None:
        return hit
    n = chain.n
    R = capsule_radii(chain, model.geometry)[flat.capsule_index] if len(flat.cap) else np.zeros((0, n))
    R = np.ascontiguousarray(R.reshape(-1, n) if R.size else np.zeros((1, n)))
    gbeg, cbeg, gcap, gball = groups(model)
    Rb = np.ascontiguousarray(_ball_radii(chain, model, gball, gbeg))
    out = (R, gbeg, cbeg, gcap, gball, Rb)
    for a in out:
        a.setflags(write=False)
    with _cache_lock:
        if len(_tables) > 64:
            _tables.clear()
        _tables[key] = out
    return out


class MotionChecker:
    """State and motion validity for ``robot`` (a :class:`kin.Robot`) in ``world`` (a
    :class:`planning.collision.CollisionWorld`, or None: no collisions), outside the interval windows
    ``intervals`` (a sequence of (joint index from 0, lo, hi), SI).

    ``limits=False`` leaves the joint limits out (collision proofs of paths that report limits apart);
    ``step`` (m), ``max_depth``, ``max_states``, ``max_evals``: the proof's resolution and budget (see the
    module docstring).  Raises :class:`PlanningError` when no C compiler is available (:func:`available`).
    """

    def __init__(self, robot, world=None, intervals=(), *, limits: bool = True, step: float = DEFAULT_STEP,
                 max_depth: int = MAX_DEPTH, max_states: int = MAX_STATES, max_evals: int = MAX_EVALS):
        fns = _load()
        if fns is None:
            raise PlanningError("the native motion checker needs a C compiler (none found, or it failed)")
        self._dll, self._ext = fns
        chain = robot.chain
        self.chain = chain
        self.n = n = chain.n
        if world is not None and world.chain != chain:
            raise PlanningError(f"the collision world is for {world.chain.name}, not {chain.name}")
        if not (math.isfinite(step) and step > 0):
            raise PlanningError(f"motion check step {step!r} must be a positive number of metres")
        self.world = world
        self.step = float(step)
        self.lower = np.ascontiguousarray(chain.lower if limits else np.full(n, -np.inf), dtype=float)
        self.upper = np.ascontiguousarray(chain.upper if limits else np.full(n, np.inf), dtype=float)
        self.revolute = np.ascontiguousarray(chain.revolute_mask, dtype=np.int64)
        win = np.array([(float(j), float(lo), float(hi)) for j, lo, hi in intervals], dtype=float).reshape(-1, 3)
        if len(win) and ((win[:, 0] < 0) | (win[:, 0] >= n)).any():
            raise PlanningError(f"interval windows name joints outside 0 … {n - 1}")
        self.intervals = np.ascontiguousarray(win)
        model = None if world is None else world.model
        if model is not None and getattr(model, "backend", "") != "compiled":
            model = None
            raise PlanningError("the native motion checker needs the compiled clearance kernel")
        self.model = model
        if model is not None:
            self.R, self.gbeg, self.cbeg, self.gcap, self.gball, self.Rb = _robot_tables(chain, model)
            struct, mp, margin, cap = model._struct, model._mp, world.margin, model.cap
        else:
            self.R = np.zeros((1, n))
            self.gbeg, self.cbeg = np.zeros(n + 3, np.int64), np.zeros(1, np.int64)
            self.gcap, self.gball = np.zeros(1, np.int64), np.zeros((1, 4))
            self.Rb = np.zeros((n + 2, n))
            struct, mp, margin, cap = None, None, 0.0, 1.0
        ngroup = len(self.cbeg) - 1
        self.gcap = np.ascontiguousarray(self.gcap if len(self.gcap) else np.zeros(1, np.int64))
        self.gball = np.ascontiguousarray(self.gball if len(self.gball) else np.zeros((1, 4)))
        keep = (struct, model, self.lower, self.upper, self.R, self.Rb, self.revolute, self.intervals, self.gbeg,
                self.cbeg, self.gcap, self.gball)
        ptr = self._dll.rmt_motion_new(mp, n, float(margin), self.lower.ctypes.data, self.upper.ctypes.data,
                                      self.R.ctypes.data, self.Rb.ctypes.data, self.revolute.ctypes.data,
                                      len(self.intervals), self.intervals.ctypes.data if len(self.intervals) else None,
                                      ngroup, self.gbeg.ctypes.data, self.cbeg.ctypes.data, self.gcap.ctypes.data,
                                      self.gball.ctypes.data, self.step, float(cap), int(max_states), int(max_depth),
                                      int(max_evals))
        if not ptr:
            raise PlanningError("the motion checker could not be made (out of memory, or more than 63 joints)")
        if self._ext is not None:
            self._handle = self._ext.wrap(ptr, keep)          # owns the C checker from here on
            self._ptr = ptr
        else:
            self._handle = None
            self._ptr = ptr
            self._finalizer = _Freer(self._dll, ptr, keep)
        self._q = np.zeros(n)
        self._count = [0]
        self._r = _Result()
        self._rp = ctypes.addressof(self._r)

    # ---- questions --------------------------------------------------------------------------------------
    def state_valid(self, q) -> bool:
        """Whether configuration ``q`` (n,) is valid."""
        return self.state_status(q) == "clear"

    def state_status(self, q) -> str:
        """``"clear"`` or why ``q`` is not valid (``"limits"``, ``"window"``, ``"collision"``, ``"bad"``)."""
        Q = self._vec(q, "q")
        return STATUS[self._dll.rmt_motion_state(self._ptr, Q.ctypes.data)]

    def motion_valid(self, a, b) -> bool:
        """Whether the straight motion ``a`` → ``b`` is proven valid."""
        return self.check(a, b).proven

    def check(self, a, b, *, ordered: bool = False, bound: bool = False) -> MotionCheck:
        """The motion ``a`` → ``b`` (n each, SI): :class:`MotionCheck`.  ``ordered``: the violation
        reported is the first along the motion (else the first found, states spread over the motion
        first); ``bound``: measure a lower bound of the clearance along a proven motion (slower)."""
        A = self._vec(a, "a")
        B = np.ascontiguousarray(self._vec(b, "b").copy())
        self._dll.rmt_motion_check(self._ptr, A.ctypes.data, B.ctypes.data, int(ordered), int(bound), self._rp)
        r = self._r
        return MotionCheck(STATUS[r.status], r.t, int(r.evals), int(r.states), r.bound)

    def shortcut(self, path, seed: int = 0, tries: int = SHORTCUT_TRIES, patience: int = SHORTCUT_PATIENCE
                 ) -> tuple[np.ndarray, int]:
        """A shorter path with the same ends (M', n) and the motions checked: rows that a proven motion
        can skip go, then random shortcuts between points along the path (``tries`` at most, stopping
        after ``patience`` failures in a row; ``seed`` makes the draws repeatable), then rows again
        (``shortcut.h``).  Every motion of the result is proven when every motion of ``path`` was."""
        P = np.asarray(path, dtype=float)
        if P.ndim != 2 or P.shape[1] != self.n:
            raise PlanningError(f"path has shape {P.shape}; expected (M, {self.n})")
        M = len(P)
        if M < 3 or M > MAX_ROWS:
            return P.copy(), 0
        cap = min(MAX_ROWS, M + 2 * int(tries) + 2)
        buf = np.zeros((cap, self.n))
        buf[:M] = P
        checks = ctypes.c_longlong(0)
        M2 = self._dll.rmt_motion_shortcut(self._ptr, buf.ctypes.data, M, cap, int(seed) & (2**64 - 1), int(tries),
                                           int(patience), ctypes.addressof(checks))
        return buf[:M2].copy(), int(checks.value)

    def _vec(self, q, what: str) -> np.ndarray:
        Q = np.ascontiguousarray(q, dtype=float)
        if Q.shape != (self.n,):
            raise PlanningError(f"{what} has shape {Q.shape}; expected ({self.n},)")
        return Q

    # ---- OMPL's callbacks ---------------------------------------------------------------------------------
    def ompl_state(self):
        """A callable for ``SpaceInformation.setStateValidityChecker``: state → bool, one C call."""
        if self._ext is not None:
            return functools.partial(self._ext.state, self._handle)
        n, dll, ptr, buf = self.n, self._dll, self._ptr, (ctypes.c_double * self.n)()

        def state(s) -> bool:
            for i in range(n):
                buf[i] = s[i]
            return dll.rmt_motion_state(ptr, buf) == 1

        return state

    def ompl_motion(self):
        """A callable (s1, s2) → bool for a :class:`ompl.base.MotionValidator`'s ``checkMotion``; each
        call counts (:meth:`motion_calls`)."""
        if self._ext is not None:
            return functools.partial(self._ext.motion, self._handle)
        n, dll, ptr, rp, count = self.n, self._dll, self._ptr, self._rp, self._count
        a, b = (ctypes.c_double * n)(), (ctypes.c_double * n)()

        def motion(s1, s2) -> bool:
            count[0] += 1
            for i in range(n):
                a[i] = s1[i]
                b[i] = s2[i]
            return dll.rmt_motion_check(ptr, a, b, 0, 0, rp) == 1

        return motion

    def motion_calls(self):
        """A callable giving how many motions the :meth:`ompl_motion` callables have checked so far (a
        planner's budget counted in motions, the same on every machine)."""
        if self._ext is not None:
            return functools.partial(self._ext.calls, self._handle)
        count = self._count
        return lambda: count[0]


def checker_for(world, intervals=(), limits: bool = True) -> MotionChecker | None:
    """The native checker of ``world`` (a :class:`planning.collision.CollisionWorld`) with these interval
    windows and limits, made once per world and kept on it (its model must not have moved since:
    :meth:`CollisionWorld.move_base` drops them); None where no checker can be built."""
    if world is None or not available() or getattr(world.model, "backend", "") != "compiled":
        return None
    key = (tuple((int(j), float(lo), float(hi)) for j, lo, hi in intervals), bool(limits), world.model._mp)
    with _cache_lock:
        cache = world.__dict__.setdefault("_motion_checkers", {})
        chk = cache.get(key)
        if chk is None:
            chk = cache[key] = MotionChecker(world.robot, world, key[0], limits=limits)
        return chk


class _Freer:
    """Frees a ctypes-owned checker when the Python checker is collected (the extension's capsule does
    it otherwise)."""

    def __init__(self, dll, ptr, keep):
        self.dll, self.ptr, self.keep = dll, ptr, keep

    def __del__(self):
        try:
            self.dll.rmt_motion_free(self.ptr)
        except Exception:       # interpreter shutdown
            pass

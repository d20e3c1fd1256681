"""Dense joint-path validation, independent of any planner.

A joint path is a sequence of configurations joined by straight segments in joint space.
:func:`check_path` interpolates every segment at a fine step (default 0.1° for revolute joints,
0.1 mm for prismatic ones: a segment gets enough points that no joint moves more than that between
two checked states) and checks every state for joint limits, singular windows and a σ_min floor,
and the rows for continuity (largest joint step between consecutive rows).  It reports the first
violation — the row index where it happens (for a state inside a segment, the segment's first row)
— and the smallest σ_min along the path.

The dense states are generated and checked in chunks (:func:`dense_chunks`), so memory stays flat
in the path's length; the steps are bounded (:data:`STEP_ANGLE_RANGE`, :data:`STEP_LENGTH_RANGE`)
and the number of states is budgeted (:data:`MAX_CHECK_STATES`): a check that would need more is
refused up front, never left to run for hours.

Windows are also decided by proof (``prove=True``, the default): every segment is proven clear of
every window, or the first state inside one is found, by :func:`planning.certify.certify_path` — a
sampled check can miss a segment that grazes a window between two states, the proof cannot.  The
result says how the windows were decided (``windows_check``: ``"proven"``, ``"sampled"`` where the
proof could not settle a segment, or None without windows); the first window violation is the
earlier of the proof's and the samples'.  A σ_min floor is proven the same way (Weyl's inequality
and a Lipschitz bound of the Jacobian, :func:`planning.certify.certify_sigma`; ``sigma_check``).

With a collision world (``world``, :class:`planning.collision.CollisionWorld`: a robot in a work
cell) every dense state's clearance is computed (``min_clearance``, the smallest, in m, and its row)
and every segment is proven clear of the cell and of the robot itself, or its first colliding state
found (:func:`planning.certify.collision.certify_collision`; ``collision_check``, ``"proven"`` or
``"sampled"``; violation kind ``"collision"`` naming the link, the obstacle and how deep).  The
nearest obstacle and the nearest self pair over those states are kept apart (``nearest``, a
:class:`planning.collision.ClearanceTally`): a self pair near in every pose must not hide the cell.
"""
from __future__ import annotations

import math
from dataclasses import asdict, dataclass, field, fields

import numpy as np

from kin.display import joint_interval, joint_label, joint_value
from kin.errors import ConfigurationError
from planning.certify import PathProof, certify_path, certify_sigma
from planning.certify.collision import CollisionProof, certify_collision
from planning.collision.report import ClearanceTally
from planning.windows import WindowSet

DEFAULT_STEP_ANGLE = math.radians(0.1)   # rad
DEFAULT_STEP_LENGTH = 1e-4               # m
#: allowed check steps: revolute joints (rad) and prismatic joints (m)
STEP_ANGLE_RANGE = (1e-6, math.radians(5.0))
STEP_LENGTH_RANGE = (1e-7, 1e-2)
#: the most dense states one check evaluates (σ_min runs at about 10⁶ states/s)
MAX_CHECK_STATES = 20_000_000
KINDS = ("nonfinite", "continuity", "limits", "window", "sigma_min", "collision")


@dataclass(frozen=True)
class Violation:
    """The first problem of a path: row ``index`` (0-based), ``kind`` (one of :data:`KINDS`), text."""

    index: int
    kind: str
    detail: str


@dataclass(frozen=True)
class PathCheck:
    """Result of :func:`check_path` (SI units)."""

    valid: bool
    first_violation: Violation | None
    min_sigma: float
    min_sigma_index: int
    max_step: float
    checked_states: int
    windows_check: str | None = None     # "proven", "sampled" (not every segment proven) or None (no windows)
    sigma_check: str | None = None       # the same for the σ_min floor (None: no floor)
    proof: PathProof | None = field(default=None, repr=False, compare=False)   # the windows' proof (prove=True)
    min_clearance: float | None = None   # smallest clearance at a dense state (m; None: no collision world)
    min_clearance_index: int = -1        # its row (segment)
    collision_check: str | None = None   # "proven", "sampled" or None (no collision world)
    clearance_bound: float | None = None  # proven lower bound on the clearance along the path (m)
    collision_proof: CollisionProof | None = field(default=None, repr=False, compare=False)
    #: the nearest obstacle and the nearest self pair over the checked states, apart
    #: (:class:`planning.collision.ClearanceTally`; None: no collision world)
    nearest: ClearanceTally | None = field(default=None, repr=False, compare=False)

    def to_dict(self) -> dict:
        d = {f.name: getattr(self, f.name) for f in fields(self)
             if f.name not in ("proof", "collision_proof", "nearest")}
        d.update(self.nearest.to_dict() if self.nearest is not None else {})
        d["first_violation"] = None if self.first_violation is None else asdict(self.first_violation)
        return d


def densify(path: np.ndarray, revolute: np.ndarray, step_angle: float = DEFAULT_STEP_ANGLE,
            step_length: float = DEFAULT_STEP_LENGTH) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Interpolate a path (M, n) so that no joint moves more than its step between states.

    Returns the dense states (K, n), the segment (row) index of each state, and its fraction along
    that segment (0 at the row itself).  The last row is included with its own index.
    """
    P = np.asarray(path, dtype=float)
    if len(P) == 1:
        return P.copy(), np.zeros(1, int), np.zeros(1)
    steps = np.where(revolute, step_angle, step_length)
    d = np.abs(np.diff(P, axis=0)) / steps
    counts = np.maximum(np.ceil(d.max(axis=1)).astype(int), 1)      # sub-steps per segment
    seg = np.repeat(np.arange(len(counts)), counts)
    frac = np.concatenate([np.arange(c) / c for c in counts])
    Q = P[seg] + frac[:, None] * (P[seg + 1] - P[seg])
    return (np.vstack([Q, P[-1]]), np.append(seg, len(P) - 1), np.append(frac, 0.0))


def _counts(P: np.ndarray, revolute: np.ndarray, step_angle: float, step_length: float) -> np.ndarray:
    """Sub-steps per segment (M − 1,), int64: no joint moves more than its step between states.
    Raises :class:`ConfigurationError` when they exceed :data:`MAX_CHECK_STATES` in all."""
    steps = np.where(revolute, step_angle, step_length)
    with np.errstate(over="ignore", invalid="ignore"):          # huge values: inf, refused below
        d = np.abs(np.diff(P, axis=0)) / steps
    counts = np.maximum(np.ceil(d.max(axis=1, initial=0.0)), 1)
    total = float(counts.sum()) + 1
    if not math.isfinite(total):
        raise ConfigurationError("the joint values are too large to check (a step between rows overflows)")
    if total > MAX_CHECK_STATES:
        raise ConfigurationError(f"the dense check would evaluate {total:.3g} states; at most "
                                 f"{MAX_CHECK_STATES:.3g} (use a larger check step)")
    return counts.astype(np.int64)


def dense_chunks(path: np.ndarray, counts: np.ndarray, chunk: int):
    """The dense states of :func:`densify`, ``chunk`` at a time: yields (Q (k, n), segment (k,),
    fraction (k,)) in path order, the last row included, with memory independent of the path length."""
    P = np.asarray(path, dtype=float)
    starts = np.concatenate([[0], np.cumsum(counts)])        # global index of each row's state
    total = int(starts[-1]) + 1
    per_row = np.append(counts, 1)                            # the last row is one state of its own
    for a in range(0, total, chunk):
        k = np.arange(a, min(a + chunk, total), dtype=np.int64)
        seg = np.searchsorted(starts, k, side="right") - 1
        frac = (k - starts[seg]) / per_row[seg]
        nxt = np.minimum(seg + 1, len(P) - 1)
        yield P[seg] + frac[:, None] * (P[nxt] - P[seg]), seg, frac


def _label(i: int, f: float) -> str:
    return f"row {i}" if f == 0 else f"between rows {i} and {i + 1} (at {f:.3f} of the segment)"


def check_path(robot, path, windows: WindowSet | None = None, sigma_min: float | None = None,
               step_angle: float = DEFAULT_STEP_ANGLE, step_length: float = DEFAULT_STEP_LENGTH,
               max_step: float | None = None, limit_tol: float = 1e-9, chunk: int = 200_000,
               prove: bool = True, world=None, dense: bool = True) -> PathCheck:
    """Check a joint path (M, n), SI units, densely — and the windows by proof unless ``prove`` is
    False.  See the module docstring.

    ``max_step``: largest allowed joint change between consecutive rows (rad or m; None: not checked,
    only reported).  ``sigma_min``: a floor on σ_min of the task Jacobian along the whole path.
    ``world``: a :class:`planning.collision.CollisionWorld` to be clear of (by its margin).
    ``dense=False`` (with ``prove``): the proofs decide alone — windows, the σ_min floor and collisions
    proven segment by segment, limits at the rows (the limit box is convex) — and the dense states are
    not evaluated: ``min_sigma`` and ``min_clearance`` are then the values at the rows, and the
    collision proof's lower bound is not measured.  What the planner returns its paths with.
    """
    chain = robot.chain
    P = np.asarray(path, dtype=float)
    if P.ndim != 2 or P.shape[1] != chain.n or len(P) == 0:
        raise ConfigurationError(f"path has shape {P.shape}; expected (M, {chain.n}) with M ≥ 1 for {chain.name}")
    rev = chain.revolute_mask
    for used, step, (lo, hi), unit in ((rev.any(), step_angle, STEP_ANGLE_RANGE, "rad"),
                                       ((~rev).any(), step_length, STEP_LENGTH_RANGE, "m")):
        if used and not (lo <= step <= hi):
            raise ConfigurationError(f"check step {step:g} {unit} is outside the allowed range [{lo:g}, {hi:g}] {unit}")
    if sigma_min is not None and not (math.isfinite(sigma_min) and sigma_min >= 0):
        raise ConfigurationError(f"σ_min floor {sigma_min} must be a finite number ≥ 0")
    if windows is not None:
        windows.check_robot(robot)
    if world is not None and world.chain != chain:
        raise ConfigurationError(f"the collision world is for {world.chain.name}, not {chain.name}")
    first: Violation | None = None

    def note(v: Violation) -> None:
        nonlocal first
        if first is None or v.index < first.index:
            first = v

    bad = ~np.isfinite(P).all(axis=1)
    if bad.any():
        i = int(np.argmax(bad))
        return PathCheck(False, Violation(i, "nonfinite", f"row {i} holds NaN or infinite values"),
                         math.nan, -1, math.nan, 0)
    # a prismatic joint beyond the evaluators' range (far outside its limits) is refused, naming the row:
    # σ_min is evaluated at every state (the states between rows lie within the range of their rows)
    chain.as_batch(P, "path")
    with np.errstate(over="ignore", invalid="ignore"):
        steps = np.abs(np.diff(P, axis=0)) if len(P) > 1 else np.zeros((0, chain.n))
    max_step_seen = float(steps.max()) if steps.size else 0.0
    if max_step is not None and steps.size and max_step_seen > max_step:
        i, j = np.unravel_index(np.argmax(steps > max_step), steps.shape)
        moved, allowed = joint_value(chain, j, steps[i, j]), joint_value(chain, j, max_step)
        note(Violation(int(i), "continuity", f"{joint_label(chain, j)} moves {moved} between rows {i} and {i + 1}; "
                                             f"allowed {allowed}"))
    if not dense and prove:
        counts = np.ones(max(len(P) - 1, 0), np.int64)      # the rows only: no state between them
    else:
        counts = _counts(P, rev, step_angle, step_length) if len(P) > 1 else np.zeros(0, np.int64)
    total = int(counts.sum()) + 1
    lo, hi = chain.lower - limit_tol, chain.upper + limit_tol
    found: dict[str, Violation] = {}
    sig_min, sig_seg = math.inf, -1
    clear_min, clear_seg = math.inf, -1
    tally = None if world is None else ClearanceTally(world)
    for Q, seg, frac in dense_chunks(P, counts, chunk):
        if world is not None:
            c = tally.add(Q, seg)       # the world's clearance: its two kinds' models, the smaller of each state's
            kc = int(np.argmin(c))
            if c[kc] < clear_min:
                clear_min, clear_seg = float(c[kc]), int(seg[kc])
            if "collision" not in found and (c <= world.margin).any():
                k = int(np.argmax(c <= world.margin))
                ct = world.nearest(Q[k:k + 1])
                what = world.describe(int(ct.body[0]), int(ct.other[0]), float(ct.clearance[0]))
                found["collision"] = Violation(int(seg[k]), "collision",
                                               f"in collision: {what} {_label(int(seg[k]), float(frac[k]))}")
        if "limits" not in found:
            out = (Q < lo) | (Q > hi)
            if out.any():
                k = int(np.argmax(out.any(axis=1)))
                j = int(np.argmax(out[k]))
                found["limits"] = Violation(int(seg[k]), "limits",
                                            f"{joint_label(chain, j)} = {joint_value(chain, j, Q[k, j])} outside "
                                            f"{joint_interval(chain, j, chain.lower[j], chain.upper[j])} "
                                            f"{_label(int(seg[k]), float(frac[k]))}")
        if "window" not in found and windows is not None and windows.windows:
            which = windows.which(Q)
            inside = which >= 0
            if inside.any():
                k = int(np.argmax(inside))
                w = windows.windows[int(which[k])]
                found["window"] = Violation(int(seg[k]), "window", f"inside window '{w.name}' "
                                            f"{_label(int(seg[k]), float(frac[k]))}")
        sig = robot.sigma_min(Q)
        kmin = int(np.argmin(sig))
        if sig[kmin] < sig_min:
            sig_min, sig_seg = float(sig[kmin]), int(seg[kmin])
        if sigma_min is not None and "sigma_min" not in found:
            low = sig < sigma_min
            if low.any():
                k = int(np.argmax(low))
                found["sigma_min"] = Violation(int(seg[k]), "sigma_min", f"σ_min = {sig[k]:.3g} < {sigma_min:.3g} "
                                               f"(SI) {_label(int(seg[k]), float(frac[k]))}")
    windows_check = None
    proof = certify_path(windows, P) if prove else None      # (no windows: proven at once)
    if windows is not None and windows.windows:
        windows_check = "sampled"
        if proof is not None:
            v = proof.violation
            if v is not None and ("window" not in found or v.segment < found["window"].index):
                found["window"] = Violation(v.segment, "window", f"inside window '{v.window}' "
                                            f"{_label(v.segment, v.t)} (proven)")
            windows_check = "proven" if proof.proven or v is not None else "sampled"
    sigma_check = None
    if sigma_min is not None:
        sigma_check = "sampled"
        if prove:
            sp = certify_sigma(robot, P, sigma_min)
            if sp.violation is not None:
                k, f, _, s = sp.violation
                if "sigma_min" not in found or k < found["sigma_min"].index:
                    found["sigma_min"] = Violation(k, "sigma_min", f"σ_min = {s:.3g} < {sigma_min:.3g} (SI) "
                                                   f"{_label(k, f)} (proven)")
            sigma_check = "proven" if sp.proven or sp.violation is not None else "sampled"
    collision_check, cproof, bound = None, None, None
    if world is not None:
        collision_check = "sampled"
        if prove:
            cproof = certify_collision(world, P, bound=dense)
            v = cproof.violation
            if v is not None and ("collision" not in found or v.segment < found["collision"].index):
                found["collision"] = Violation(v.segment, "collision", f"in collision: {v.text} "
                                               f"{_label(v.segment, v.t)} (proven)")
            collision_check = "proven" if cproof.proven or v is not None else "sampled"
            bound = cproof.bound if cproof.proven and math.isfinite(cproof.bound) else None
    if not dense and prove and "sampled" in (windows_check, sigma_check, collision_check):
        # a proof left something open: the dense states decide after all
        return check_path(robot, P, windows, sigma_min, step_angle, step_length, max_step, limit_tol, chunk, prove,
                          world, dense=True)
    for kind in ("limits", "window", "sigma_min", "collision"):
        if kind in found:
            note(found[kind])
    return PathCheck(first is None, first, sig_min, sig_seg, max_step_seen, total, windows_check, sigma_check, proof,
                     None if world is None else clear_min, clear_seg, collision_check, bound, cproof, tally)

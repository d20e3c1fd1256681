"""Building windows: a window per factor from a margin (:func:`window_for_factor`), dexterity
margins from a σ_min or manipulability threshold (:func:`dexterity_margins`), and
:func:`build_windows`, which puts them together.  See :mod:`planning.windows` for what a window is."""
from __future__ import annotations

import copy
import math
from functools import lru_cache
from typing import Sequence

import numpy as np

from kin.singular import SingularComponent, SingularFactor, SingularityAnalysis, analyse_singularities
from kin.singular.exact import content_key
from kin.validation import real
from planning.certify.gradient import gradient_bound, zero_free
from planning.certify.intervals import IntervalError
from planning.errors import WindowError
from planning.windows.model import Window, WindowSet, robot_key
from planning.windows.sampled import PointSetWindow

#: dexterity margins are widened by this factor beyond the last sample they had to include
SAFETY = 1.02
#: the margins are built so that the measure stays ≥ threshold × this on the samples: a little
#: slack for the configurations that no finite sample set visits
BUILD_MARGIN = 1.2
#: a dexterity threshold whose windows would cover more of the joint space than this is refused
MAX_COVERAGE = 0.5
#: windows are built from the singular analysis with this seed and sample count, whatever seed a
#: command was given: the zero-set samples of a numeric component (its point-set window) and the
#: dexterity margins' starting points come from them, and a window must not depend on a seed
WINDOW_SEED = 0
WINDOW_SAMPLES = 200
#: the rule a |g| ≤ ε window is built by (recorded in its detail)
EPSILON_RULE = ("epsilon = width × G, G a bound of ‖∇g‖ over the joint limits proven by interval arithmetic: "
                "every configuration within the width of the zero set (joint distance, SI) is inside")



# ---- building windows ----------------------------------------------------------------------------
def _merge(intervals: list[tuple[float, float]]) -> list[tuple[float, float]]:
    out: list[list[float]] = []
    for lo, hi in sorted(intervals):
        if out and lo <= out[-1][1]:
            out[-1][1] = max(out[-1][1], hi)
        else:
            out.append([lo, hi])
    return [(a, b) for a, b in out]


def _sampled(factor) -> bool:
    """A multi-joint component of a numeric analysis: known by samples, not by a formula."""
    return isinstance(factor, SingularComponent) and factor.single_joint is None


def window_for_factor(factor: SingularFactor | SingularComponent, width: float, method: str, lower: np.ndarray,
                      upper: np.ndarray, detail: dict | None = None, robot=None) -> Window | PointSetWindow:
    """The window of half-width ``width`` (SI) around ``factor``'s zero set (a point-set window
    for a multi-joint component of a numeric analysis; with ``robot`` its miss rate on fresh points
    of the set is measured, :func:`point_set_misses`)."""
    if not (width >= 0 and math.isfinite(width)):
        raise WindowError(f"window width {width} must be a finite number ≥ 0 (rad or m)")
    n = factor.n
    name = f"{factor.kind}: {factor.expr}"
    detail = dict(detail or {})
    j = factor.single_joint
    if j is not None:
        roots = factor.solutions.get("values", [])
        ivs = _merge([(max(r - width, lower[j]), min(r + width, upper[j])) for r in roots])
        detail["proof"] = "exact"          # the roots of a one-joint factor
        return Window(name, factor.kind, factor.expr, factor.joints, float(width), method, n, intervals=ivs,
                      detail=detail)
    if _sampled(factor):
        cols = [jj - 1 for jj in factor.joints]
        if robot is not None:
            detail["miss"] = point_set_misses(robot, factor, width)
        detail.update({"resolution": factor.resolution, "points": int(len(factor.points)),
                       "proof": "sampled",
                       "note": "the component has no formula: the window holds every configuration within the "
                               "width of its sampled points (distance over the component's joints), so the set "
                               "only as far as its samples reach; miss counts fresh points of the set outside"})
        return PointSetWindow(name, factor.kind, factor.expr, factor.joints, float(width), method, n,
                              points=factor.points[:, cols], detail=detail, normals=factor.local_normals,
                              radius=None if factor.local_normals is None else factor.radius)
    bound = factor_gradient_bound(factor.expr, n, tuple(map(float, lower)), tuple(map(float, upper)))
    if bound is None:
        raise WindowError(f"the {factor.kind} factor {factor.expr} holds an operation that interval arithmetic does "
                          "not support: its window cannot be bounded")
    G, attained, converged, empty = bound
    if empty:   # zero set proven outside the limits: an empty window
        return Window(name, factor.kind, factor.expr, factor.joints, float(width), method, n, epsilon=-1.0,
                      detail={**detail, "proof": "interval bound",
                              "note": "zero set outside the joint limits (proven: g has no zero there)"})
    detail.update({"proof": "interval bound", "rule": EPSILON_RULE, "grad_norm_bound": G,
                   "grad_norm_attained": attained, "bound_converged": converged})
    return Window(name, factor.kind, factor.expr, factor.joints, float(width), method, n, epsilon=float(width * G),
                  detail=detail)


@lru_cache(maxsize=64)
def factor_gradient_bound(expr: str, n: int, lower: tuple[float, ...],
                          upper: tuple[float, ...]) -> tuple[float, float, bool, bool] | None:
    """(G, attained, converged, empty) for the factor ``expr`` over the joint box: G a proven bound of
    ‖∇g‖ (:func:`planning.certify.gradient.gradient_bound`), ``attained`` a value of ‖∇g‖ reached in
    the box, ``empty`` whether g is proven nonzero on the whole box.  None when interval arithmetic
    does not support the expression."""
    from kin.singular.expression import parse_tree
    g = parse_tree(expr, n, "singular factor")
    try:
        if zero_free(g, n, lower, upper):
            return 0.0, 0.0, True, True
        b = gradient_bound(g, n, lower, upper)
    except IntervalError:
        return None
    return b.bound, b.attained, b.converged, False


#: fresh starts projected onto the singular set to measure a point-set window's miss rate
MISS_STARTS = 256


def point_set_misses(robot, component: SingularComponent, width: float) -> dict:
    """How well a point-set window of half-width ``width`` holds its component: configurations drawn
    afresh (a fixed seed, none of the analysis's) are projected onto the singular set (Gauss–Newton,
    :func:`kin.singular.projection.project`, a fixed iteration count: no clock enters it); those
    that land on this component (the same joints) should all lie within ``width`` of its sampled
    points.  Returns the count that landed, how many did not lie within the width (the misses), their
    share and the largest distance found."""
    from kin.singular.projection import project, residuals, support
    lo, hi = robot.chain.lower, robot.chain.upper
    Q0 = np.random.default_rng(WINDOW_SEED + 104729).uniform(lo, hi, size=(MISS_STARTS, robot.n))
    Qp, ok = project(robot, Q0, tol=component.tolerance)
    Qp = Qp[ok]
    landed = np.zeros(0, bool)
    if len(Qp):
        _, _, G, _, _ = residuals(robot, Qp)
        supp, _ = support(G)
        landed = np.all(supp == np.isin(np.arange(robot.n), [j - 1 for j in component.joints])[None], axis=1)
    d = component.distance(Qp[landed]) if landed.any() else np.zeros(0)
    misses = int(np.count_nonzero(d > width))
    return {"fresh_set_points": int(len(d)), "outside_window": misses,
            "miss_rate": misses / len(d) if len(d) else None, "largest_distance": float(d.max()) if len(d) else None}


def _normal_directions(factor: SingularFactor, S: np.ndarray) -> np.ndarray:
    j = factor.single_joint
    if j is not None:
        D = np.zeros_like(S)
        D[:, j] = 1.0
        return D
    if _sampled(factor):
        return factor.normal_at(S)
    G = factor.gradient(S)
    return G / np.maximum(np.linalg.norm(G, axis=1, keepdims=True), 1e-300)


def _window_distance(factor: SingularFactor, Q: np.ndarray, grad_max: float) -> np.ndarray:
    """Joint-space distance of configurations from the factor's zero set, in the window's metric:
    distance to the nearest root for a one-joint factor, |g| / max‖∇g‖ otherwise."""
    j = factor.single_joint
    if j is not None:
        roots = np.array(factor.solutions.get("values", []))
        if len(roots) == 0:
            return np.full(len(Q), np.inf)
        return np.abs(Q[:, j][:, None] - roots[None, :]).min(axis=1)
    if _sampled(factor):
        return factor.distance(Q)
    if grad_max <= 0:
        return np.full(len(Q), np.inf)
    return np.abs(factor(Q)) / grad_max


def _corner_samples(factors, limits, rng, widths=None, count: int = 300) -> list[np.ndarray]:
    """Configurations near where two factors meet (one of them a one-joint factor): the other
    factor's zero-set samples with the one joint set near one of its roots, both moved off their
    zero sets by random steps — the corners that uniform sampling rarely reaches."""
    out = []
    for a, fa in enumerate(factors):
        j = fa.single_joint
        roots = fa.solutions.get("values", []) if j is not None else []
        if not roots:
            continue
        for b, fb in enumerate(factors):
            if b == a or len(fb.samples) == 0:
                continue
            S = fb.samples[rng.integers(len(fb.samples), size=count)].copy()
            scale_a = limits[a] if widths is None or widths[a] == 0 else 3 * widths[a]
            S[:, j] = np.asarray(roots)[rng.integers(len(roots), size=count)] + rng.uniform(-1, 1, count) * scale_a
            D = _normal_directions(fb, fb.samples[:1].repeat(count, 0)) if fb.single_joint is not None else None
            scale_b = limits[b] if widths is None or widths[b] == 0 else 3 * widths[b]
            step = rng.uniform(-1, 1, count)[:, None] * scale_b
            S += step * (D if D is not None else _normal_directions(fb, S))
            out.append(S)
    # corners of all one-joint factors at once (wrist and elbow together, next to the shoulder)
    singles = [(a, f) for a, f in enumerate(factors) if f.single_joint is not None and f.solutions.get("values")]
    if len(singles) >= 2:
        bases = [f.samples for f in factors if f.single_joint is None and len(f.samples)]
        for base in bases or [None]:
            S = (base[rng.integers(len(base), size=count * 4)] if base is not None
                 else np.repeat(factors[singles[0][0]].samples[:1], count * 4, axis=0)).copy()
            for a, f in singles:
                roots = np.asarray(f.solutions["values"])
                scale = limits[a] if widths is None or widths[a] == 0 else 3 * widths[a]
                S[:, f.single_joint] = roots[rng.integers(len(roots), size=len(S))] + rng.uniform(-1, 1, len(S)) * scale
            out.append(S)
    return out


def dexterity_margins(robot, analysis: SingularityAnalysis, threshold: float, measure: str = "sigma_min",
                      random_samples: int = 40000, steps: int = 24, seed: int = 0,
                      max_rounds: int = 50) -> tuple[list[float], dict]:
    """Smallest margins (one per factor) such that the measure is ≥ ``threshold`` at every sampled
    configuration outside all windows.

    The samples are uniform in the joint limits plus, for every factor, points of its zero set
    moved along the factor's normal by geometric steps.  A sample below the threshold and outside
    every window is charged to the factor it is nearest to (in that window's metric), whose margin
    grows to include it; this repeats until no sample is left.  Raises :class:`WindowError` when a
    margin would exceed half the range of the factor's joints (the threshold is too high for this
    machine: its σ_min stays below it far from any singularity).  A component of a numeric
    analysis first absorbs the low samples' projections onto the singular set as new points
    (:meth:`~kin.singular.numeric.SingularComponent.absorb`; ``analysis`` is updated in place), so
    that a gap between its sampled points does not count as distance from the set.
    """
    if measure not in ("sigma_min", "manipulability"):
        raise WindowError(f"dexterity measure {measure!r} unknown; allowed: sigma_min, manipulability")
    if not (threshold > 0 and math.isfinite(threshold)):
        raise WindowError(f"dexterity threshold {threshold} must be a positive number")
    chain = robot.chain
    lo, hi = chain.lower, chain.upper
    rng = np.random.default_rng(seed)
    parts = [rng.uniform(lo, hi, size=(random_samples, robot.n))]
    factors = analysis.factors
    grad_max = []
    limits = []
    for f in factors:
        S = f.samples
        limits.append(0.5 * float(min(hi[j - 1] - lo[j - 1] for j in f.joints)))
        if len(S) == 0:
            grad_max.append(0.0)
            continue
        S = S[rng.choice(len(S), min(len(S), 100), replace=False)]
        if f.single_joint is None and not _sampled(f):     # the window's own metric: |g| / G
            bound = factor_gradient_bound(f.expr, robot.n, tuple(map(float, lo)), tuple(map(float, hi)))
            grad_max.append(0.0 if bound is None or bound[3] else bound[0])
        else:
            grad_max.append(1.0)
        D = _normal_directions(f, S)
        ts = np.geomspace(1e-5, limits[-1], steps)
        for sign in (1.0, -1.0):
            parts.append((S[:, None, :] + sign * ts[None, :, None] * D[:, None, :]).reshape(-1, robot.n))
    parts += _corner_samples(factors, limits, rng)
    col = 1 if measure == "sigma_min" else 0
    widths = np.zeros(len(factors))
    too_high = (f"{measure} ≥ {threshold:g} cannot be kept by windows around the singular factors of "
                f"{chain.name}: it stays below that threshold far from its singularities; choose a smaller threshold")

    def charge(Qs: np.ndarray) -> int:
        """Grow the margins until every low sample of Qs is inside a window; return how many were low."""
        Qs = Qs[np.all((Qs >= lo) & (Qs <= hi), axis=1)]
        res, _ = robot.evaluate(Qs, 4 | 8)
        Ql = Qs[res["measures"][:, col] < threshold * BUILD_MARGIN]
        if len(Ql) and not factors:
            raise WindowError(too_high)
        for f in factors:
            # a sampled component has gaps between its points: low configurations far from them
            # are projected onto the set first, so that the margin covers the set, not the gaps
            if _sampled(f):
                f.absorb(robot, Ql)
        dist = np.stack([_window_distance(f, Ql, g) for f, g in zip(factors, grad_max)], axis=1) \
            if factors else np.zeros((0, 0))
        for _ in range(max_rounds):
            outside = np.all(dist > widths[None, :], axis=1)
            if not outside.any():
                break
            near = np.argmin(dist[outside], axis=1)
            for i in np.unique(near):
                widths[i] = max(widths[i], float(dist[outside][near == i, i].max()) * SAFETY)
            over = [i for i in range(len(factors)) if widths[i] > limits[i]]
            if over:
                raise WindowError(too_high + f" (the {factors[over[0]].kind} window would exceed "
                                  f"{limits[over[0]]:.3g})")
        return len(Ql)

    low = charge(np.concatenate(parts))
    # check on fresh samples, as a user would, and charge what slipped through, until three rounds
    # in a row find nothing new
    clean = 0
    for k in range(12):
        fresh_rng = np.random.default_rng(seed + 1 + k)
        fresh = [fresh_rng.uniform(lo, hi, size=(random_samples, robot.n)), *_corner_samples(factors, limits,
                                                                                              fresh_rng, widths)]
        before = widths.copy()
        charge(np.concatenate(fresh))
        clean = clean + 1 if np.array_equal(before, widths) else 0
        if clean == 3:
            break
    if factors:
        probe = np.random.default_rng(seed + 99).uniform(lo, hi, size=(20000, robot.n))
        covered = np.any(np.stack([_window_distance(f, probe, g) for f, g in zip(factors, grad_max)], 1)
                         <= widths[None, :], axis=1).mean()
        if covered > MAX_COVERAGE:
            raise WindowError(too_high + f" (the windows would cover {100 * covered:.0f} % of the joint space)")
    return [float(w) for w in widths], {"threshold": threshold, "measure": measure,
                                         "samples": int(sum(len(p) for p in parts)), "below_threshold": int(low)}


def _canonical(robot, analysis: SingularityAnalysis | None, needs_samples: bool) -> SingularityAnalysis:
    """The analysis windows are built from: ``analysis`` when it is ``robot``'s and, where its samples
    matter (a numeric analysis, dexterity margins), drawn with :data:`WINDOW_SEED` and
    :data:`WINDOW_SAMPLES`; otherwise a fresh one with those (the exact part is cached on disk)."""
    if analysis is None:
        return analyse_singularities(robot, samples=WINDOW_SAMPLES, seed=WINDOW_SEED)
    if not isinstance(analysis, SingularityAnalysis):
        raise WindowError(f"analysis must be a SingularityAnalysis (kin.singular.analyse_singularities), "
                          f"got {type(analysis).__name__}")
    bad = [f for f in analysis.factors if getattr(f, "n", None) != robot.n
           or not all(isinstance(j, (int, np.integer)) and 1 <= j <= robot.n for j in f.joints)]
    if analysis.robot != robot.name or bad:
        joints = f" ({bad[0].n} joints)" if bad else ""
        raise WindowError(f"analysis is of {analysis.robot!r}{joints}, not of {robot.name!r} ({robot.n} joints): "
                          "pass the analysis of the same robot, or none")
    if analysis.content and analysis.content != content_key(robot):
        raise WindowError(f"analysis is of another robot named {robot.name!r} (other DH values, limits or task "
                          "rows): pass the analysis of this robot, or none")
    if needs_samples and (analysis.seed, analysis.samples) != (WINDOW_SEED, WINDOW_SAMPLES):
        return analyse_singularities(robot, samples=WINDOW_SAMPLES, seed=WINDOW_SEED)
    return analysis


def build_windows(robot, margin: float | Sequence[float] | None = None, sigma_min: float | None = None,
                  manipulability: float | None = None, analysis: SingularityAnalysis | None = None) -> WindowSet:
    """Windows for every singular factor of ``robot``; exactly one width source must be given.

    ``margin``: one SI width for all factors, or one per factor (in ``analysis.factors`` order);
    ``sigma_min`` / ``manipulability``: a dexterity threshold (see :func:`dexterity_margins`).
    The result depends on the robot, the factors and the widths only: no seed enters it (see
    :data:`WINDOW_SEED`); ``analysis`` saves recomputing the singular set.
    """
    if not (hasattr(robot, "chain") and hasattr(robot, "evaluate")):
        raise WindowError(f"robot must be a kin.Robot (kin.load_robot(...)), got {type(robot).__name__}")
    given = [x is not None for x in (margin, sigma_min, manipulability)]
    if sum(given) != 1:
        raise WindowError("give exactly one window width source: margin, sigma_min or manipulability")
    dexterity = margin is None
    analysis = _canonical(robot, analysis, dexterity or getattr(analysis, "method", "exact") != "exact")
    lo, hi = robot.chain.lower, robot.chain.upper
    factors = analysis.factors
    if margin is not None:
        widths = list(margin) if isinstance(margin, (list, tuple, np.ndarray)) else [margin] * len(factors)
        if len(widths) != len(factors):
            raise WindowError(f"{len(widths)} margins given for {len(factors)} singular factors")
        widths = [real(w, "margin (rad for revolute, m for prismatic joints)", 0.0, error=WindowError)
                  for w in widths]
        method, detail = "margin", {}
    else:
        method = "sigma_min" if sigma_min is not None else "manipulability"
        threshold = real(sigma_min if sigma_min is not None else manipulability, f"{method} (SI)", 0.0,
                         low_open=True, error=WindowError)
        if analysis.method != "exact":     # the margins absorb points into the components: work on a copy
            analysis = copy.deepcopy(analysis)
            factors = analysis.factors
        widths, detail = dexterity_margins(robot, analysis, threshold, method)
    out = [window_for_factor(f, float(w), method, lo, hi, detail, robot=robot) for f, w in zip(factors, widths)]
    ws = WindowSet(robot=robot.name, n=robot.n, windows=out, robot_key=robot_key(robot))
    if dexterity:
        miss = floor_misses(robot, ws, threshold, method)
        for w in ws.windows:
            w.detail["floor"] = miss
    return ws


#: fresh configurations on which a dexterity floor is checked after the windows are built
FLOOR_CHECK_SAMPLES = 50_000


def floor_misses(robot, windows: WindowSet, threshold: float, measure: str) -> dict:
    """How a dexterity floor holds outside ``windows``: it is found by sampling, not proven, so it is
    checked on :data:`FLOOR_CHECK_SAMPLES` fresh uniform configurations (a fixed seed, none of the
    build's): how many lie outside every window with the measure below ``threshold``."""
    Q = np.random.default_rng(WINDOW_SEED + 7919).uniform(robot.chain.lower, robot.chain.upper,
                                                          size=(FLOOR_CHECK_SAMPLES, robot.n))
    outside = ~windows.contains(Q)
    res, _ = robot.evaluate(Q[outside], 4 | 8)
    low = int(np.count_nonzero(res["measures"][:, 1 if measure == "sigma_min" else 0] < threshold))
    n_out = int(outside.sum())
    return {"proof": "sampled", "measure": measure, "threshold": threshold, "fresh_samples": FLOOR_CHECK_SAMPLES,
            "outside_windows": n_out, "below_threshold_outside": low,
            "miss_rate": low / n_out if n_out else 0.0}

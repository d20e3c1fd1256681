"""Surrogate refinement of a finished sweep (scikit-learn).

Two Gaussian processes (``GaussianProcessRegressor``, Matérn ν = 5/2 with one length scale per
input, a white-noise term, inputs scaled to the unit cube, outputs normalised) are fitted to the
done rows: one to the task's objective (in the minimised sense), one to the coverage.  A candidate
is scored by its expected improvement over the best feasible design times the probability that its
coverage meets ``min_coverage`` (the coverage GP's normal tail above the threshold halfway between
the coverage levels k/N either side of the constraint), among the candidates more likely feasible
than not.  Candidates are a scrambled Sobol set over the swept ranges plus Gaussian perturbations of
the best feasible designs; a batch of one design per worker is chosen by the "kriging believer"
(each pick is added to the data at its predicted mean before the next).  The picks are stored as
ordinary rows with ``origin = "refine"`` and evaluated like the sample.

Refinement works on the range parameters of the best row's architecture, with that row's
list-parameter values fixed.
"""
from __future__ import annotations

import math
import time
import warnings

import numpy as np
from scipy.stats import norm, qmc

from design.sweep.dispatch import evaluate_pending
from design.sweep.file import Sweep, SweepError
from design.sweep.space import Design

__all__ = ["expected_improvement", "fit_gp", "propose", "refine_sweep", "coverage_threshold"]

_MAXIMISE = ("coverage", "gci")


def expected_improvement(mu: np.ndarray, sigma: np.ndarray, best: float) -> np.ndarray:
    """EI of minimisation below ``best`` for a normal prediction (mu, sigma): (best−μ)Φ(z) + σφ(z)."""
    s = np.maximum(sigma, 1e-12)
    z = (best - mu) / s
    return (best - mu) * norm.cdf(z) + s * norm.pdf(z)


def fit_gp(X: np.ndarray, y: np.ndarray, seed: int = 0):
    """A Matérn-5/2 Gaussian process (plus white noise) on inputs X (M, d) in the unit cube."""
    from sklearn.gaussian_process import GaussianProcessRegressor
    from sklearn.gaussian_process.kernels import ConstantKernel, Matern, WhiteKernel
    d = X.shape[1]
    kernel = (ConstantKernel(1.0, (1e-3, 1e3)) * Matern(length_scale=np.full(d, 0.3), length_scale_bounds=(1e-2, 1e2),
                                                        nu=2.5) + WhiteKernel(1e-6, (1e-10, 1e-3)))
    gp = GaussianProcessRegressor(kernel=kernel, normalize_y=True, n_restarts_optimizer=2, random_state=seed)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")       # convergence notes of the hyper-parameter search
        gp.fit(X, y)
    return gp


def _believer(gp, X: np.ndarray, y: np.ndarray, x: np.ndarray):
    """The GP with the same kernel refitted to the data plus x at its predicted mean."""
    from sklearn.base import clone
    g = clone(gp).set_params(kernel=gp.kernel_, optimizer=None)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        g.fit(np.vstack([X, x]), np.append(y, gp.predict(x[None])[0]))
    return g


def coverage_threshold(min_coverage: float, n_targets: int) -> float:
    """The coverage the constraint GP is compared with: coverage takes the values k/N, so halfway
    between the largest infeasible and the smallest feasible value."""
    need = math.ceil(min_coverage * n_targets - 1e-9)
    return (need - 0.5) / n_targets


def propose(X: np.ndarray, y: np.ndarray, c: np.ndarray, feas: np.ndarray, threshold: float, k: int,
            seed: int = 0, taken: np.ndarray | None = None, min_feasible: float = 0.5) -> np.ndarray:
    """``k`` new points (k, d) of the unit cube by constrained expected improvement, given done
    designs X (M, d) (unit cube), objectives y (M,) (minimised), coverages c (M,), feasibility
    flags (M,) and the coverage ``threshold`` of the constraint."""
    d = X.shape[1]
    gy, gc = fit_gp(X, y, seed), fit_gp(X, c, seed)
    thr = threshold
    feas = np.asarray(feas, bool)
    rng = np.random.default_rng(seed)
    cand = qmc.Sobol(d, scramble=True, seed=seed).random(2048)
    if feas.any():
        top = X[feas][np.argsort(y[feas])[:5]]
        cand = np.vstack([cand, np.clip(top[rng.integers(0, len(top), 1024)] + rng.normal(0, 0.04, (1024, d)), 0, 1)])
    taken = np.empty((0, d)) if taken is None else taken
    out = []
    Xa, ya = X, y
    for _ in range(k):
        mu, sd = gy.predict(cand, return_std=True)
        mc, sc = gc.predict(cand, return_std=True)
        pf = norm.cdf((mc - thr) / np.maximum(sc, 1e-9))
        if feas.any():        # EI × P(feasible), among the candidates more likely feasible than not
            acq = expected_improvement(mu, sd, float(y[feas].min())) * pf
            if np.any(pf >= min_feasible):
                acq = np.where(pf >= min_feasible, acq, -1.0)
        else:
            acq = pf
        near = np.vstack([taken, Xa])
        dist = np.min(np.linalg.norm(cand[:, None] - near[None], axis=2), axis=1)
        acq = np.where(dist < 1e-6, -np.inf, acq)                       # no design twice
        i = int(np.argmax(acq))
        out.append(cand[i])
        gy = _believer(gy, Xa, ya, cand[i])
        Xa, ya = np.vstack([Xa, cand[i]]), np.append(ya, mu[i])
    return np.array(out)


def _best(rows: list[dict], sign: float) -> float | None:
    vals = [sign * r["metrics"]["objective"] for r in rows if r["metrics"] and r["metrics"].get("feasible")]
    return min(vals) if vals else None


def refine_sweep(store, sweep: Sweep, executor, k: int, progress=None, seed: int = 0,
                 deadline: float = math.inf) -> dict:
    """Propose and evaluate ``k`` designs (batches of one per worker) on an open executor; returns
    {proposed, evaluated, failed, best_before (the sample's best feasible objective), best_after,
    improvement (≥ 0, in the objective's units), architecture}."""
    from design.sweep.export import best_row
    ranged = [ps for ps in sweep.parameters if not ps.is_list]
    if not ranged:
        raise SweepError("refinement needs at least one parameter with a range", sweep.source, "parameters")
    sign = -1.0 if sweep.task.objective in _MAXIMISE else 1.0
    lo = np.array([ps.low for ps in ranged])
    span = np.array([ps.high - ps.low for ps in ranged])
    names = [ps.name for ps in ranged]
    rows = [r for r in store.rows() if r["status"] == "done"]
    best = best_row(rows, sweep.task.objective)
    if best is None:
        raise SweepError("refinement needs at least one done design", sweep.source)
    arch, fixed = best["architecture"], {k2: v for k2, v in best["params"].items() if k2 not in names}
    before = _best([r for r in rows if r["origin"] == "sample"], sign)
    proposed = evaluated = failed = 0
    rnd = 0
    while proposed < k:
        if time.monotonic() > deadline:
            break
        rows = [r for r in store.rows() if r["status"] == "done" and r["architecture"] == arch
                and all(abs(r["params"][n] - v) <= 1e-12 * max(1.0, abs(v)) for n, v in fixed.items())]
        if len(rows) < 2:
            raise SweepError("refinement needs at least two done designs of the best architecture", sweep.source)
        X = np.array([[(r["params"][n] - lo[j]) / span[j] for j, n in enumerate(names)] for r in rows])
        y = np.array([sign * r["metrics"]["objective"] for r in rows])
        c = np.array([r["metrics"].get("coverage", float(r["metrics"]["feasible"])) for r in rows])
        f = np.array([bool(r["metrics"]["feasible"]) for r in rows])
        b = min(k - proposed, max(1, getattr(executor, "workers", 1)))
        U = propose(X, y, c, f, coverage_threshold(sweep.task.min_coverage, len(sweep.task.targets)), b,
                    seed + rnd)
        designs = []
        for u in U:
            vals = dict(fixed)
            vals.update(zip(names, lo + u * span))
            designs.append(Design.make(arch, {n: vals[n] for n in sweep.task.robot.chain.parameters}, "refine"))
        store.add(designs, sweep.eval_seed)
        new = [d for d in store.designs(["pending"]) if d.origin == "refine"]
        proposed += len(designs)
        rnd += 1
        e, f, _ = evaluate_pending(store, executor, new, progress, deadline=deadline)
        evaluated, failed = evaluated + e, failed + f
    after = _best([r for r in store.rows() if r["status"] == "done"], sign)
    imp = None if after is None else (after - before if before is None else before - after)
    return {"proposed": proposed, "evaluated": evaluated, "failed": failed, "architecture": arch,
            "best_before": None if before is None else sign * before,
            "best_after": None if after is None else sign * after,
            "improvement": None if before is None or after is None else max(0.0, imp)}

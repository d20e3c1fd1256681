"""Sweep figures: coverage against structural length with the Pareto front marked, the objective over
the parameter plane of a 2-parameter sweep, and (a sweep storing the cycle metrics) the cycle time
against the peak torque ratio with their Pareto front."""
from __future__ import annotations

import numpy as np
from matplotlib.figure import Figure

from design.sweep.export import pareto_front, pareto_rows
from studies.plots.figure import save_figure

__all__ = ["plot_pareto", "plot_heatmap", "plot_cycle_pareto"]


def _done(rows: list[dict]) -> list[dict]:
    return [r for r in rows if r["status"] == "done" and r["metrics"] and r["metrics"].get("coverage") is not None
            and r["metrics"].get("structural_length") is not None]


def plot_pareto(meta: dict, rows: list[dict], path, marks=()):
    """Coverage (%) against structural length (m) of every done design; the Pareto front (shorter and
    more coverage) joined by a line, refined designs marked.  ``marks``: further designs to show,
    (label, structural length m, coverage 0..1) each (e.g. an optimiser's answer).  A co-design sweep
    (``placement = true``: its rows have a mean reach score) colours each design by its mean score and
    rings the designs no other beats on coverage, score and length at once."""
    done = _done(rows)
    fig = Figure(figsize=(6.4, 4.6))
    ax = fig.add_subplot(111)
    if done:
        L = np.array([r["metrics"]["structural_length"] for r in done])
        C = 100 * np.array([r["metrics"]["coverage"] for r in done])
        refined = np.array([r["origin"] != "sample" for r in done])
        scores = [r["metrics"].get("mean_score") for r in done]
        if all(isinstance(v, (int, float)) for v in scores):
            sc = ax.scatter(L, C, s=22, c=scores, cmap="viridis", vmin=0, vmax=max(max(scores), 1e-9),
                            label="design (colour: mean reach score)")
            fig.colorbar(sc, ax=ax, label="mean reach score at its best placement")
            f3 = pareto_rows([r["metrics"] for r in done])
            ax.scatter(L[f3], C[f3], s=90, facecolors="none", edgecolors="k", lw=1.2,
                       label="Pareto: coverage, score, length")
        else:
            ax.scatter(L[~refined], C[~refined], s=10, c="tab:blue", alpha=0.6, label="sample")
        if refined.any():
            ax.scatter(L[refined], C[refined], s=28, c="tab:orange", marker="D", label="refined")
        front = pareto_front(L, C)
        o = np.argsort(L[front])
        ax.step(L[front][o], C[front][o], where="post", c="tab:red", lw=1.5, label="Pareto front")
        ax.scatter(L[front], C[front], s=30, facecolors="none", edgecolors="tab:red")
    for (label, length, cov), marker, colour in zip(marks, "*^sPD", ("gold", "tab:green", "tab:purple", "tab:brown",
                                                                    "tab:pink")):
        ax.scatter([length], [100 * cov], marker=marker, s=140, c=colour, edgecolors="k", zorder=5, label=label)
    ax.set_xlabel("structural length Σ(|a|+|d|) (m)")
    ax.set_ylabel("coverage (%)")
    ax.ticklabel_format(useOffset=False)
    ax.set_title(f"{meta['name']}: {len(done)} designs")
    ax.legend(loc="lower right", fontsize=8)
    return save_figure(fig, path)


def plot_heatmap(meta: dict, rows: list[dict], path):
    """The objective over the two swept parameters (file units); infeasible designs hatched grey."""
    p, q = meta["swept"]
    sp, sq = meta["scales"][p], meta["scales"][q]
    done = [r for r in rows if r["status"] == "done" and r["metrics"]]
    fig = Figure(figsize=(6.4, 5.0))
    ax = fig.add_subplot(111)
    if done:
        X = np.array([r["params"][p] / sp for r in done])
        Y = np.array([r["params"][q] / sq for r in done])
        Z = np.array([r["metrics"]["objective"] for r in done], float)
        F = np.array([bool(r["metrics"]["feasible"]) for r in done])
        ux, uy = np.unique(X), np.unique(Y)
        if len(ux) * len(uy) == len(done) and len(ux) > 1 and len(uy) > 1:     # a full grid
            G = np.full((len(uy), len(ux)), np.nan)
            G[np.searchsorted(uy, Y), np.searchsorted(ux, X)] = np.where(F, Z, np.nan)
            m = ax.pcolormesh(ux, uy, G, shading="nearest", cmap="viridis")
            ax.scatter(X[~F], Y[~F], s=12, c="0.6", marker="x", label="infeasible")
        else:
            m = ax.scatter(X[F], Y[F], c=Z[F], s=30, cmap="viridis")
            ax.scatter(X[~F], Y[~F], s=12, c="0.6", marker="x", label="infeasible")
        fig.colorbar(m, ax=ax, label=f"objective: {meta['objective']}")
        if (~F).any():
            ax.legend(loc="upper right", fontsize=8)
    ax.set_xlabel(f"{p} ({meta['units'][p]})")
    ax.set_ylabel(f"{q} ({meta['units'][q]})")
    ax.ticklabel_format(useOffset=False)
    ax.set_title(f"{meta['name']}: {meta['objective']} over {p}, {q}")
    return save_figure(fig, path)


def plot_cycle_pareto(meta: dict, rows: list[dict], path, marks=()):
    """Cycle time (s) against the largest peak torque over its limit of every done design that
    reaches its cycle; the Pareto front (faster and less torque) joined by a line, the torque limit
    (ratio 1) dashed, infeasible designs (coverage or torque) as crosses.  ``marks``: (label, torque
    ratio, cycle time s) each."""
    done = [r for r in rows if r["status"] == "done" and r["metrics"]
            and all(isinstance(r["metrics"].get(k), (int, float)) and np.isfinite(r["metrics"][k])
                    for k in ("cycle_time", "torque_ratio"))]
    fig = Figure(figsize=(6.4, 4.6))
    ax = fig.add_subplot(111)
    if done:
        R = np.array([r["metrics"]["torque_ratio"] for r in done])
        T = np.array([r["metrics"]["cycle_time"] for r in done])
        F = np.array([bool(r["metrics"]["feasible"]) for r in done])
        ax.scatter(R[F], T[F], s=16, c="tab:blue", label="feasible design")
        ax.scatter(R[~F], T[~F], s=16, c="0.6", marker="x", label="infeasible (torque or coverage)")
        front = pareto_rows([r["metrics"] for r in done], maximise=(), minimise=("torque_ratio", "cycle_time"))
        o = sorted(front, key=lambda i: R[i])
        ax.step(R[o], T[o], where="post", c="tab:red", lw=1.5, label="Pareto front")
        ax.axvline(1.0, ls="--", c="k", lw=1.0, label="torque limit")
    for (label, ratio, t), marker, colour in zip(marks, "*^sP", ("gold", "tab:green", "tab:purple", "tab:brown")):
        ax.scatter([ratio], [t], marker=marker, s=140, c=colour, edgecolors="k", zorder=5, label=label)
    ax.set_xlabel("largest peak |τ| / τ_max over the joints")
    ax.set_ylabel("cycle time (s)")
    ax.set_title(f"{meta['name']}: cycle time against motor torque, {len(done)} designs")
    ax.legend(loc="upper right", fontsize=8)
    return save_figure(fig, path)

"""Figure of the drawing study (the bundled study ``ur3_drawing``, :mod:`studies.study.drawing`): joint
speeds of the naive resolved-rate method and of the QP follower, and the tracking error of every
method, against time.  Matplotlib Figure API (Agg, no pyplot state); written atomically."""
from __future__ import annotations

import os
from pathlib import Path

import numpy as np
from matplotlib.figure import Figure

from studies.plots.figure import save_figure

__all__ = ["plot_drawing"]

_COLOURS = ["#1f77b4", "#ff7f0e", "#2ca02c", "#d62728", "#9467bd", "#8c564b"]


def _positive(x: np.ndarray, floor: float) -> np.ndarray:
    """Values for a log axis: non-finite → NaN (a gap), ≤ floor → floor."""
    x = np.asarray(x, dtype=float).copy()
    x[~np.isfinite(x)] = np.nan
    return np.maximum(x, floor)


def plot_drawing(result: dict, path: str | os.PathLike, title: str = "") -> Path:
    """Three panels over time: per-joint speeds of the homework's naive method (log scale), per-joint
    speeds of the QP follower (reference mode), and the position tracking error of every method (log
    scale).  ``result`` is :func:`~studies.study.drawing.run_drawing_study` with ``series=True``."""
    s = result["series"]
    t = s["t"]
    ref = result.get("comparison", {}).get("reference_mode")
    fig = Figure(figsize=(10, 9), layout="constrained")
    ax1, ax2, ax3 = fig.subplots(3, 1, sharex=True)
    corners = t[result["path"]["corners"]]
    nh = s["naive_homework"]["joint_speed"]
    for j in range(nh.shape[1]):
        ax1.plot(t[1:], _positive(nh[1:, j], 1e-6), lw=0.8, color=_COLOURS[j % 6], label=f"q{j + 1}")
    nv = s["naive"]["joint_speed"]
    ax1.plot(t[1:], _positive(np.nanmax(nv[1:], axis=1), 1e-6), lw=1.2, color="k", ls="--",
             label="max, correct Jacobian")
    ax1.set_yscale("log")
    ax1.set_ylabel("joint speed (rad/s)")
    ax1.set_title("naive q += J⁻¹·ẋ·Δt with the homework's Jacobian (axes z1…z6)", fontsize=10)
    ax1.legend(ncol=4, fontsize=8, loc="upper left")
    if ref is not None:
        qs = s[f"qp_{ref}"]["joint_speed"]
        for j in range(qs.shape[1]):
            ax2.plot(t[1:], qs[1:, j], lw=0.9, color=_COLOURS[j % 6], label=f"q{j + 1}")
        ax2.set_title(f"OSQP follower, {ref} mode", fontsize=10)
        ax2.legend(ncol=6, fontsize=8, loc="upper left")
    ax2.set_ylabel("joint speed (rad/s)")
    floor = 1e-12
    ax3.plot(t, _positive(s["naive_homework"]["position_error"], floor), color="#d62728", lw=1.0,
             label="naive, homework Jacobian")
    ax3.plot(t, _positive(s["naive"]["position_error"], floor), color="k", lw=1.0, ls="--",
             label="naive, correct Jacobian")
    qp_style = {"qp_pose": ("#1f77b4", "-"), "qp_axis": ("#2ca02c", "--"), "qp_position": ("#9467bd", "-.")}
    for key, val in s.items():
        if key.startswith("qp_"):
            colour, ls = qp_style.get(key, ("#8c564b", "-"))
            ax3.plot(t, _positive(val["position_error"], floor), lw=1.0, color=colour, ls=ls,
                     label=f"QP, {key[3:]} mode")
    tol = result["tolerance"]["position_m"]
    ax3.axhline(tol, color="grey", lw=0.8, ls=":", label=f"tolerance {tol * 1e3:g} mm")
    ax3.set_yscale("log")
    ax3.set_ylabel("position error (m)")
    ax3.set_xlabel("time (s)")
    ax3.legend(fontsize=8, ncol=2, loc="lower right")
    for ax in (ax1, ax2, ax3):
        for c in corners:
            ax.axvline(c, color="grey", lw=0.5, alpha=0.5)
        ax.grid(True, which="major", alpha=0.3)
    fig.suptitle(title or f"{result['robot']}: the drawing task from a singular start", fontsize=11)
    return save_figure(fig, path)

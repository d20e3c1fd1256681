"""The figure of ``rmt time --plot``: joint speed, acceleration and torque of a timed trajectory
(:class:`planning.timing.TimedTrajectory`), each divided by its limit, against time, with the limits
±1 drawn."""
from __future__ import annotations

import os
from pathlib import Path

import numpy as np
from matplotlib.figure import Figure

from studies.plots.figure import save_figure

__all__ = ["timing_figure", "plot_timing"]

#: times per interval between the trajectory's samples drawn (from the exact s(t))
PER_INTERVAL = 4


def _times(t: np.ndarray) -> np.ndarray:
    if len(t) < 2:
        return t.copy()
    u = np.linspace(0.0, 1.0, PER_INTERVAL + 1)[:-1]
    return np.r_[(t[:-1, None] + np.diff(t)[:, None] * u[None, :]).ravel(), t[-1]]


def timing_figure(traj, names: list[str], title: str = "") -> Figure:
    """Three panels — |q̇|/v_max, q̈/a_max, τ/τ_max per joint — against time; the torque panel only
    when the trajectory carries torques (τ/τ_max only where a limit is known, else τ in N·m or N)."""
    ts = _times(traj.t)
    _, qd, qdd = traj.sample(ts)
    rows = 3 if traj.tau is not None else 2
    fig = Figure(figsize=(9, 2.6 * rows), layout="constrained")
    axes = fig.subplots(rows, 1, sharex=True, squeeze=False)[:, 0]
    panels = [(qd / traj.v_max, "q̇ / v_max"), (qdd / traj.a_max, "q̈ / a_max")]
    if traj.tau is not None:
        lim = traj.tau_max if traj.tau_max is not None else np.full(traj.tau.shape[1], np.inf)
        scale = np.where(np.isfinite(lim), lim, 1.0)
        panels.append((traj.tau / scale, "τ / τ_max" if np.all(np.isfinite(lim)) else "τ / τ_max (N·m, N unlimited)"))
    for k, (ax, (y, label)) in enumerate(zip(axes, panels)):
        x = traj.t if k == 2 else ts
        for j in range(y.shape[1]):
            ax.plot(x, y[:, j], lw=1.0, label=names[j])
        for lv in (-1.0, 1.0):
            ax.axhline(lv, color="k", ls="--", lw=0.8)
        ax.set_ylabel(label)
        ax.grid(alpha=0.3)
    axes[0].legend(loc="upper right", fontsize="small", ncols=min(len(names), 7))
    axes[-1].set_xlabel("t (s)")
    fig.suptitle(title or f"timed trajectory: {traj.duration:.4g} s")
    return fig


def plot_timing(traj, path: str | os.PathLike, names: list[str], title: str = "") -> Path:
    """:func:`timing_figure` written as PNG to ``path`` (:func:`studies.plots.figure.save_figure`)."""
    return save_figure(timing_figure(traj, names, title), path)

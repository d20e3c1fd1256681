"""Figure of a path following (:func:`studies.study.follow.follow_toolpath`, ``rmt follow --plot``):
three panels against time, one line per method — the largest joint speed over its limit (log
scale, the limit at 1), the position error in the robot file's length unit (log scale, with the
tolerance) and σ_min of the task Jacobian (log scale), with the waypoints where the follower is
inside a singular window shaded.  matplotlib's Figure API (Agg, no pyplot state); written
atomically."""
from __future__ import annotations

import os
from pathlib import Path

import numpy as np
from matplotlib.figure import Figure

from planning.follow import joint_velocity_limits
from studies.plots.figure import save_figure

__all__ = ["follow_figure", "plot_follow"]

STYLE = {"qp": ("#1f77b4", "-"), "naive": ("#d62728", "--")}


def _positive(x: np.ndarray, floor: float) -> np.ndarray:
    """Values for a log axis: non-finite → NaN (a gap), ≤ floor → floor."""
    x = np.asarray(x, dtype=float).copy()
    x[~np.isfinite(x)] = np.nan
    return np.maximum(x, floor)


def _runs(mask: np.ndarray) -> list[tuple[int, int]]:
    """(first, last) index of every run of True."""
    d = np.diff(np.concatenate([[0], np.asarray(mask, dtype=np.int8), [0]]))
    return list(zip(np.nonzero(d == 1)[0], np.nonzero(d == -1)[0] - 1))


def follow_figure(comparison, title: str = "") -> Figure:
    """The figure of a :class:`~studies.study.follow.FollowComparison` (see the module docstring)."""
    robot = comparison.robot
    c = robot.chain
    v_max = joint_velocity_limits(robot)
    fig = Figure(figsize=(10, 8.5), layout="constrained")
    ax1, ax2, ax3 = fig.subplots(3, 1, sharex=True)
    for r in comparison.runs:
        colour, ls = STYLE.get(r.key, ("#2ca02c", "-."))
        res = r.result
        label = f"{r.label} ({res.mode})"
        with np.errstate(invalid="ignore"):
            ratio = np.nanmax(res.joint_speed / v_max[None, :], axis=1)
        ax1.plot(res.t[1:], _positive(ratio[1:], 1e-9), color=colour, ls=ls, lw=1.1, label=label)
        ax2.plot(res.t, _positive(res.position_error / c.length_scale, 1e-15), color=colour, ls=ls, lw=1.1,
                 label=label)
        ax3.plot(res.t, _positive(r.sigma_min, 1e-16), color=colour, ls=ls, lw=1.1, label=label)
    ax1.axhline(1.0, color="grey", lw=0.8, ls=":", label="speed limit")
    ax1.set_ylabel("max joint speed / limit")
    ax2.axhline(comparison.tolerance[0] / c.length_scale, color="grey", lw=0.8, ls=":",
                label=f"tolerance {comparison.tolerance[0] / c.length_scale:g} {c.length_unit}")
    ax2.set_ylabel(f"position error ({c.length_unit})")
    ax3.set_ylabel("σ_min of J (SI; ≤ 1e-16 drawn at 1e-16)")
    ax3.set_xlabel("time (s)")
    qp = comparison.runs[0]
    inside = np.asarray(qp.in_window) >= 0
    t = qp.result.t
    for k, (a, b) in enumerate(_runs(inside)):
        for ax in (ax1, ax2, ax3):
            ax.axvspan(t[a], t[b] if b > a else t[a] + 1e-9, color="#f4a582", alpha=0.3, lw=0,
                       label="follower inside a singular window" if (k == 0 and ax is ax3) else None)
    for ax in (ax1, ax2, ax3):
        ax.set_yscale("log")
        ax.grid(True, which="major", alpha=0.3)
        ax.legend(fontsize=8, loc="best")
    fig.suptitle(title or f"{robot.name}: following {comparison.source or 'the tool path'} ({comparison.mode} mode)",
                 fontsize=11)
    return fig


def plot_follow(comparison, path: str | os.PathLike, title: str = "") -> Path:
    """Write :func:`follow_figure` of ``comparison`` as PNG to ``path``."""
    return save_figure(follow_figure(comparison, title), path)

"""Helpers of the ``scara_design`` study: the SCARA's coverage in closed form (the independent check
of the IK-verified metric) and the study's figures.

Closed form.  The SCARA (``studies/tasks/robots/scara_design.toml``: revolute J1, J2 with arms
A1, A2 in a horizontal plane, then the vertical prismatic J3) reaches a point at horizontal radius r
iff |A1 − A2| ≤ r ≤ A1 + A2 (cos q2 = (r² − A1² − A2²)/(2·A1·A2)), on one of the two elbow branches
±q2, with q1 = atan2(y, x) − atan2(A2·sin q2, A1 + A2·cos q2); both joints must be inside their
limits, and the height z must be inside J3's stroke.  The translational Jacobian is block-diagonal
(the planar 2×2 block and J3's unit column), so σ_min = min(σ_min(2×2), 1) with, for the 2×2 block,
σ_min² = (F − √(F² − 4·det²))/2, F = A1² + 2·A2² + 2·A1·A2·cos q2 (its squared Frobenius norm) and
det = A1·A2·sin q2.  Everything SI (m, rad, m/rad).
"""
from __future__ import annotations

import numpy as np
from matplotlib.figure import Figure

__all__ = ["scara_sigma", "scara_covered", "closed_form_map", "task_figure", "optimum_figure",
           "design_plane_figure", "arm_points"]


def scara_sigma(l1, l2, xy: np.ndarray, lower: np.ndarray, upper: np.ndarray) -> np.ndarray:
    """Best σ_min (m/rad) of the translational Jacobian over the elbow branches inside the limits of
    J1, J2, for designs ``l1``, ``l2`` (D,) m and points ``xy`` (N, 2) m: (D, N), NaN where no
    branch reaches the point."""
    l1 = np.atleast_1d(np.asarray(l1, float))[:, None]
    l2 = np.atleast_1d(np.asarray(l2, float))[:, None]
    x, y = xy[:, 0][None], xy[:, 1][None]
    c2 = (x ** 2 + y ** 2 - l1 ** 2 - l2 ** 2) / (2 * l1 * l2)
    reach = np.abs(c2) <= 1.0
    c2 = np.clip(c2, -1.0, 1.0)
    best = np.full(c2.shape, np.nan)
    for sign in (1.0, -1.0):
        q2 = sign * np.arccos(c2)
        q1 = np.arctan2(y, x) - np.arctan2(l2 * np.sin(q2), l1 + l2 * np.cos(q2))
        q1 = (q1 + np.pi) % (2 * np.pi) - np.pi
        inside = reach & (q1 >= lower[0]) & (q1 <= upper[0]) & (q2 >= lower[1]) & (q2 <= upper[1])
        F = l1 ** 2 + 2 * l2 ** 2 + 2 * l1 * l2 * np.cos(q2)
        det = l1 * l2 * np.sin(q2)
        sigma = np.minimum(np.sqrt(np.maximum((F - np.sqrt(np.maximum(F ** 2 - 4 * det ** 2, 0.0))) / 2, 0.0)), 1.0)
        best = np.where(inside & ~(best >= sigma), sigma, best)
    return best


def scara_covered(l1, l2, positions: np.ndarray, lower: np.ndarray, upper: np.ndarray, sigma_min: float,
                  z0: float) -> np.ndarray:
    """(D, N) bool: target ``positions`` (N, 3) m covered by design (l1, l2) with σ_min ≥ ``sigma_min``;
    ``z0`` the tool height at q3 = 0 (the sum of the fixed d's), so q3 = z − z0 must be in J3's stroke."""
    sigma = scara_sigma(l1, l2, positions[:, :2], lower, upper)
    z_ok = (positions[:, 2] - z0 >= lower[2]) & (positions[:, 2] - z0 <= upper[2])
    return (np.nan_to_num(sigma, nan=-1.0) >= sigma_min * (1 - 1e-9)) & z_ok[None]


def closed_form_map(axis: np.ndarray, positions: np.ndarray, lower, upper, sigma_min: float, z0: float) -> np.ndarray:
    """Covered share of the targets (0..1) in closed form over the design plane ``axis`` × ``axis``
    (A1 along the first index, A2 along the second), m."""
    A1, A2 = np.meshgrid(axis, axis, indexing="ij")
    cov = scara_covered(A1.ravel(), A2.ravel(), positions, lower, upper, sigma_min, z0)
    return cov.mean(axis=1).reshape(A1.shape)


def closed_form_optimum(positions, lower, upper, sigma_min: float, z0: float, bounds,
                        coarse: float = 1e-3, steps: tuple[float, ...] = (1e-4, 1e-5), margin: float = 5e-3):
    """The shortest design (A1, A2) m covering every target, in closed form, to the last of ``steps``.

    A ``coarse`` grid over the bounds finds the valley of short covering designs; each refinement then
    searches the band of lengths A1 + A2 just below the best so far (``margin``, then ten steps of the
    previous refinement) over the valley's A1 range, A2 = length − A1, at its step.  None when no
    design of the coarse grid covers every target."""
    def covering(A1, A2):
        keep = (A2 >= bounds[1, 0]) & (A2 <= bounds[1, 1])
        A1, A2 = A1[keep], A2[keep]
        ok = scara_covered(A1, A2, positions, lower, upper, sigma_min, z0).all(axis=1)
        return A1[ok], A2[ok]

    def axis(lo, hi, step):
        return np.linspace(lo, hi, int(round((hi - lo) / step)) + 1)

    A1, A2 = covering(*(g.ravel() for g in np.meshgrid(axis(*bounds[0], coarse), axis(*bounds[1], coarse),
                                                       indexing="ij")))
    if not len(A1):
        return None
    prev, width = coarse, margin
    for step in steps:
        best = (A1 + A2).min()
        valley = A1 + A2 <= best + prev + 1e-12
        a1 = axis(max(A1[valley].min() - 2 * prev, bounds[0, 0]), min(A1[valley].max() + 2 * prev, bounds[0, 1]), step)
        lengths = axis(best - width, best, step)
        N1, N2 = covering(np.repeat(a1, len(lengths)), np.tile(lengths, len(a1)) - np.repeat(a1, len(lengths)))
        if len(N1):
            A1, A2 = N1, N2
        prev, width = step, 10 * step
    i = int(np.argmin(A1 + A2))
    return np.array([A1[i], A2[i]])


# ----------------------------------------------------------------------------------------- figures
def arm_points(l1: float, l2: float, q1: float, q2: float) -> np.ndarray:
    """Base, elbow and tool of the arm in the horizontal plane (3, 2), in the units of l1, l2."""
    elbow = l1 * np.array([np.cos(q1), np.sin(q1)])
    return np.array([[0.0, 0.0], elbow, elbow + l2 * np.array([np.cos(q1 + q2), np.sin(q1 + q2)])])


def _region(ax, l1: float, l2: float, lower, upper, sigma_min: float, lim: float, colour: str, label: str):
    """Shade the horizontal region (mm axes) where the design (l1, l2 m) reaches with σ_min ≥ the
    threshold, in closed form; returns a legend handle."""
    from matplotlib.patches import Patch
    g = np.linspace(-lim, lim, 401)
    X, Y = np.meshgrid(g, g)
    sig = scara_sigma([l1], [l2], np.column_stack([X.ravel(), Y.ravel()]) / 1e3, lower, upper)[0].reshape(X.shape)
    ok = np.nan_to_num(sig, nan=-1.0) >= sigma_min
    ax.contourf(X, Y, ok.astype(float), levels=[0.5, 1.5], colors=[colour], alpha=0.35)
    ax.contour(X, Y, ok.astype(float), levels=[0.5], colors=[colour], linewidths=1.0)
    return Patch(facecolor=colour, alpha=0.35, edgecolor=colour, label=label)


def _plane_axes(ax, lim: float):
    ax.set_xlim(-lim, lim)
    ax.set_ylim(-lim, lim)
    ax.set_aspect("equal")
    ax.set_xlabel("x (mm)")
    ax.set_ylabel("y (mm)")
    ax.ticklabel_format(useOffset=False)
    ax.grid(alpha=0.3)


def task_figure(positions_mm: np.ndarray, nominal_m: tuple[float, float], lower, upper, sigma_min: float) -> Figure:
    """The targets seen from above, the box they fill, the radii they span, and where the nominal
    design reaches them with the required dexterity (closed form)."""
    fig = Figure(figsize=(7.0, 6.2))
    ax = fig.add_subplot(111)
    lim = 1.15 * 1e3 * (nominal_m[0] + nominal_m[1])
    h = _region(ax, *nominal_m, lower, upper, sigma_min, lim, "tab:green",
                f"nominal A1 = {1e3 * nominal_m[0]:.0f}, A2 = {1e3 * nominal_m[1]:.0f} mm: "
                f"σ_min ≥ {sigma_min:g} m/rad")
    lo, hi = positions_mm[:, :2].min(axis=0), positions_mm[:, :2].max(axis=0)
    box, = ax.plot([lo[0], hi[0], hi[0], lo[0], lo[0]], [lo[1], lo[1], hi[1], hi[1], lo[1]], "k-", lw=1.0,
                   label="target box")
    pts = ax.scatter(positions_mm[:, 0], positions_mm[:, 1], s=22, c="tab:blue", zorder=3,
                     label=f"{len(positions_mm)} targets")
    r = np.hypot(positions_mm[:, 0], positions_mm[:, 1])
    t = np.linspace(-np.pi, np.pi, 361)
    circ = None
    for rad in (r.min(), r.max()):
        circ, = ax.plot(rad * np.cos(t), rad * np.sin(t), "k--", lw=0.8,
                        label=f"target radii {r.min():.0f} … {r.max():.0f} mm")
    base = ax.scatter([0], [0], marker="s", s=50, c="k", zorder=4, label="base (J1 axis)")
    _plane_axes(ax, lim)
    ax.set_title(f"the task seen from above (targets at z = {positions_mm[0, 2]:.0f} mm)")
    ax.legend(handles=[pts, box, circ, h, base], loc="lower left", fontsize=8)
    return fig


def optimum_figure(positions_mm: np.ndarray, design_m: tuple[float, float], cov, lower, upper,
                   sigma_min: float) -> Figure:
    """The optimum seen from above: where it reaches with the required dexterity (closed form,
    shaded), the targets coloured by the IK-verified best σ_min, and the arm at the target with the
    smallest σ_min (the one that sets the length)."""
    fig = Figure(figsize=(7.4, 6.2))
    ax = fig.add_subplot(111)
    l1, l2 = design_m
    lim = 1.15 * 1e3 * (l1 + l2)
    h = _region(ax, l1, l2, lower, upper, sigma_min, lim, "tab:green",
                f"σ_min ≥ {sigma_min:g} m/rad (closed form)")
    ok = cov.covered
    handles = [h]
    if ok.any():
        sc = ax.scatter(positions_mm[ok, 0], positions_mm[ok, 1], c=cov.best[ok], cmap="viridis", s=30, zorder=3,
                        edgecolors="k", linewidths=0.4, label="target, covered (IK)")
        fig.colorbar(sc, ax=ax, label="best σ_min at the target (m/rad)", shrink=0.8)
        handles.append(sc)
    if (~ok).any():
        handles.append(ax.scatter(positions_mm[~ok, 0], positions_mm[~ok, 1], c="red", marker="x", s=30, zorder=3,
                                  label="target, not covered"))
    k = int(np.nanargmin(np.where(ok, cov.best, np.inf))) if ok.any() else 0
    arm = arm_points(1e3 * l1, 1e3 * l2, cov.q[k, 0], cov.q[k, 1])
    line, = ax.plot(arm[:, 0], arm[:, 1], "-o", c="tab:red", lw=2.5, ms=5, zorder=4,
                    label=f"arm at the least dexterous target (σ_min {cov.best[k]:.3f} m/rad)")
    handles.append(line)
    _plane_axes(ax, lim)
    ax.set_title(f"optimum A1 = {1e3 * l1:.1f} mm, A2 = {1e3 * l2:.1f} mm: {100 * cov.fraction:.0f} % covered")
    ax.legend(handles=handles, loc="lower left", fontsize=8)
    return fig


def design_plane_figure(axis_mm: np.ndarray, cf_share: np.ndarray, grid_P_mm: np.ndarray, grid_feasible: np.ndarray,
                        grid_cf: np.ndarray, marks: list[tuple[str, float, float, str, str]], z_len_mm: float,
                        best_len_mm: float) -> Figure:
    """The design plane A1 × A2 (mm): the closed-form covered share, its 100 % boundary, the grid's
    IK-verified feasible designs (disagreements with the closed form crossed), the line of equal
    length through the optimum, and the optimisers' answers ``marks`` (label, A1, A2, marker, colour)."""
    from matplotlib.lines import Line2D
    fig = Figure(figsize=(7.4, 6.2))
    ax = fig.add_subplot(111)
    m = ax.pcolormesh(axis_mm, axis_mm, 100 * cf_share.T, shading="nearest", cmap="Greys_r", vmin=0, vmax=100)
    fig.colorbar(m, ax=ax, label="targets covered, closed form (%)", shrink=0.8)
    ax.contour(axis_mm, axis_mm, cf_share.T, levels=[1 - 1e-9], colors=["tab:green"], linewidths=1.5)
    handles = [Line2D([], [], c="tab:green", lw=1.5, label="100 % covered (closed form)")]
    feas = grid_feasible
    handles.append(ax.scatter(grid_P_mm[feas, 0], grid_P_mm[feas, 1], s=4, c="tab:cyan",
                              label=f"grid design feasible by IK ({int(feas.sum())})"))
    bad = feas != grid_cf
    if bad.any():
        handles.append(ax.scatter(grid_P_mm[bad, 0], grid_P_mm[bad, 1], s=24, c="red", marker="x",
                                  label=f"IK and closed form disagree ({int(bad.sum())})"))
    a = np.array([axis_mm[0], axis_mm[-1]])
    handles.append(ax.plot(a, best_len_mm - z_len_mm - a, "--", c="tab:orange", lw=1.0,
                           label=f"A1 + A2 = {best_len_mm - z_len_mm:.1f} mm")[0])
    for label, x, y, marker, colour in marks:
        handles.append(ax.scatter([x], [y], marker=marker, s=90, c=colour, edgecolors="k", zorder=5, label=label))
    ax.set_xlim(axis_mm[0], axis_mm[-1])
    ax.set_ylim(axis_mm[0], axis_mm[-1])
    ax.set_aspect("equal")
    ax.set_xlabel("A1 (mm)")
    ax.set_ylabel("A2 (mm)")
    ax.ticklabel_format(useOffset=False)
    ax.set_title("the design plane: where every target is covered")
    ax.legend(handles=handles, loc="upper right", fontsize=7.5)
    return fig

"""Figures of the ``scara_error_window`` study (kept here so that the study reads as a script):
the dexterity of the SCARA across θ2 with the window bands shaded, and the learned IK's joint error
across its training branch."""
from __future__ import annotations

import numpy as np
from matplotlib.figure import Figure

__all__ = ["BAND_COLOURS", "dexterity_across_window", "learned_error_across_branch"]

#: shading of each window band, keyed by the band's label prefix
BAND_COLOURS = {"thesis": "#d62728", "σ_min": "#2ca02c", "learned": "#1f77b4"}


def _shade(ax, bands: list[tuple[str, float]]) -> None:
    """Shade the bands |θ2| ≤ w, widest first so that the narrow ones stay visible on top, with their
    edges drawn in the band's colour."""
    for label, w in sorted(bands, key=lambda b: -b[1]):
        colour = next(c for k, c in BAND_COLOURS.items() if label.startswith(k))
        ax.axvspan(-w, w, color=colour, alpha=0.15, lw=0, label=f"{label}: |θ2| ≤ {w:.3g} rad")
        for x in (-w, w):
            ax.axvline(x, color=colour, lw=0.9, alpha=0.8)


def dexterity_across_window(q2: np.ndarray, sigma_min: np.ndarray, det_mm2: np.ndarray, closed_mm2: np.ndarray,
                            threshold: float, bands: list[tuple[str, float]], zoom: float) -> Figure:
    """Three panels over θ2 (rad): σ_min (SI, m/rad) with the threshold, det Jv (mm²) beside the closed
    form, and σ_min near θ2 = 0 (|θ2| ≤ ``zoom``) where the thesis's narrow band is visible."""
    fig = Figure(figsize=(13, 4.4), layout="constrained")
    ax1, ax2, ax3 = fig.subplots(1, 3)
    for ax in (ax1, ax2, ax3):
        ax.ticklabel_format(useOffset=False, style="plain")
        ax.set_xlabel("θ2 (rad)")
        ax.grid(alpha=0.3)
    _shade(ax1, bands)
    ax1.plot(q2, sigma_min, color="k", lw=1.4, label="σ_min of Jv (rmtkit)")
    ax1.axhline(threshold, color=BAND_COLOURS["σ_min"], ls="--", lw=1.2, label=f"threshold {threshold:.3g} m/rad")
    ax1.set_ylabel("σ_min of the position Jacobian (m/rad)")
    ax1.set_title("dexterity across θ2")
    ax1.legend(fontsize=8, loc="upper center")
    _shade(ax2, bands)
    ax2.plot(q2, det_mm2, color="k", lw=2.4, alpha=0.45, label="det Jv (rmtkit)")
    ax2.plot(q2, closed_mm2, color="#ff7f0e", lw=1.2, ls="--", label="closed form 101250·sin θ2")
    ax2.axhline(0, color="0.4", lw=0.8)
    ax2.set_ylabel("det Jv (mm²)")
    ax2.set_title("determinant: rmtkit against the closed form")
    ax2.legend(fontsize=8, loc="upper left")
    near = np.abs(q2) <= zoom
    _shade(ax3, [(b, w) for b, w in bands if w < zoom])
    wide = [b for b, w in bands if w >= zoom]
    if wide:
        ax3.text(0.5, 0.6, f"the {' and '.join(wide)}\nwindows cover this whole panel", transform=ax3.transAxes,
                 ha="center", fontsize=8, color="0.3")
    ax3.plot(q2[near], sigma_min[near], color="k", lw=1.4, label="σ_min of Jv (rmtkit)")
    ax3.set_xlim(-zoom, zoom)
    ax3.set_ylim(0, None)
    ax3.set_ylabel("σ_min of the position Jacobian (m/rad)")
    ax3.set_title(f"close to the singularity (|θ2| ≤ {zoom:g} rad)")
    ax3.legend(fontsize=8, loc="upper center")
    return fig


def learned_error_across_branch(q2: np.ndarray, err: np.ndarray, q2_singular: np.ndarray, err_singular: np.ndarray,
                                width: float, bins: int = 40) -> Figure:
    """The learned IK's |Δθ2| (rad) against θ2 over its training branch, its 95th percentile per bin,
    the errors at the singular poses (θ2 = 0) and the window half-width (their maximum)."""
    fig = Figure(figsize=(9, 4.2), layout="constrained")
    ax = fig.add_subplot()
    ax.ticklabel_format(useOffset=False, style="plain")
    ax.scatter(q2, err, s=3, color="#4c6a8a", alpha=0.3, lw=0, label=f"fresh poses of the branch ({len(q2):,})")
    edges = np.linspace(q2.min(), q2.max(), bins + 1)
    idx = np.clip(np.digitize(q2, edges) - 1, 0, bins - 1)
    p95 = np.array([np.percentile(err[idx == k], 95) if np.any(idx == k) else np.nan for k in range(bins)])
    ax.plot(0.5 * (edges[:-1] + edges[1:]), p95, color="k", lw=1.4, label="95th percentile per bin")
    ax.scatter(q2_singular, err_singular, s=10, color=BAND_COLOURS["thesis"], alpha=0.5, lw=0,
               label=f"singular poses, θ2 = 0 ({len(q2_singular):,})")
    ax.axhline(width, color=BAND_COLOURS["learned"], ls="--", lw=1.2,
               label=f"window half-width = largest error at θ2 = 0: {width:.3g} rad")
    ax.set_xlabel("true θ2 (rad)")
    ax.set_ylabel("|θ2 predicted − θ2 true| (rad)")
    ax.set_yscale("log")
    ax.set_title("learned IK: joint-2 error across its training branch")
    ax.grid(alpha=0.3, which="both")
    ax.legend(fontsize=8, loc="lower right")
    return fig

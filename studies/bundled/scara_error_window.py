"""The SCARA arm of the singularities thesis (RRP, its Table 2; docs/machines.md §2) redone: its one
singularity, θ2 = 0 (the arm stretched out at 675 mm), checked against the closed form
det Jv = 101250 · sin θ2 mm²; the thesis's learned-IK "error window" θ2 ∈ [−0.01, 0.01] rad
recomputed with a seeded network and set beside a window tied to a dexterity requirement (σ_min);
and the workspace, an annulus swept along the 200 mm stroke of the vertical axis.

The two widths answer different questions. The learned width is the largest joint-2 error a small
neural network makes when asked for the inverse kinematics of stretched-out poses: it measures that
network (its size, training data and seed), not the machine. The σ_min window is where the arm
cannot deliver a required tool speed within a joint-speed budget: it follows from the Jacobian and a
requirement you choose, and it is the one to plan around.
"""
from __future__ import annotations

import sys

import numpy as np
from matplotlib.figure import Figure

from design.learned.windows import jsonable_report, learned_windows
from planning.windows import build_windows
from studies.published import PUBLISHED_LEARNED_WINDOWS, compare_learned_window
from studies.study import Study, main, sections

NAME = "scara_error_window"
TITLE = "SCARA (RRP): the singularity θ2 = 0 and its error window"

#: forward-kinematics checks of docs/machines.md §2 (joint values and tool positions in mm and rad)
FK_CHECKS = [("FK(0, 0, −197)", [0.0, 0.0, -197.0]), ("FK(0.5, 1.0, −150)", [0.5, 1.0, -150.0])]
FK_REFERENCE = {"FK(0, 0, −197)": [675.0, 0.0, -195.0], "FK(0.5, 1.0, −150)": [229.29, 556.74, -148.0]}
FK_TOL_MM = 0.01           # the reference values are printed to 0.01 mm
#: the closed form of docs/machines.md §2: det Jv = DET_COEFF_MM2 · sin θ2 (mm²)
DET_COEFF_MM2 = 101250.0


def _interval(lo: float, hi: float) -> str:
    """[lo, hi] with true minus signs, as the report's numbers have them."""
    return f"[{lo:.4g}, {hi:.4g}]".replace("-", "−")


def run(s: Study) -> None:
    robot = s.robot("scara_rrp")
    chain = robot.chain
    mm = chain.length_scale                    # metres per millimetre: robot.fk and robot.det work in SI
    seed = s.input("seed", 0)
    n_check = s.input("det check: random configurations", 2_000 if s.quick else 20_000)
    # the dexterity requirement behind the σ_min window: the tool must move at V_TOOL in any
    # horizontal direction with joint speeds of at most QDOT_MAX, i.e. σ_min ≥ V_TOOL / QDOT_MAX
    v_tool = s.input("σ_min window: tool speed (m/s)", 0.1)
    qdot_max = s.input("σ_min window: joint-speed budget (rad/s)", 5.0)
    threshold = v_tool / qdot_max
    # the learned window's dependence on training: training sizes × seeds
    train_sizes = s.input("learned window: training sizes", [2_000, 20_000] if s.quick else
                          [2_000, 5_000, 20_000, 50_000])
    train_seeds = s.input("learned window: seeds", [0] if s.quick else [0, 1, 2])
    n_workspace = s.input("workspace: samples", 20_000 if s.quick else 200_000)

    with s.section("The machine"):
        s.text("Three joints: two revolute joints about vertical axes (θ1, θ2) and a vertical prismatic "
               "joint (d3). Every link has a = 225 mm and α = 0, so the tool moves in horizontal circles set "
               "by θ1 and θ2 and slides vertically with d3; the last link carries the tool 225 mm beyond "
               "the second joint's link, so the effective forearm is 450 mm.")
        sections.dh_table(s, robot)
        rows = sections.configurations_table(s, robot, FK_CHECKS, expected=FK_REFERENCE, tol=FK_TOL_MM)
        worst = max(r["deviation"] for r in rows)
        s.finding(f"forward kinematics matches docs/machines.md §2 at both reference configurations "
                  f"(largest deviation {worst:.2g} mm, within the 0.01 mm the values are printed to)",
                  ok=worst <= FK_TOL_MM)

    with s.section("The singular set"):
        analysis = sections.singular_set(s, robot)
        factor = analysis.factors[0]
        # our factor against the closed form, numerically: det Jv from the compiled Jacobian (SI, m²)
        # in mm², beside 101250·sin θ2 and beside the factor found by the analysis
        Q = robot.random_configurations(n_check, seed=seed)
        det_mm2 = robot.det(Q) / mm**2
        closed = DET_COEFF_MM2 * np.sin(Q[:, 1])
        away = np.abs(factor(Q)) > 1e-3                      # the ratio is ill-conditioned right at the zero set
        ratio = det_mm2[away] / factor(Q)[away]
        diff = float(np.max(np.abs(det_mm2 - closed)))
        s.table(["random configurations", "max |det Jv − 101250·sin θ2| (mm²)", "det Jv / factor: min (mm²)",
                 "det Jv / factor: max (mm²)"], [[n_check, diff, ratio.min(), ratio.max()]],
                f"det Jv of the compiled Jacobian at {n_check:,} random configurations (seed {seed}) against the "
                f"closed form of docs/machines.md §2, and divided by the analysis's factor `{factor.expr}`: the "
                "quotient is constant, so the factor is the whole singular set.", fmt=".7g")
        one_factor = (len(analysis.factors) == 1 and factor.single_joint == 1
                      and list(factor.solutions.get("values", [])) == [0.0])
        matches = diff <= 1e-6 * DET_COEFF_MM2 and float(np.ptp(ratio)) <= 1e-6 * DET_COEFF_MM2
        s.results["det_check"] = {"samples": n_check, "seed": seed, "closed_form": "101250 sin(q2) mm^2",
                                  "max_abs_difference_mm2": diff, "factor": factor.expr,
                                  "det_over_factor_mm2": [float(ratio.min()), float(ratio.max())]}
        s.text(f"The arm is singular only where `{factor.expr}` = 0 inside the limits: θ2 = 0, the arm stretched "
               "out at its full reach of 675 mm (a **boundary** singularity: the tool cannot move further out). "
               "The folded pose θ2 = ±π is the other root of sin θ2, but the elbow stops at ±2.53 rad.")
        s.finding(f"one singular factor, θ2 = 0 (det Jv = {float(np.median(ratio)):.6g}·sin θ2 mm² on {n_check:,} "
                  f"samples, closed form 101250·sin θ2; largest difference {diff:.2g} mm²)", ok=one_factor and matches)

    with s.section("Error windows"):
        thesis = PUBLISHED_LEARNED_WINDOWS["scara_rrp"]["interval"]
        w_thesis = 0.5 * (thesis[1] - thesis[0])
        # the thesis's method, made reproducible: a 55-unit tanh network trained on one IK branch
        # (θ2 ≥ 0), evaluated at poses with θ2 = 0; the window is the largest joint-2 error there
        s.say("training the learned IK")
        learned, reports = learned_windows(robot, analysis=analysis, seed=seed)
        rep = reports[0]
        w_learned = rep["width"]
        # the learned report, with the thesis's published window beside ours
        s.results["learned"] = jsonable_report(rep) | {"published": compare_learned_window(rep, robot.name)}
        # a window from a dexterity requirement: σ_min ≥ threshold outside it
        dex = build_windows(robot, sigma_min=threshold, analysis=analysis)
        w_sigma = dex.windows[0].width
        # σ_min of this arm depends on θ2 alone (θ1 turns the arm, d3 lifts it): checked on samples
        q_probe = robot.random_configurations(200, seed=seed + 1)
        q_probe_fixed = q_probe.copy()
        q_probe_fixed[:, 0], q_probe_fixed[:, 2] = 0.0, chain.lower[2]
        spread = float(np.max(np.abs(robot.sigma_min(q_probe) - robot.sigma_min(q_probe_fixed))))
        sigma_at_thesis = robot.sigma_min(np.array([0.0, w_thesis, chain.lower[2]]))

        s.table(["window", "θ2 interval (rad)", "half-width (rad)", "× thesis", "what sets it"],
                [["thesis (published)", _interval(thesis[0], thesis[1]), w_thesis, 1.0,
                  "a network's IK error at θ2 = 0, no seed or training size given"],
                 ["learned IK (rmtkit)", _interval(-w_learned, w_learned), w_learned, w_learned / w_thesis,
                  f"55 tanh units, {rep['n_train']:,} training poses, seed {seed}, largest error over "
                  f"{rep['n_eval']:,} singular poses"],
                 [f"σ_min ≥ {threshold:g} m/rad", _interval(-w_sigma, w_sigma), w_sigma, w_sigma / w_thesis,
                  f"{v_tool:g} m/s of tool speed with at most {qdot_max:g} rad/s of joint speed"]],
                "The three windows around θ2 = 0.", fmt=".4g")
        sections.windows_table(s, robot, learned, "learned IK", key="learned")
        sections.windows_table(s, robot, dex, f"σ_min ≥ {threshold:g} m/rad", key="sigma_min")

        s.heading("How the learned width depends on training")
        runs = []
        for n_train in train_sizes:
            for sd in train_seeds:
                if not (n_train == rep["n_train"] and sd == seed):
                    s.say(f"training run: {n_train:,} poses, seed {sd}")
                r = rep if (n_train == rep["n_train"] and sd == seed) else \
                    learned_windows(robot, analysis=analysis, seed=sd, n_train=n_train)[1][0]
                runs.append({"n_train": n_train, "seed": sd, "width": r["width"], "heldout_r2": r["heldout_r2"],
                             "heldout_max_q2": r["heldout_errors"]["max"][1],
                             "heldout_p95_q2": r["heldout_errors"]["p95"][1]})
        s.table(["training poses", "seed", "held-out R²", "held-out |Δθ2|: 95 % (rad)", "held-out |Δθ2|: max (rad)",
                 "window half-width (rad)"],
                [[r["n_train"], r["seed"], r["heldout_r2"], r["heldout_p95_q2"], r["heldout_max_q2"], r["width"]]
                 for r in runs],
                "The same method with other training sizes and seeds: the window follows the network.", fmt=".4g")
        widths = [r["width"] for r in runs]
        s.results["learned_training"] = runs

        s.heading("What each width means")
        s.text(f"**The learned width** (±{w_learned:.3g} rad here, ±{w_thesis:g} rad in the thesis) is the largest "
               "joint-2 error of a learned inverse-kinematics model at poses where θ2 = 0. It measures the network — "
               "its size, its training poses, its seed — and how badly a regression from position to joints fits "
               "where two elbow branches meet: over the training sizes and seeds above it ranges from "
               f"{min(widths):.3g} to {max(widths):.3g} rad. A bigger or better-trained network shrinks it without "
               "the machine changing at all, and the thesis gave neither its training set nor a seed, so its "
               "±0.01 rad cannot be reproduced or trusted as a property of the arm.")
        s.text(f"**The σ_min window** (±{w_sigma:.3g} rad) is tied to a requirement: outside it the smallest "
               f"singular value of the position Jacobian is at least {threshold:g} m/rad, so any horizontal tool "
               f"velocity of {v_tool:g} m/s needs a joint speed (θ̇1, θ̇2) of at most {qdot_max:g} rad/s in norm. "
               "It depends only on the Jacobian "
               f"(σ_min here depends on θ2 alone: changing θ1 and d3 moved it by at most {spread:.1g} m/rad on 200 "
               "samples) and on the requirement you write down; change the requirement and the width follows. "
               f"By this measure the thesis's ±0.01 rad corresponds to σ_min ≥ {sigma_at_thesis:.3g} m/rad: at "
               f"its edge a {v_tool:g} m/s tool speed can need {v_tool / sigma_at_thesis:.0f} rad/s of joint speed. "
               "This is the window to plan around.")

        q2 = np.linspace(-1.5 * max(w_learned, w_sigma), 1.5 * max(w_learned, w_sigma), 1201)
        q2 = q2[(q2 >= chain.lower[1]) & (q2 <= chain.upper[1])]
        Qg = np.column_stack([np.zeros_like(q2), q2, np.full_like(q2, chain.lower[2])])
        s.figure(dexterity_across_window(q2, robot.sigma_min(Qg), robot.det(Qg) / mm**2, DET_COEFF_MM2 * np.sin(q2),
                                         threshold, [("thesis", w_thesis), ("learned IK", w_learned),
                                                     (f"σ_min ≥ {threshold:g}", w_sigma)], zoom=0.05),
                 "sigma_min_across_window",
                 "σ_min of the position Jacobian and det Jv across θ2 (θ1 = 0, d3 at its lower limit; neither "
                 "changes them) with the three windows shaded; right: close to θ2 = 0, where the thesis's band is "
                 "visible.")
        model = rep["data"]["model"]
        Qb = model.sample_configurations(4_000 if s.quick else 20_000, seed=seed + 2)
        err = np.abs(model.predict(robot.fk(Qb))[:, 1] - Qb[:, 1])
        Qs, Ps = rep["data"]["q_true"], rep["data"]["q_pred"]
        s.figure(learned_error_across_branch(Qb[:, 1], err, Qs[:, 1], np.abs(Ps[:, 1] - Qs[:, 1]), w_learned),
                 "learned_error_across_branch",
                 f"The learned IK's joint-2 error over its training branch θ2 ∈ [0, {chain.upper[1]:g}] rad (fresh "
                 "poses, not used in training) and at the singular poses θ2 = 0, where the window is read off.")
        s.results["window_widths_rad"] = {"thesis": w_thesis, "learned": w_learned, "sigma_min": w_sigma,
                                          "sigma_min_threshold": threshold,
                                          "sigma_min_at_thesis_edge": sigma_at_thesis,
                                          "learned_range_over_training": [min(widths), max(widths)]}
        s.finding(f"the learned-IK window is ±{w_learned:.3g} rad vs the thesis's ±{w_thesis:g} rad "
                  f"({w_learned / w_thesis:.0f}× wider; {min(widths):.3g}–{max(widths):.3g} rad over "
                  f"{len(runs)} training runs): it measures the network, not the arm")
        s.finding(f"a dexterity requirement ({v_tool:g} m/s of tool speed within {qdot_max:g} rad/s, "
                  f"σ_min ≥ {threshold:g} m/rad) gives the window ±{w_sigma:.3g} rad; the thesis's ±{w_thesis:g} rad "
                  f"means accepting σ_min down to {sigma_at_thesis:.3g} m/rad")

    with s.section("Workspace"):
        # near-singular (red) = σ_min below the study's dexterity threshold, i.e. inside the σ_min window
        ws = sections.workspace(s, robot, n_workspace, seed, q_view=chain.to_si([0.6, 1.2, -197.0]),
                                threshold=threshold)
        # closed-form bounds: full reach with the arm stretched, the innermost radius with the elbow
        # folded to its limit, the height from d1 + d2 + d3
        a1, a2, a3 = (j.a for j in chain.joints)
        forearm = a2 + a3
        outer = a1 + forearm
        inner = float(np.sqrt(a1**2 + forearm**2 + 2 * a1 * forearm * np.cos(chain.upper[1])))
        z_lo, z_hi = (chain.joints[0].d + chain.joints[1].d + lim for lim in (chain.lower[2], chain.upper[2]))
        radius = np.hypot(ws.positions[:, 0], ws.positions[:, 1])
        z = ws.positions[:, 2]
        rows = [["outer radius (full reach)", outer / mm, radius.max() / mm],
                ["inner radius (elbow at its limit)", inner / mm, radius.min() / mm],
                ["lowest tool height", z_lo / mm, z.min() / mm], ["highest tool height", z_hi / mm, z.max() / mm]]
        s.table(["quantity", "closed form (mm)", "sampled (mm)"], rows,
                f"The sampled workspace against its closed-form bounds ({len(radius):,} samples).", fmt=".5g")
        s.text(f"Seen from above the workspace is an annulus between {inner / mm:.0f} mm and {outer / mm:.0f} mm; "
               f"since θ1 turns only ±{chain.upper[0]:g} rad, a wedge behind the base is missing near full reach. "
               f"Every horizontal point is available over the same {(z_hi - z_lo) / mm:.0f} mm of height, so the "
               "volume is this annulus extruded along the prismatic stroke. The near-singular samples (red: σ_min "
               f"below the {threshold:g} m/rad of the dexterity requirement, i.e. inside the σ_min window) lie on the "
               "outer rim, where the arm is stretched out (θ2 near 0).")
        s.results["workspace_bounds_mm"] = {"outer_radius": {"closed_form": outer / mm, "sampled": radius.max() / mm},
                                            "inner_radius": {"closed_form": inner / mm, "sampled": radius.min() / mm},
                                            "z": {"closed_form": [z_lo / mm, z_hi / mm],
                                                  "sampled": [z.min() / mm, z.max() / mm]}}
        within = radius.max() <= outer * (1 + 1e-9) and radius.min() >= inner * (1 - 1e-9)
        s.finding(f"workspace: an annulus of radii {inner / mm:.0f}–{outer / mm:.0f} mm over "
                  f"{(z_hi - z_lo) / mm:.0f} mm of height; sampled reach {radius.max() / mm:.1f} mm "
                  f"(closed form {outer / mm:.0f} mm)", ok=bool(within))


# ---- figures (matplotlib's Figure API, no pyplot state) -------------------------------------------
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


if __name__ == "__main__":
    raise SystemExit(main(sys.modules[__name__]))

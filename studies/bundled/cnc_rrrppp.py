"""The six-axis CNC machine of the singularities thesis, modelled as RRRPPP (its Table 19;
docs/machines.md §4), set beside the model the thesis actually evaluated: it handed the fixed angles
of the three linear axes (∓90°, ±90°) to sin and cos as radians. The study rebuilds that slipped
chain, compares the tool pose of both at several configurations, shows that the one singularity,
θ2 = 0, survives the slip (det J is proportional to sin θ2 in both, only the constant changes), and
compares the workspaces.

A degree/radian slip in a fixed DH angle does not announce itself: the slipped chain is a perfectly
valid machine, just not this one. rmtkit's robot files state their units and refuse an angle of
90 rad, so the slip cannot be written into a robot file; here it is built in memory on purpose.
"""
from __future__ import annotations

import sys
from dataclasses import replace

import numpy as np
from matplotlib.figure import Figure
from matplotlib.lines import Line2D

import kin
from design.workspace import compute_workspace
from kin.singular import analyse_singularities
from studies.study import Study, main, sections
from studies.study.rotations import rotation_angle_deg

NAME = "cnc_rrrppp"
TITLE = "CNC machine as RRRPPP: the correct model beside the thesis's degree/radian slip"

#: the fixed θ of the linear axes 4–6 as the thesis evaluated them: the degrees ∓90, ±90 read as radians
SLIP = {4: -90.0, 5: 90.0, 6: -90.0}
#: configurations compared (robot-file units: rad for joints 1–3, m for joints 4–6)
CONFIGS = [("home", [0.0, 0.0, 0.0, 0.0, 0.0, 0.0]),
           ("rotary axes turned", [0.5, -0.8, 1.2, 0.0, 0.0, 0.0]),
           ("linear axes extended", [0.0, 0.6, 0.0, 0.3, -0.2, 0.25]),
           ("mixed", [-1.0, 1.2, 0.4, -0.2, 0.1, 0.35]),
           ("limits corner", [1.74, -1.74, 1.74, 0.4, 0.3, -0.4])]


def slipped_chain(chain: kin.Chain) -> kin.Chain:
    """The chain as the thesis evaluated it: joints 4–6 keep every DH value but their fixed θ, which
    becomes ∓90, ±90 *radians* (the degrees taken as radians)."""
    joints = tuple(replace(j, theta=SLIP[i]) if i in SLIP else j for i, j in enumerate(chain.joints, 1))
    return replace(chain, name=f"{chain.name}_slipped", title=f"{chain.title}, fixed angles of joints 4–6 in "
                                                              "degrees read as radians", joints=joints)


def run(s: Study) -> None:
    robot = s.robot("cnc_rrrppp")
    chain = robot.chain
    slipped = kin.Robot(slipped_chain(chain))
    seed = s.input("seed", 0)
    n_compare = s.input("comparison: random configurations", 5_000 if s.quick else 50_000)
    n_workspace = s.input("workspace: samples", 20_000 if s.quick else 200_000)

    with s.section("The correct model"):
        s.text("Three revolute axes (θ1–θ3) position and orient the tool; three linear axes (d4–d6) move it. "
               "The table is the thesis's, with the fixed angles of the linear axes as meant: −π/2, π/2, −π/2 rad.")
        sections.dh_table(s, robot)
        sections.configurations_table(s, robot, CONFIGS)
        s.text("`home` is singular (σ_min = 0): it has θ2 = 0.")

    with s.section("The degree/radian slip"):
        correct_theta = [chain.joints[i - 1].theta for i in SLIP]
        s.table(["joint", "fixed θ as meant (rad)", "as the thesis evaluated it (rad)", "same angle mod 2π (rad)",
                 "in degrees mod 360 (°)"],
                [[f"J{i}", th, v, np.angle(np.exp(1j * v)), np.degrees(np.angle(np.exp(1j * v)))]
                 for (i, v), th in zip(SLIP.items(), correct_theta)],
                "The slipped chain: joints 4–6 with their fixed θ in degrees read as radians; everything else is "
                "the correct table.", fmt=".6g")
        try:
            kin.loads_robot(kin.dumps_robot(slipped.chain), path="cnc_rrrppp_slipped.toml")
            refused = None
        except kin.RobotFileError as e:
            refused = str(e)
        s.text("Written as a robot file, the slipped chain is refused by rmtkit's reader: "
               f"`{refused}`. The study builds it in memory (`dataclasses.replace` on the chain's joints) to "
               "evaluate it." if refused else "**The robot-file reader accepted the slipped chain.**")
        s.results["slipped_file_refused"] = refused

        rows, compared = [], []
        for label, q_file in CONFIGS:
            q = chain.to_si(q_file)
            T, Ts = robot.fk(q), slipped.fk(q)
            dp = float(np.linalg.norm(T[:3, 3] - Ts[:3, 3]))
            ang = float(rotation_angle_deg(T[:3, :3], Ts[:3, :3]))
            rows.append([label, *T[:3, 3], *Ts[:3, 3], dp, ang])
            compared.append({"label": label, "q": q_file, "T_correct": T.tolist(), "T_slipped": Ts.tolist(),
                             "position_difference_m": dp, "rotation_difference_deg": ang})
        s.table(["configuration", "x (m)", "y (m)", "z (m)", "x slipped (m)", "y slipped (m)", "z slipped (m)",
                 "|Δp| (m)", "rotation between (°)"], rows,
                "Tool position of the correct model and of the slipped one at the same joint values, the distance "
                "between them and the angle of the rotation that turns one tool orientation into the other.", fmt=".4g")
        for label, q_file in CONFIGS[:2]:
            T, Ts = robot.fk(chain.to_si(q_file)) + 0.0, slipped.fk(chain.to_si(q_file)) + 0.0   # no −0
            s.table(["row", "correct: r1", "r2", "r3", "p (m)", "slipped: r1", "r2", "r3", "p (m)"],
                    [[k + 1, *T[k], *Ts[k]] for k in range(3)],
                    f"The full tool pose at `{label}` (q = {q_file}): rotation columns r1–r3 and position p.",
                    fmt=".4f")
        # the same over many random configurations inside the limits
        Q = robot.random_configurations(n_compare, seed=seed)
        T, Ts = robot.fk(Q), slipped.fk(Q)
        dP = np.linalg.norm(T[:, :3, 3] - Ts[:, :3, 3], axis=1)
        dR = rotation_angle_deg(T[:, :3, :3], Ts[:, :3, :3])
        s.table(["quantity", "min", "median", "max"],
                [["|Δp| (m)", dP.min(), np.median(dP), dP.max()], ["rotation between (°)", dR.min(), np.median(dR),
                                                                     dR.max()]],
                f"Over {n_compare:,} random configurations inside the limits (seed {seed}).", fmt=".4g")
        s.results["slip"] = {"configurations": compared, "random": {
            "samples": n_compare, "seed": seed, "position_difference_m": [float(dP.min()), float(np.median(dP)),
                                                                          float(dP.max())],
            "rotation_difference_deg": [float(dR.min()), float(np.median(dR)), float(dR.max())]}}
        s.text(f"The orientation differs by the same {np.median(dR):.2f}° everywhere: the linear axes add a fixed "
               "rotation after joint 3, and the slip changes only that rotation. The position difference varies "
               "with the configuration, because the skewed linear axes and their offsets a4–a6 turn with the "
               "rotary axes.")
        s.finding(f"the slip moves the tool by {dP.min():.2f}–{dP.max():.2f} m (median {np.median(dP):.2f} m) and "
                  f"turns it by a constant {np.median(dR):.2f}° over {n_compare:,} configurations: the thesis's "
                  "printed matrices belong to another machine")

    with s.section("The singularity survives the slip"):
        analysis = sections.singular_set(s, robot)
        analysis_s = analyse_singularities(slipped, seed=seed)
        s.table(["#", "factor", "kind", "joints"],
                [[i, f"`{f.expr}` = 0", f.kind, ", ".join(f"q{j}" for j in f.joints)]
                 for i, f in enumerate(analysis_s.factors, 1)],
                f"Singular set of the slipped chain: {len(analysis_s.factors)} factor(s), {analysis_s.method} "
                f"analysis ({analysis_s.derivation}).")
        # det J / sin θ2 over random configurations: one constant per chain when sin θ2 is the whole story
        away = np.abs(np.sin(Q[:, 1])) > 1e-3
        det, det_s = robot.det(Q), slipped.det(Q)
        ratio, ratio_s = det[away] / np.sin(Q[away, 1]), det_s[away] / np.sin(Q[away, 1])
        # det J = −det Z · det W: Z the three linear axes (the prismatic columns' position rows), a constant
        # of the chain; W the three rotary axes (the revolute columns' rotation rows), where sin θ2 lives
        det_z = np.linalg.det(robot.jacobian(Q[:50])[:, :3, 3:])
        det_z_s = np.linalg.det(slipped.jacobian(Q[:50])[:, :3, 3:])
        s.table(["model", "factors", "det J / sin θ2: min", "det J / sin θ2: max", "det Z (linear axes)",
                 "sin(θ of joint 5)"],
                [["correct", ", ".join(f.expr for f in analysis.factors), ratio.min(), ratio.max(), det_z.mean(),
                  np.sin(chain.joints[4].theta)],
                 ["slipped", ", ".join(f.expr for f in analysis_s.factors), ratio_s.min(), ratio_s.max(),
                  det_z_s.mean(), np.sin(SLIP[5])]],
                f"det J divided by sin θ2 at {int(away.sum()):,} random configurations (|sin θ2| > 0.001): constant "
                "in both models. The constant is det Z, the determinant of the three linear axes, which works out "
                "to the sine of joint 5's fixed angle.", fmt=".6g")
        s.text("Why the singularity survives: the linear axes move the tool without turning it, so det J splits "
               "into the rotary block W (joints 1–3 only, det W ∝ sin θ2) and the linear block Z (the three axis "
               "directions, a constant of the machine). The slip changes only the fixed angles of joints 4–6, so it "
               f"changes det Z — from 1 (orthogonal axes) to sin(90 rad) = {np.sin(SLIP[5]):.4f} (skewed axes) — and "
               "leaves W, and with it the singularity θ2 = 0, untouched.")
        s.figure(det_across_q2({"correct": Q[:2000, 1], "slipped": Q[:2000, 1]},
                               {"correct": det[:2000], "slipped": det_s[:2000]},
                               {"correct": float(np.median(ratio)), "slipped": float(np.median(ratio_s))}),
                 "det_across_q2", "det J of both models against θ2 at random configurations: each falls on one "
                                  "sine curve through θ2 = 0.")
        same = ([f.expr for f in analysis.factors] == ["sin(q2)"] == [f.expr for f in analysis_s.factors])
        const = float(np.ptp(ratio)) < 1e-9 and float(np.ptp(ratio_s)) < 1e-9
        s.results["singularity"] = {
            "correct": {"factors": [f.expr for f in analysis.factors], "det_over_sin_q2": [float(ratio.min()),
                                                                                           float(ratio.max())],
                        "det_Z": float(det_z.mean())},
            "slipped": {"factors": [f.expr for f in analysis_s.factors], "kinds": [f.kind for f in analysis_s.factors],
                        "det_over_sin_q2": [float(ratio_s.min()), float(ratio_s.max())],
                        "det_Z": float(det_z_s.mean())},
            "samples": int(away.sum())}
        s.finding(f"the singularity θ2 = 0 survives the slip: both analyses find the one factor sin(q2), and "
                  f"det J = {np.median(ratio):.4g}·sin θ2 (correct) and {np.median(ratio_s):.4g}·sin θ2 (slipped) "
                  f"on {int(away.sum()):,} samples", ok=same and const)

    with s.section("Workspace"):
        ws = sections.workspace(s, robot, n_workspace, seed, title=f"{chain.title}: functional workspace",
                                q_view=chain.to_si(CONFIGS[3][1]))
        # the same Sobol seed and joint limits: the slipped model is sampled at exactly the same joint values
        ws_s = compute_workspace(slipped, n_samples=n_workspace, seed=seed)
        s.heading("The workspace the slipped model would report")
        s.figure(workspace_overlay({"correct": ws.positions, "slipped": ws_s.positions}), "workspace_slipped",
                 "Tool positions of the correct and the slipped model over the same joint samples (top and front "
                 "views; the crosses are the centroids), and how far apart the two tool positions of each sample "
                 "are.")
        shift = float(np.linalg.norm(ws.positions.mean(axis=0) - ws_s.positions.mean(axis=0)))
        rows = [[key, *w.positions.mean(axis=0), *(w.bbox_max - w.bbox_min), w.reach]
                for key, w in (("correct", ws), ("slipped", ws_s))]
        s.table(["model", "centroid x (m)", "centroid y (m)", "centroid z (m)", "extent x (m)", "extent y (m)",
                 "extent z (m)", "reach (m)"], rows,
                f"Both workspaces from the same {ws.n_samples:,} joint samples (seed {seed}); reach is the largest "
                "distance of a sample from the base origin.", fmt=".4g")
        s.text(f"As sets the two workspaces overlap largely: the centroid moves by {shift:.2f} m and the reach "
               f"changes from {ws.reach:.2f} m to {ws_s.reach:.2f} m. The damage is at the level of single "
               "configurations: the same joint values put the tool somewhere else (the histogram), so every "
               "position or program computed with the slipped model misses. (The volume estimates in the "
               "four-view figure come from voxel counts of a 6-joint sample and grow with the sample count; they "
               "are not compared here.)")
        s.results["workspace_slipped"] = ws_s.to_dict()
        s.results["workspace_shift_m"] = shift
        s.finding(f"the correct workspace reaches {ws.reach:.2f} m from the base; the slipped model's reaches "
                  f"{ws_s.reach:.2f} m and its centroid lies {shift:.2f} m away — the sets overlap, the tool "
                  "positions at given joint values do not")


# ---- figures (matplotlib's Figure API, no pyplot state) -------------------------------------------
#: the colour of each model in the figures
COLOURS = {"correct": "#4c6a8a", "slipped": "#ff7f0e"}


def det_across_q2(q2: dict[str, np.ndarray], det: dict[str, np.ndarray], coeff: dict[str, float]) -> Figure:
    """det J of each chain at random configurations against θ2 (rad), with the curve coeff·sin θ2."""
    fig = Figure(figsize=(9, 4.4), layout="constrained")
    ax = fig.add_subplot()
    ax.ticklabel_format(useOffset=False, style="plain")
    x = np.linspace(min(v.min() for v in q2.values()), max(v.max() for v in q2.values()), 400)
    for key in q2:
        ax.scatter(q2[key], det[key], s=6, color=COLOURS[key], alpha=0.35, lw=0,
                   label=f"{key}: det J at {len(q2[key]):,} random configurations")
        ax.plot(x, coeff[key] * np.sin(x), color=COLOURS[key], lw=1.4, ls="--",
                label=f"{key}: {coeff[key]:.4g} · sin θ2")
    ax.axhline(0, color="0.4", lw=0.8)
    ax.axvline(0, color="#d62728", lw=1.0, label="θ2 = 0 (the singularity)")
    ax.set_xlabel("θ2 (rad)")
    # det J = −det Z · det W: unit axis vectors only (prismatic linear rows, revolute angular rows)
    ax.set_ylabel("det J of the 6×6 Jacobian (dimensionless)")
    ax.set_title("det J against θ2: the other five joints change nothing")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8, loc="upper left")
    return fig


def workspace_overlay(P: dict[str, np.ndarray], max_points: int = 20_000, seed: int = 0) -> Figure:
    """Top (x–y) and front (x–z) views of the tool-position clouds (m) of both chains over the same
    joint samples, and the histogram of the distance between the two tool positions of each sample."""
    fig = Figure(figsize=(15, 5.2), layout="constrained")
    axes = fig.subplots(1, 3, width_ratios=[1, 1, 0.8])
    rng = np.random.default_rng(seed)
    n = min(len(C) for C in P.values())
    idx = np.sort(rng.choice(n, max_points, replace=False)) if n > max_points else np.arange(n)
    for (i, j, title), ax in zip(((0, 1, "top view (x–y)"), (0, 2, "front view (x–z)")), axes):
        for key, C in P.items():
            ax.scatter(C[idx, i], C[idx, j], s=1.5, color=COLOURS[key], alpha=0.2, lw=0)
            ax.scatter(*C.mean(axis=0)[[i, j]], s=90, marker="x", color=COLOURS[key], lw=2.5)
        ax.ticklabel_format(useOffset=False, style="plain")
        ax.set_aspect("equal", adjustable="datalim")
        ax.set_xlabel(f"{'xyz'[i]} (m)")
        ax.set_ylabel(f"{'xyz'[j]} (m)")
        ax.set_title(title)
        ax.grid(alpha=0.3)
    C1, C2 = P.values()
    d = np.linalg.norm(C1[:n] - C2[:n], axis=1)
    ax = axes[2]
    ax.hist(d, bins=60, color="0.45")
    ax.ticklabel_format(useOffset=False, style="plain")
    ax.set_xlabel("|p correct − p slipped| at the same joint values (m)")
    ax.set_ylabel("joint samples")
    ax.set_title("how far the slip moves the tool")
    ax.grid(alpha=0.3)
    handles = [Line2D([], [], ls="", marker="o", color=COLOURS[k], label=f"{k} model: tool positions") for k in P]
    handles += [Line2D([], [], ls="", marker="x", mew=2.5, color=COLOURS[k], label=f"{k} model: centroid") for k in P]
    fig.legend(handles=handles, loc="outside upper center", ncols=4, fontsize=9)
    return fig


if __name__ == "__main__":
    raise SystemExit(main(sys.modules[__name__]))

"""The controller thesis's configuration test (docs/machines.md §1) redone: chains of 1 to 5 revolute
joints with a = d = 0, θ = (90, 30, 90, 60, 180)° and α = (−90, 60, 90, 90, 0)°. For each chain the
report gives the correct rotation and position next to the same computation done the thesis's way:
degrees handed to sin and cos as radians, and the row sums of the rotation printed as the "position".
(The correct position is 0 in every case, since every a and d is zero.) The test never checked
joint limits: against the PUMA 560's, θ5 = 180° is out of range.

The thesis's printed tables are not reproduced verbatim: we have only the nature of their errors. The
"thesis's method" column is that method applied to the same inputs, not a quotation.

The second part enumerates the 2³ joint-type architectures (revolute or prismatic per joint) of the
PUMA's arm — its first three joints, the tool point at the wrist centre. It compares them by workspace
volume and by dexterity (the global conditioning index of the position Jacobian). Three of the eight
collapse to a planar workspace, because joints 2 and 3 of the PUMA have parallel axes.
"""
from __future__ import annotations

import math
import sys
from dataclasses import replace

import numpy as np
from matplotlib.figure import Figure

import kin
from design.architecture import all_architectures, with_joint_types
from design.workspace import compute_workspace, sample_joint_space
from studies.report.view3d import robot_view
from studies.study import Study, main, sections
from studies.study.rotations import rotation_angle_deg

NAME = "puma_configurations"
TITLE = "PUMA 560: the controller thesis's 1–5 joint configuration test, its joint limits and the 2³ architectures"

#: docs/machines.md §1: the correct rotation with all five joints (printed to three decimals)
REFERENCE_R5 = [[0.866, 0.0, -0.5], [-0.25, -0.866, -0.433], [-0.433, 0.5, -0.75]]
THESIS_LABEL = "the thesis's method (degrees read as radians, row sums as position)"


# ---- the thesis's test chain, the PUMA's arm and its dexterity -------------------------------------
#: the controller thesis's configuration test (docs/machines.md §1): a = d = 0 for every joint
TEST_THETA_DEG = (90.0, 30.0, 90.0, 60.0, 180.0)
TEST_ALPHA_DEG = (-90.0, 60.0, 90.0, 90.0, 0.0)


def test_chain(k: int, slipped: bool = False) -> tuple[kin.Robot, np.ndarray]:
    """The first ``k`` joints of the test chain and the joint values to evaluate it at (SI).

    Correct: α in radians, q = θ in radians.  ``slipped``: every angle handed over as its number of
    degrees read as radians — α = −90 rad …, and θ = 90 rad … (as fixed angles, q = 0, so that no
    joint-limit convention gets in the way)."""
    if not 1 <= k <= len(TEST_THETA_DEG):
        raise kin.ChainError(f"test chain: k = {k}; allowed 1 … {len(TEST_THETA_DEG)}")
    joints = []
    for i in range(k):
        alpha = TEST_ALPHA_DEG[i] if slipped else math.radians(TEST_ALPHA_DEG[i])
        theta = TEST_THETA_DEG[i] if slipped else 0.0
        joints.append(kin.chain.Joint("revolute", a=0.0, alpha=alpha, d=0.0, theta=theta, name=f"J{i + 1}"))
    name = f"thesis_test_{k}" + ("_slipped" if slipped else "")
    q = np.zeros(k) if slipped else np.radians(TEST_THETA_DEG[:k])
    return kin.Robot(kin.Chain(name=name, joints=tuple(joints), title=f"thesis test chain, {k} joint(s)")), q


def row_sums(T: np.ndarray) -> np.ndarray:
    """What the thesis printed as the position: the row sums of the rotation, R·(1, 1, 1)ᵀ (plus the
    true position, which is 0 here) — where the point (1, 1, 1) of the last frame lands."""
    return T[:3, :3].sum(axis=1) + T[:3, 3]


def skeleton(puma: kin.Robot) -> kin.Chain:
    """The PUMA's first three joints, with the forearm (joint 4's d = 433.07 mm along z3) as the tool
    offset: the tool point is the wrist centre."""
    c = puma.chain
    d4 = float(c.joints[3].d)
    return replace(c, name="puma560_arm", title="PUMA 560 arm (joints 1–3, tool point = wrist centre)",
                   joints=c.joints[:3], tool=kin.chain.Placement(xyz=(0.0, 0.0, d4)), geometry=None)


def dexterity(robot: kin.Robot, Q: np.ndarray, length: float) -> dict:
    """Dexterity of the position Jacobian (3 × 3) at configurations Q: revolute columns (m/rad)
    divided by the characteristic ``length`` (m) so that every column is m per m of joint travel —
    a 1 rad turn counts as ``length`` of stroke — then σ_min (dimensionless) and 1/κ = σ_min/σ_max.
    Returns the arrays and the global conditioning index GCI = mean 1/κ.  1/κ below 1e-12 (a Jacobian
    rank-deficient up to rounding) counts as 0."""
    J = robot.jacobian(Q)[:, :3, :].copy()
    J[:, :, robot.chain.revolute_mask] /= length
    sv = np.linalg.svd(J, compute_uv=False)
    inv_kappa = np.where(sv[:, 0] > 0, sv[:, -1] / np.where(sv[:, 0] > 0, sv[:, 0], 1.0), 0.0)
    inv_kappa[inv_kappa < 1e-12] = 0.0
    return {"sigma_min": sv[:, -1], "inverse_condition": inv_kappa, "gci": float(inv_kappa.mean())}


def cloud_sample(robot: kin.Robot, ws, length: float, k: int = 4000, seed: int = 0) -> tuple[np.ndarray, np.ndarray]:
    """``k`` of the workspace's positions and 1/κ there (the configurations are the same Sobol sequence
    :func:`design.workspace.compute_workspace` drew), for a side view coloured by dexterity."""
    Q = sample_joint_space(robot, ws.n_requested, ws.method, ws.seed)
    idx = np.sort(np.random.default_rng(seed).choice(len(Q), min(k, len(Q)), replace=False))
    P = robot.fk(Q[idx])[:, :3, 3]
    return P, dexterity(robot, Q[idx], length)["inverse_condition"]


def _vec(v) -> str:
    """(x, y, z) to four digits with true minus signs and no −0."""
    return ("(" + ", ".join(f"{round(float(x), 4) + 0.0:.4g}" for x in v) + ")").replace("-", "−")


def run(s: Study) -> None:
    puma = s.robot("puma560")
    seed = s.input("seed", 0)
    n_ws = s.input("architectures: workspace samples (Sobol)", 200_000 if s.quick else 1_600_000)
    voxel = s.input("architectures: voxel side (m)", 0.05)
    n_dex = s.input("architectures: dexterity samples (uniform random)", 5_000 if s.quick else 50_000)
    # the characteristic length that puts revolute (m/rad) and prismatic (m/m) columns on one scale:
    # the PUMA's upper arm a2 — a 1 rad turn of a joint counts like a stroke of a2
    L = s.input("architectures: characteristic length L (m) = a2", float(puma.chain.joints[1].a))
    # prismatic strokes: 0 … a2 from the joint's DH offset d, i.e. a linear axis as long as the PUMA's
    # longest link; the sensitivity section tries half and twice that
    stroke_factors = s.input("architectures: strokes compared (× a2)", [0.5, 1.0, 2.0])

    with s.section("The thesis's configuration test, 1 to 5 joints"):
        s.table(["joint", "a", "d", "α (°)", "θ (°)"],
                [[i + 1, 0, 0, TEST_ALPHA_DEG[i], TEST_THETA_DEG[i]] for i in range(5)],
                "The test chain (docs/machines.md §1): every a and d is zero, so every frame origin stays at the "
                "base origin and the tool position is (0, 0, 0) for any number of joints.", fmt=".4g")
        s.text(f"For k = 1 … 5 joints, the correct forward kinematics (angles in radians, as meant) is set beside "
               f"**{THESIS_LABEL}**: every angle, θ and α, is handed to sin and cos as its number of degrees "
               "read as radians, and the \"position\" is the rotation's row sums. The row sums are R·(1, 1, 1)ᵀ, "
               "the image of the point (1, 1, 1) of the last frame, **not** a position: the frame origin is "
               "(0, 0, 0) throughout. We do not have the thesis's printed tables verbatim (only the nature of its "
               "errors, including one wrong matrix entry that cannot be reconstructed), so that column is the "
               "method re-run, not a quotation.")
        rows, table = [], []
        for k in range(1, 6):
            robot, q = test_chain(k)
            slipped, q_s = test_chain(k, slipped=True)
            T, Ts = robot.fk(q) + 0.0, slipped.fk(q_s) + 0.0
            r = {"k": k, "R_correct": T[:3, :3].tolist(), "position_correct": T[:3, 3].tolist(),
                 "row_sums_correct": row_sums(T).tolist(), "R_thesis": Ts[:3, :3].tolist(),
                 "position_thesis": row_sums(Ts).tolist(),
                 "angle_deg": float(rotation_angle_deg(T[:3, :3], Ts[:3, :3]))}
            rows.append(r)
            for i in range(3):
                table.append([k if i == 0 else "", i + 1, *T[i, :3], T[i, 3], *Ts[i, :3], r["position_thesis"][i]])
        s.table(["joints", "row", "R: col 1", "col 2", "col 3", "p (correct)", "R thesis's method: col 1", "col 2",
                 "col 3", "\"p\" thesis's method = row sum"], table,
                "Rotation R (rows 1–3, columns 1–3) and position p of the last frame for k = 1 … 5 joints: correct, "
                "and by the thesis's method (degrees read as radians; the row sums printed as the position).",
                fmt=".4f")
        s.table(["joints", "rotation between correct and thesis's method (°)", "correct position",
                 "thesis's \"position\" (row sums)", "row sums of the correct rotation"],
                [[r["k"], r["angle_deg"], _vec(r["position_correct"]), _vec(r["position_thesis"]),
                  _vec(r["row_sums_correct"])] for r in rows],
                "How far apart the two results are: the angle of the rotation that turns one into the other, and "
                "the positions. Even without the slip, the row sums (last column) are not a position.", fmt=".4g")
        s.figure(frames_figure(rows), "frames",
                 "The last frame for k = 1 … 5 joints: correct axes (solid), the thesis's method (dashed), the true "
                 "origin (dot) and the thesis's \"position\" (cross, the row sums).")
        R5 = np.array(rows[-1]["R_correct"])
        dev = float(np.abs(R5 - np.array(REFERENCE_R5)).max())
        s.results["configurations"] = rows
        s.results["reference_R5_deviation"] = dev
        s.finding(f"with all five joints the correct rotation is rows {', '.join(_vec(x) for x in R5)} — "
                  f"docs/machines.md §1 to within {dev:.1g} (printed to three decimals); "
                  "the position is (0, 0, 0)", ok=dev < 5e-4)
        s.finding(f"the thesis's method (degrees read as radians) gives rotations "
                  f"{min(r['angle_deg'] for r in rows):.0f}°–{max(r['angle_deg'] for r in rows):.0f}° "
                  "away from the correct ones for k = 1 … 5, and its \"position\" "
                  f"is the row sums R·(1, 1, 1)ᵀ — e.g. {_vec(rows[-1]['position_thesis'])} for five joints where the "
                  "true position is (0, 0, 0)")

    with s.section("The joint-limit check the thesis skipped"):
        q_deg = [*TEST_THETA_DEG, 0.0]                    # the PUMA has six joints: joint 6 at 0
        q = puma.chain.to_si(q_deg)
        bad = {i: v for i, v, _ in puma.chain.limit_violations(q)}
        lim_rows = [[f"J{i}", q_deg[i - 1], f"{j.limits[0] / puma.chain.angle_scale:g} … "
                     f"{j.limits[1] / puma.chain.angle_scale:g}".replace("-", "−"), "**no**" if i in bad else "yes"]
                    for i, j in enumerate(puma.chain.joints, 1)]
        s.table(["joint", "test value (°)", "PUMA 560 range (°)", "within"], lim_rows,
                "The test's joint values against the PUMA 560's ranges (docs/machines.md §1; joint 6, which the test "
                "does not have, at 0). The test chain's α are not the PUMA's; the ranges are the arm's the "
                "controller was written for.", fmt=".4g")
        try:
            puma.check_limits(q)
            message = None
        except kin.JointLimitError as e:
            message = str(e)
        s.code(message or "(no violation)", "`puma.check_limits(q)` — rmtkit's limit check on the test configuration")
        s.results["limit_check"] = {"q_deg": q_deg, "violations": [{"joint": i, "value_deg": math.degrees(v)}
                                                                   for i, v in bad.items()], "message": message}
        lo5, hi5 = (float(x) / puma.chain.angle_scale for x in puma.chain.joints[4].limits)
        range5 = f"{lo5:g}…{hi5:g}°".replace("-", "−")
        s.finding(f"the joint-limit check the thesis skipped: θ5 = {q_deg[4]:g}° is outside the PUMA 560's range "
                  f"{range5} — the test configuration cannot be reached by the arm; every other joint is within its "
                  "range",
                  ok=sorted(bad) == [5] and message is not None)

    with s.section("The 2³ joint-type architectures of the PUMA's arm"):
        arm = skeleton(puma)
        s.text("The skeleton is the PUMA's first three joints with the forearm (d4 = 433.07 mm along z3) as a fixed "
               "tool offset, so the tool point is the wrist centre — where the arm puts the wrist. Each joint may "
               "be revolute (R) or prismatic (P): a joint made prismatic keeps its α, a and fixed θ, and slides "
               f"along its axis from its DH offset d over a stroke of 0 … {L:g} m — as long as the upper arm a2, the "
               "PUMA's longest link. A revolute joint keeps the PUMA's range. Volumes count occupied voxels of "
               f"side {voxel:g} m over {n_ws:,} Sobol samples (seed {seed}); dexterity is measured on the position "
               f"Jacobian with revolute columns divided by L = a2 = {L:g} m (a 1 rad turn counts like a stroke of "
               f"L), over {n_dex:,} uniform random configurations: σ_min and 1/κ = σ_min/σ_max, and their mean, "
               "the global conditioning index GCI (1 = isotropic everywhere, 0 = singular everywhere).")
        sections.dh_table(s, kin.Robot(arm), "DH parameters of the skeleton (mm, degrees); tool offset 433.07 mm "
                                             "along z3.")
        archs = all_architectures(3)
        arch_rows, table, clouds = [], [], {}
        for a in archs:
            robot = kin.Robot(with_joint_types(arm, a, stroke=(0.0, L)))
            ws = compute_workspace(robot, n_samples=n_ws, seed=seed, voxel=voxel)
            dex = dexterity(robot, robot.random_configurations(n_dex, seed=seed), L)
            planar = ws.dimension < 3
            r = {"architecture": a, "dimension": ws.dimension, "volume_m3": ws.volume,
                 "area_m2": ws.area if planar else None, "reach_m": ws.reach, "gci": dex["gci"],
                 "median_inverse_condition": float(np.median(dex["inverse_condition"])),
                 "median_sigma_min": float(np.median(dex["sigma_min"])),
                 "singular_share": float(np.mean(dex["inverse_condition"] < 1e-9)),
                 "stroke_m": [0.0, L], "samples": ws.n_samples, "voxel_m": ws.voxel}
            arch_rows.append(r)
            table.append([a, ws.dimension, ws.volume, r["area_m2"], ws.reach, r["gci"], r["median_inverse_condition"],
                          r["median_sigma_min"], 100 * r["singular_share"]])
            clouds[a] = cloud_sample(robot, ws, L, seed=seed)
        s.table(["architecture", "dimension", "volume (m³)", "area if planar (m²)", "reach (m)", "GCI (–)",
                 "median 1/κ (–)", "median σ_min (–)", "singular samples (%)"], table,
                "Each architecture's wrist-centre workspace and dexterity. RRR is the PUMA's own arm.", fmt=".3g")
        planar = [r["architecture"] for r in arch_rows if r["dimension"] < 3]
        s.text(f"Planar: {', '.join(planar)}. Joints 2 and 3 of the PUMA have parallel axes (α2 = 0): two prismatic "
               "joints there slide along the same direction, and a prismatic joint 1 slides along the base axis, "
               "which lies in the plane joints 2 and 3 turn in — either way one direction of motion is lost "
               "everywhere (σ_min = 0 at every sample), and the workspace is a surface.")
        s.figure(architecture_figure(arch_rows), "architectures",
                 "Workspace volume against dexterity (GCI) for the eight architectures.")
        s.figure(clouds_figure(clouds, seed=seed), "architecture_workspaces",
                 "Each architecture's wrist-centre workspace, coloured by 1/κ, seen along the base axis in which it "
                 "is widest (a planar workspace face on).")
        # the PUMA's own arm in 3-D with its wrist-centre cloud; near-singular: 1/κ below 5 % of its median
        P, ik = clouds["RRR"]
        near = ik < 0.05 * float(np.median(ik))
        s.view3d(robot_view(kin.Robot(arm), np.radians([30.0, -60.0, 120.0]), cloud=P, near_singular=near,
                            title="PUMA 560 arm (RRR): wrist-centre workspace"), "arm_workspace_3d",
                 f"The PUMA's arm (joints 1–3, tool point at the wrist centre) at q = (30°, −60°, 120°) and "
                 f"{len(P):,} points of its workspace, in red the {int(near.sum())} where 1/κ is below 5 % of its "
                 "median (near-singular).")
        s.results["architectures"] = arch_rows
        solid = [r for r in arch_rows if r["dimension"] == 3]
        big = max(solid, key=lambda r: r["volume_m3"])
        dex_best = max(solid, key=lambda r: r["gci"])
        s.finding(f"of the 2³ = {len(archs)} architectures, {len(planar)} ({', '.join(planar)}) have a planar "
                  f"workspace (joints 2 and 3 have parallel axes); {big['architecture']} has the largest volume "
                  f"({big['volume_m3']:.2f} m³) and {dex_best['architecture']} the best dexterity (GCI "
                  f"{dex_best['gci']:.2f}, volume {dex_best['volume_m3']:.2f} m³) with strokes of {L:g} m")

        s.heading("How the prismatic stroke changes the ranking")
        sweep, sweep_rows = [], []
        for f in stroke_factors:
            for a in archs:
                if a == "RRR" or a in planar:
                    continue                    # no prismatic joint, or planar at any stroke
                robot = kin.Robot(with_joint_types(arm, a, stroke=(0.0, f * L)))
                ws = compute_workspace(robot, n_samples=n_ws, seed=seed, voxel=voxel)
                gci = dexterity(robot, robot.random_configurations(n_dex, seed=seed), L)["gci"]
                sweep.append({"stroke_factor": f, "stroke_m": f * L, "architecture": a, "volume_m3": ws.volume,
                              "gci": gci})
        rrr = next(r for r in arch_rows if r["architecture"] == "RRR")
        for f in stroke_factors:
            part = sorted((x for x in sweep if x["stroke_factor"] == f), key=lambda x: -x["volume_m3"])
            sweep_rows.append([f"{f:g} × a2 = {f * L:.3g} m", ", ".join(f"{x['architecture']} {x['volume_m3']:.2f}"
                                                                       for x in part),
                               ", ".join(f"{x['architecture']} {x['gci']:.2f}"
                                         for x in sorted(part, key=lambda x: -x["gci"])),
                               sum(x["volume_m3"] > rrr["volume_m3"] for x in part)])
        s.table(["stroke", "volume (m³), largest first", "GCI, best first",
                 f"architectures above RRR's {rrr['volume_m3']:.2f} m³"],
                sweep_rows, "The non-planar architectures with a prismatic joint at three strokes (the revolute "
                            "joints keep the PUMA's ranges; RRR does not depend on the stroke).", fmt=".3g")
        s.results["stroke_sweep"] = sweep
        orders = {key: {tuple(x["architecture"] for x in sorted((x for x in sweep if x["stroke_factor"] == f),
                                                                 key=lambda x: -x[key])) for f in stroke_factors}
                  for key in ("volume_m3", "gci")}
        s.results["stroke_ranking_stable"] = {"volume": len(orders["volume_m3"]) == 1, "gci": len(orders["gci"]) == 1}
        s.text("Volumes grow with the stroke, so a ranking by volume ranks the strokes chosen as much as the joint "
               "types: " + ("here the volume order changes with the stroke" if len(orders["volume_m3"]) > 1 else
                            "here the volume order happens to hold at every stroke tried")
               + ", and the dexterity order " + ("holds at every stroke" if len(orders["gci"]) == 1 else
                                                 "changes too")
               + ". State the stroke with any comparison of architectures.")


# ---- figures (matplotlib's Figure API, no pyplot state) -------------------------------------------
_AXIS_COLOURS = ("#d62728", "#2ca02c", "#1f77b4")


def frames_figure(rows: list[dict]) -> Figure:
    """One 3-D panel per k: the last frame's unit axes (dimensionless), correct (solid) and as the thesis
    evaluated it (dashed), the true origin (0, 0, 0) and the thesis's "position" (row sums, black cross)."""
    fig = Figure(figsize=(3.6 * len(rows), 4.6), layout="constrained")
    for i, r in enumerate(rows, 1):
        ax = fig.add_subplot(1, len(rows), i, projection="3d")
        Rc, Rs, rs = np.array(r["R_correct"]), np.array(r["R_thesis"]), np.array(r["position_thesis"])
        for j, name in enumerate("xyz"):
            ax.plot([0, Rc[0, j]], [0, Rc[1, j]], [0, Rc[2, j]], color=_AXIS_COLOURS[j], lw=2.2,
                    label=f"{name} axis, correct" if i == 1 else None)
            ax.plot([0, Rs[0, j]], [0, Rs[1, j]], [0, Rs[2, j]], color=_AXIS_COLOURS[j], lw=1.2, ls="--",
                    label=f"{name} axis, thesis's method" if i == 1 else None)
        ax.scatter([0], [0], [0], color="k", s=18, label="true origin (0, 0, 0)" if i == 1 else None)
        ax.scatter([rs[0]], [rs[1]], [rs[2]], color="k", marker="x", s=40,
                   label="thesis's \"position\" (row sums)" if i == 1 else None)
        lim = max(1.0, float(np.abs(rs).max()))
        for setter in (ax.set_xlim, ax.set_ylim, ax.set_zlim):
            setter(-lim, lim)
        ax.set_box_aspect(None, zoom=0.82)          # room for the z label
        ax.set_xlabel("x (–)")
        ax.set_ylabel("y (–)")
        ax.set_zlabel("z (–)")
        ax.set_title(f"{r['k']} joint(s): {r['angle_deg']:.0f}° apart", fontsize=9)
    fig.legend(loc="lower center", ncol=4, fontsize=8)
    fig.get_layout_engine().set(rect=(0, 0.12, 1, 0.88))
    return fig


def architecture_figure(rows: list[dict]) -> Figure:
    """Workspace volume against dexterity (GCI), one labelled point per architecture; architectures
    whose workspace is planar (volume 0) are drawn on the axis with their area noted."""
    fig = Figure(figsize=(8.5, 5.5), layout="constrained")
    ax = fig.subplots()
    stacked = 0
    for r in rows:
        planar = r["dimension"] < 3
        colour = "#888888" if planar else ("#d62728" if r["architecture"] == "RRR" else "#1f77b4")
        ax.plot(r["gci"], r["volume_m3"], "s" if planar else "o", color=colour, ms=9,
                mfc="none" if planar else colour)
        note = f" (planar: {r['area_m2']:.2f} m²)" if planar else ""
        ax.annotate(r["architecture"] + note, (r["gci"], r["volume_m3"]), textcoords="offset points",
                    xytext=(7, 5 if not planar else 5 + 12 * stacked), fontsize=9)
        stacked += planar
    ax.plot([], [], "o", color="#d62728", label="RRR: the PUMA's own arm")
    ax.plot([], [], "o", color="#1f77b4", label="other architectures")
    ax.plot([], [], "s", color="#888888", mfc="none", label="planar workspace (volume 0, GCI 0)")
    ax.set_xlabel("dexterity: GCI = mean σ_min/σ_max of the scaled position Jacobian (–)")
    ax.set_ylabel("workspace volume of the wrist centre (m³)")
    ax.ticklabel_format(useOffset=False, style="plain")
    ax.set_xlim(-0.03, max(0.6, max(r["gci"] for r in rows) + 0.12))
    ax.set_ylim(-0.15, 1.15 * max(r["volume_m3"] for r in rows) + 0.1)
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=8, loc="upper right")
    ax.set_title("The 2³ joint-type architectures of the PUMA's arm (wrist-centre workspace)", fontsize=10)
    return fig


def clouds_figure(clouds: dict[str, tuple[np.ndarray, np.ndarray]], max_points: int = 4000, seed: int = 0) -> Figure:
    """Every architecture's wrist-centre cloud (m) coloured by 1/κ, one panel each, seen along the base
    axis (x, y, z) in which its projection is largest — a planar workspace face on."""
    names = list(clouds)
    cols = 4
    rows = math.ceil(len(names) / cols)
    fig = Figure(figsize=(3.4 * cols, 3.4 * rows), layout="constrained")
    axes = fig.subplots(rows, cols, squeeze=False)
    rng = np.random.default_rng(seed)
    lim = 1.05 * max(float(np.abs(P).max()) for P, _ in clouds.values())
    views = [((0, 2), "side view, x–z"), ((0, 1), "top view, x–y"), ((1, 2), "side view, y–z")]
    sc = None
    for ax, name in zip(axes.flat, names):
        P, ik = clouds[name]
        ext = P.max(axis=0) - P.min(axis=0)
        (i, j), view = max(views, key=lambda v: ext[v[0][0]] * ext[v[0][1]])
        idx = np.sort(rng.choice(len(P), min(max_points, len(P)), replace=False))
        sc = ax.scatter(P[idx, i], P[idx, j], c=ik[idx], s=1.5, cmap="viridis", vmin=0.0, vmax=1.0, rasterized=True)
        ax.set_title(f"{name} ({view})", fontsize=9)
        ax.set_xlim(-lim, lim)
        ax.set_ylim(-lim, lim)
        ax.set_aspect("equal")
        ax.set_xlabel(f"{'xyz'[i]} (m)")
        ax.set_ylabel(f"{'xyz'[j]} (m)")
        ax.grid(True, alpha=0.3)
    for ax in list(axes.flat)[len(names):]:
        ax.remove()
    if sc is not None:
        fig.colorbar(sc, ax=axes, shrink=0.8, label="1/κ of the scaled position Jacobian (–)")
    return fig


if __name__ == "__main__":
    raise SystemExit(main(sys.modules[__name__]))

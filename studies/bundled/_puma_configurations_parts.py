"""Pieces of the puma_configurations study: the thesis's 1–5 joint test chain (correct, and as the thesis
evaluated it), the 3-joint PUMA skeleton for the joint-type architectures, their dexterity, and the
figures (matplotlib Figure API, no pyplot state)."""
from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
from matplotlib.figure import Figure

import kin

__all__ = ["TEST_THETA_DEG", "TEST_ALPHA_DEG", "test_chain", "row_sums", "rotation_angle_deg", "skeleton",
           "dexterity", "cloud_sample", "frames_figure", "architecture_figure", "clouds_figure"]

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


def rotation_angle_deg(Ra: np.ndarray, Rb: np.ndarray) -> float:
    """Angle of the rotation that turns Ra into Rb (degrees)."""
    c = (np.trace(Ra.T @ Rb) - 1.0) / 2.0
    return math.degrees(math.acos(float(np.clip(c, -1.0, 1.0))))


def skeleton(puma: kin.Robot) -> kin.Chain:
    """The PUMA's first three joints, with the forearm (joint 4's d = 433.07 mm along z3) as the tool
    offset: the tool point is the wrist centre."""
    c = puma.chain
    d4 = float(c.joints[3].d)
    return replace(c, name="puma560_arm", title="PUMA 560 arm (joints 1–3, tool point = wrist centre)",
                   joints=c.joints[:3], tool=kin.chain.Placement(xyz=(0.0, 0.0, d4)))


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
    from design.workspace import sample_joint_space
    Q = sample_joint_space(robot, ws.n_requested, ws.method, ws.seed)
    idx = np.sort(np.random.default_rng(seed).choice(len(Q), min(k, len(Q)), replace=False))
    P = robot.fk(Q[idx])[:, :3, 3]
    return P, dexterity(robot, Q[idx], length)["inverse_condition"]


# ---- figures --------------------------------------------------------------------------------------
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

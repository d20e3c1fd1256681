"""The FANUC M-16iB/20 chapter of the singularities thesis (its Table 16; docs/machines.md §3), redone:
the arm has three singular factors — wrist, elbow and shoulder — where the thesis reported only the
wrist; each gets an error window from a fixed margin, from a dexterity requirement (σ_min) and from
the thesis's own learned-IK method, side by side; a move whose straight joint-space line enters a
window is planned around it and proven clear; and an L-shaped weld seam on a table in front of the
robot is checked waypoint by waypoint.

Run it with ``rmt study`` (or ``make run``), ``rmt study fanuc_singularities --quick`` for the reduced
version, or ``python studies/bundled/fanuc_singularities.py --out DIR``.  Every number in the report
is in SI units (m, rad, s): the robot file is in metres and radians.  Copy this file to change the
margin, the dexterity requirement, the move or the seam.
"""
from __future__ import annotations

import math
import sys
import tempfile
from pathlib import Path

import numpy as np

from design.learned.runs import LearnedRuns
from design.learned.windows import jsonable_report, learned_windows
from planning.errors import PlanningError
from planning.toolpath import load_toolpath, validate_toolpath
from planning.windows import build_windows
from studies.plots.plan import plot_plan
from studies.plots.toolpath import plot_toolpath_report
from studies.plots.windows import plot_sigma_across_windows
from studies.report.view3d import robot_view
from studies.study import Study, main, sections
from studies.study.toolpath import toolpath_json
from studies.toolpaths import TOOLPATH_DIR

NAME = "fanuc_singularities"
TITLE = "FANUC M-16iB/20: singularities, error windows, a certified plan and a weld seam"

#: the DH table of docs/machines.md §3, rows (a, α, d) in m and rad — typed in from the document,
#: not read from the robot file, so that the numpy FK below checks the file as well as the code
DH_DOCS = [(0.150, -math.pi / 2, 0.525), (0.770, 0.0, 0.0), (0.100, math.pi / 2, 0.0),
           (0.0, -math.pi / 2, 0.740), (0.0, math.pi / 2, 0.0), (0.0, 0.0, 0.100)]
#: docs/machines.md §3: at q = 0 the tool is at (1.02, 0, 1.365) m with rotation I
Q_ZERO_POSITION = [1.02, 0.0, 1.365]
#: configurations for the forward-kinematics table (rad)
CONFIGURATIONS = [("q = 0 (wrist singular: q5 = 0)", [0.0, 0.0, 0.0, 0.0, 0.0, 0.0]),
                  ("ready", [0.0, 0.3, -0.4, 0.0, -0.9, 0.0]),
                  ("reach left", [1.2, 0.6, 0.2, 0.5, 0.7, -0.3]),
                  ("near the elbow singularity", [0.0, 0.5, 1.40, 0.0, 0.8, 0.0]),
                  ("random", [-0.7, -0.2, 1.1, -1.3, 1.5, 2.0])]
#: the move of studies/default_study.toml: its straight joint-space line dips into the shoulder window
PLAN_START = [0.0, -0.8, 0.7, 0.3, 0.8, 0.0]
PLAN_GOAL = [0.5, -0.5, -1.6, -0.3, 0.9, 0.4]
#: the weld seam, and the arm's configuration at its first point (upper arm raised, forearm reaching
#: down to the table, q5 > 0): validate_toolpath solves the first waypoint from here
SEAM_FILE = TOOLPATH_DIR / "fanuc_weld_seam.toml"
SEAM_START = [-0.26, -0.8, 3.24, 0.36, 0.8, 2.62]


# ---- an independent DH product: plain numpy, written from the DH table of docs/machines.md §3 -----
def dh_frames(dh: list[tuple[float, float, float]], q) -> list[np.ndarray]:
    """Frames 0…n (4×4 each) of an all-revolute standard-DH chain: rows (a, α, d), joint i adds
    A_i = Rz(q_i)·Tz(d_i)·Tx(a_i)·Rx(α_i)."""
    T = np.eye(4)
    frames = [T]
    for (a, alpha, d), th in zip(dh, np.asarray(q, float)):
        ct, st, ca, sa = np.cos(th), np.sin(th), np.cos(alpha), np.sin(alpha)
        A = np.array([[ct, -st * ca, st * sa, a * ct],
                      [st, ct * ca, -ct * sa, a * st],
                      [0.0, sa, ca, d],
                      [0.0, 0.0, 0.0, 1.0]])
        T = T @ A
        frames.append(T)
    return frames


def dh_jacobian(dh: list[tuple[float, float, float]], q, point=None) -> np.ndarray:
    """Geometric Jacobian (6×n, rows vx vy vz wx wy wz) of the point ``point`` (default: the tool
    origin) fixed to the last link; column i = (z_{i−1} × (p − o_{i−1}), z_{i−1})."""
    F = dh_frames(dh, q)
    p = F[-1][:3, 3] if point is None else np.asarray(point, float)
    cols = [np.concatenate([np.cross(T[:3, 2], p - T[:3, 3]), T[:3, 2]]) for T in F[:-1]]
    return np.stack(cols, axis=1)


def run(s: Study) -> None:
    robot = s.robot("fanuc_m16ib20")
    seed = s.input("seed", 0)
    n_random = s.input("FK and det checks: random configurations", 500 if s.quick else 5_000)
    margin = s.input("margin window: half-width (rad)", 0.05)
    # the dexterity requirement behind the σ_min windows: a tool twist of norm V_TOOL (SI: m/s and
    # rad/s together) with a joint-speed norm of at most QDOT_MAX needs σ_min ≥ V_TOOL / QDOT_MAX
    v_tool = s.input("σ_min windows: tool twist (m/s, rad/s)", 0.1)
    qdot_max = s.input("σ_min windows: joint-speed budget (rad/s)", 5.0)
    threshold = v_tool / qdot_max
    n_train = s.input("learned windows: training poses", 10_000 if s.quick else 40_000)
    # the learned width's dependence on training: training sizes × seeds (the run above is one of them)
    train_sizes = s.input("learned windows: training sizes compared", [5_000, 10_000] if s.quick else
                          [5_000, 20_000, 40_000, 80_000])
    train_seeds = s.input("learned windows: seeds compared", [0] if s.quick else [0, 1])
    n_sigma_check = s.input("σ_min window check: random configurations", 20_000 if s.quick else 200_000)
    n_workspace = 20_000 if s.quick else 200_000        # workspace samples (sections.workspace records them)
    plan_time = 1.0 if s.quick else 2.0                  # OMPL's time limit, s (sections.planned_path records it)

    # ------------------------------------------------------------------------------------------
    with s.section("The robot"):
        s.text("Six revolute joints: a base rotation (J1), shoulder and elbow pitch (J2, J3) with a 100 mm "
               "elbow offset, and a spherical wrist (J4–J6) whose axes meet at the wrist centre, 740 mm along "
               "the forearm. The tool point is the flange centre, 100 mm beyond the wrist centre. In these "
               "frames q = 0 has the upper arm horizontal and the forearm vertical.")
        sections.dh_table(s, robot)
        sections.configurations_table(s, robot, CONFIGURATIONS, expected={CONFIGURATIONS[0][0]: Q_ZERO_POSITION},
                                      tol=1e-9)
        # an independent check: a plain numpy DH product from docs/machines.md's table, against
        # rmtkit's compiled FK and Jacobian, at the listed and at random configurations
        Q = np.concatenate([np.array([q for _, q in CONFIGURATIONS]),
                            robot.random_configurations(n_random, seed=seed)])
        T, J = robot.fk_jacobian(Q)
        T_np = np.array([dh_frames(DH_DOCS, q)[-1] for q in Q])
        J_np = np.array([dh_jacobian(DH_DOCS, q) for q in Q])
        dp = np.linalg.norm(T[:, :3, 3] - T_np[:, :3, 3], axis=1)
        dR = np.abs(T[:, :3, :3] - T_np[:, :3, :3]).max(axis=(1, 2))
        dJ = np.abs(J - J_np).max(axis=(1, 2))
        R0_dev = float(np.abs(T[0, :3, :3] - np.eye(3)).max())
        p0_dev = float(np.linalg.norm(T[0, :3, 3] - Q_ZERO_POSITION))
        rows = [[label, dp[i], dR[i], dJ[i]] for i, (label, _) in enumerate(CONFIGURATIONS)]
        rows.append([f"{n_random:,} random configurations (seed {seed}): largest", dp.max(), dR.max(), dJ.max()])
        s.table(["configuration", "|p − p_numpy| (m)", "max |R − R_numpy|", "max |J − J_numpy| (SI)"], rows,
                "rmtkit's compiled forward kinematics and Jacobian against a plain numpy DH product written from "
                "the table of docs/machines.md §3 (`dh_frames` and `dh_jacobian` in this study's script).", fmt=".3g")
        s.results["fk_check"] = {"q_zero": {"position": T[0, :3, 3].tolist(), "reference": Q_ZERO_POSITION,
                                            "position_deviation": p0_dev, "rotation_deviation_from_identity": R0_dev},
                                 "numpy_dh": {"configurations": int(len(Q)), "max_position_deviation": float(dp.max()),
                                              "max_rotation_deviation": float(dR.max()),
                                              "max_jacobian_deviation": float(dJ.max())}}
        fk_ok = p0_dev <= 1e-9 and R0_dev <= 1e-9 and max(dp.max(), dR.max(), dJ.max()) <= 1e-9
        s.finding(f"FK at q = 0 gives ({T[0, 0, 3]:.4g}, {T[0, 1, 3]:.4g}, {T[0, 2, 3]:.4g}) m with R = I, as "
                  f"docs/machines.md §3 states (deviation {p0_dev:.1g} m); FK and Jacobian agree with a numpy DH "
                  f"product at {len(Q):,} configurations to {max(dp.max(), dR.max(), dJ.max()):.1g}", ok=fk_ok)

    # ------------------------------------------------------------------------------------------
    with s.section("The singular set"):
        analysis = sections.singular_set(s, robot)
        factors = analysis.factors
        kinds = [f.kind for f in factors]
        # det J divided by the product of the factors is a constant (−a2 = −0.77 m): nothing is missing
        Qr = robot.random_configurations(n_random, seed=seed + 1)
        prod = np.prod([f(Qr) for f in factors], axis=0)
        away = np.abs(prod) > 1e-3                     # the quotient is ill-conditioned on the singular set
        ratio = robot.det(Qr)[away] / prod[away]
        # the thesis's split: the Jacobian of the flange and of the wrist centre have the same determinant
        # (numpy, from the DH table); at the wrist centre the wrist joints do not move the point, so the
        # upper-right 3×3 block is zero and det J = det J11 · det J22
        Qs = Qr[:200]
        det_f, det_w, block = [], [], []
        for q in Qs:
            wc = dh_frames(DH_DOCS, q)[4][:3, 3]       # frame 4's origin: where the wrist axes meet
            Jf, Jw = dh_jacobian(DH_DOCS, q), dh_jacobian(DH_DOCS, q, point=wc)
            det_f.append(np.linalg.det(Jf))
            det_w.append(np.linalg.det(Jw))
            block.append(np.abs(Jw[:3, 3:]).max())
        det_f, det_w = np.array(det_f), np.array(det_w)
        s.table(["check", "configurations", "value"],
                [["det J / (product of the three factors): min (m)", int(away.sum()), float(ratio.min())],
                 ["det J / (product of the three factors): max (m)", int(away.sum()), float(ratio.max())],
                 ["max |det J(flange) − det J(wrist centre)| (numpy)", len(Qs), float(np.abs(det_f - det_w).max())],
                 ["max |upper-right 3×3 block of J(wrist centre)| (numpy)", len(Qs), float(max(block))]],
                "The three factors are the whole singular set: det J divided by their product is the constant "
                "−a2 = −0.77 m. Moving the Jacobian's reference point from the flange to the wrist centre leaves "
                "det J unchanged and makes J block-triangular.", fmt=".6g")
        s.results["det_check"] = {"configurations": int(away.sum()), "det_over_factors": [float(ratio.min()),
                                                                                        float(ratio.max())],
                                  "reference_point_difference": float(np.abs(det_f - det_w).max()),
                                  "wrist_centre_upper_right_block": float(max(block))}
        s.text("**The thesis found only the wrist singularity** (q5 = 0). It put the blame on splitting the "
               "Jacobian at the flange, but the determinant of a square Jacobian does not depend on the reference "
               "point (the table above shows it numerically), so that was not the cause. What the split at the "
               "wrist centre gives is a block-triangular Jacobian, whose determinant is det J11 · det J22 and "
               "factors easily: J22 gives the wrist factor sin q5; J11, the arm's 3×3 block, gives the elbow factor "
               "a3 sin q3 − d4 cos q3 (the forearm in line with the upper arm: q3 = atan(d4/a3) = 1.4365 rad, "
               "stretched, and 1.4365 ± π rad, folded back) and the shoulder factor "
               "a1 + a2 cos q2 + a3 cos(q2+q3) + d4 sin(q2+q3) (the wrist centre "
               "on the axis of joint 1, or on the 150 mm offset surface around it).")
        ok_kinds = sorted(kinds) == ["elbow", "shoulder", "wrist"]
        ok_ratio = float(np.ptp(ratio)) <= 1e-6 and abs(float(np.median(ratio)) + DH_DOCS[1][0]) <= 1e-6
        ratio_text = f"{float(np.median(ratio)):.4g}".replace("-", "−")
        s.finding(f"{len(factors)} singular factors ({', '.join(kinds)}); the thesis found 1 (the wrist); det J = "
                  f"{ratio_text} m × their product at {int(away.sum()):,} random configurations",
                  ok=ok_kinds and ok_ratio)

    # ------------------------------------------------------------------------------------------
    with s.section("Error windows"):
        s.text(f"A window is a band of joint space around a singular factor that plans stay out of. Three ways to "
               f"choose its half-width: a **fixed margin** of {margin:g} rad; a **dexterity requirement** — σ_min of "
               f"the Jacobian (SI rows: m/s and rad/s per rad/s) at least {threshold:g} outside every window, so that "
               f"any tool twist of norm {v_tool:g} (m/s and rad/s together) needs a joint-speed norm of at most "
               f"{qdot_max:g} rad/s; and the thesis's **learned-IK** method — a 55-unit tanh network trained on "
               f"{n_train:,} poses of one IK branch, asked for the joints of poses on each singular set, the window "
               "being its largest joint error there.")
        w_margin = build_windows(robot, margin=margin, analysis=analysis)
        w_sigma = build_windows(robot, sigma_min=threshold, analysis=analysis)
        # the training runs of the comparison below go to worker processes (a run is single-threaded and
        # seeded: the same reports as one after another) while this process trains the main network
        others = [(n_tr, sd) for n_tr in train_sizes for sd in train_seeds if (n_tr, sd) != (n_train, seed)]
        with LearnedRuns(robot, analysis, others) as pending:
            s.say(f"training the learned IK on {n_train:,} poses" + (
                f" ({len(others)} more runs in {pending.workers} worker processes)" if pending.workers > 1 else ""))
            w_learned, reports = learned_windows(robot, analysis=analysis, seed=seed, n_train=n_train)
            other_reports = dict(zip(others, pending.results(s.say)))
        by_kind = {w.kind: w for w in w_learned.windows}
        sets = {"margin": w_margin, "sigma_min": w_sigma, "learned": w_learned}

        probe = robot.random_configurations(100_000, seed=0)
        rows, comparison = [], {}
        for k, f in enumerate(factors):
            wm, ws, wl = w_margin.windows[k], w_sigma.windows[k], by_kind.get(f.kind)
            shares = [float(np.mean(w.contains(probe))) * 100 if w is not None else None for w in (wm, ws, wl)]
            thesis = ("the only singularity it found, so its method could give a q5 window only; docs/machines.md "
                      "records no width — the learned column is the method reproduced" if f.kind == "wrist"
                      else "not found")
            rows.append([f.kind, f"`{f.expr}` = 0", wm.width, ws.width, None if wl is None else wl.width,
                         *shares, thesis])
            comparison[f.kind] = {"margin": wm.width, "sigma_min": ws.width,
                                  "learned": None if wl is None else wl.width,
                                  "share_percent": dict(zip(("margin", "sigma_min", "learned"), shares))}
        s.table(["factor", "singular set", "margin ± (rad)", f"σ_min ≥ {threshold:g}: ± (rad)", "learned IK: ± (rad)",
                 "margin: share (%)", "σ_min: share (%)", "learned: share (%)", "the thesis"], rows,
                "Window half-widths from the three sources, and the share of the joint space each window covers "
                "(100 000 uniform samples). For the shoulder factor the half-width is the smallest joint-space "
                "distance the window keeps everywhere (the window is |g| ≤ ε).", fmt=".3g")
        s.results["window_comparison"] = comparison
        s.results["sigma_requirement"] = {"threshold": threshold, "tool_twist": v_tool, "joint_speed_budget": qdot_max}

        s.heading("The windows in detail")
        for label, ws in sets.items():
            caption = {"margin": f"Margin windows (±{margin:g} rad).",
                       "sigma_min": f"σ_min windows: σ_min ≥ {threshold:g} outside them.",
                       "learned": f"Learned-IK windows ({n_train:,} training poses, seed {seed})."}[label]
            sections.windows_table(s, robot, ws, label, caption, key=label)
        rng_ = reports[0]["branch"]["ranges"]
        branch_text = ", ".join([f"{k} ∈ [{rng_[k][0]:.3g}, {rng_[k][1]:.3g}] rad" for k in ("q3", "q5")]
                                + ["shoulder factor ≥ 0" if reports[0]["branch"]["spec"].get("shoulder", 1) > 0
                                   else "shoulder factor ≤ 0"])
        lrows = []
        for r in reports:
            j = [int(x[1:]) - 1 for x in r.get("width_joints", [])]
            held = max(r["heldout_errors"]["p95"][i] for i in j) if j else None
            lrows.append([r["factor"]["kind"], r.get("width"), ", ".join(r.get("width_joints", [])),
                          r.get("heldout_r2"), held, r.get("n_eval"), r.get("seconds")])
        s.table(["factor", "half-width (rad)", "joints", "held-out R²", "held-out error, 95 % (rad)",
                 "singular poses", "time (s)"], lrows,
                f"The learned-IK windows: one network ({reports[0]['model']['hidden_layer_sizes'][0]} tanh units, "
                f"trained in {reports[0]['model']['fit_seconds']:.1f} s on the IK branch {branch_text}) errs on fresh "
                "poses of its own branch nearly as much as on singular ones.", fmt=".3g")
        s.results["learned"] = {"n_train": n_train, "seed": seed, "reports": [jsonable_report(r) for r in reports],
                                "seconds": float(sum(r.get("seconds", 0.0) for r in reports))}

        s.heading("How the learned width depends on training")
        runs = []
        for n_tr in train_sizes:
            for sd in train_seeds:
                reps = reports if (n_tr == n_train and sd == seed) else other_reports[(n_tr, sd)]
                runs.append({"n_train": n_tr, "seed": sd, "heldout_r2": reps[0].get("heldout_r2"),
                             "widths": {r["factor"]["kind"]: r.get("width") for r in reps}})
        s.table(["training poses", "seed", "held-out R²", *[f"{f.kind} ± (rad)" for f in factors]],
                [[r["n_train"], r["seed"], r["heldout_r2"], *[r["widths"].get(f.kind) for f in factors]] for r in runs],
                "The same method with other training sizes and seeds: the windows follow the network.", fmt=".3g")
        s.results["learned_training"] = runs
        wrist_range = [min(r["widths"]["wrist"] for r in runs), max(r["widths"]["wrist"] for r in runs)]

        # the σ_min windows keep their promise: σ_min ≥ threshold at every sampled configuration outside
        # them; the same check for the other two sources
        Qc = robot.random_configurations(n_sigma_check, seed=seed + 7)
        sig_c = robot.sigma_min(Qc)
        check = {}
        for label, ws in sets.items():
            outside = ~ws.contains(Qc)
            check[label] = {"outside": int(outside.sum()),
                            "min_sigma_outside": float(sig_c[outside].min()) if outside.any() else None}
        kept = check["sigma_min"]["min_sigma_outside"] >= threshold
        names = {"margin": f"margin ±{margin:g} rad", "sigma_min": f"σ_min ≥ {threshold:g}", "learned": "learned IK"}
        s.table(["windows", "random configurations outside them", "min σ_min there", f"≥ {threshold:g}?"],
                [[names[label], c["outside"], c["min_sigma_outside"],
                  None if c["min_sigma_outside"] is None else c["min_sigma_outside"] >= threshold]
                 for label, c in check.items()],
                f"σ_min at {n_sigma_check:,} fresh random configurations (seed {seed + 7}) outside each source's "
                "windows: only the σ_min windows keep the requirement.", fmt=".4g")
        s.results["sigma_window_check"] = {"samples": n_sigma_check, "seed": seed + 7, "threshold": threshold,
                                           "outside": check["sigma_min"]["outside"],
                                           "min_sigma_outside": check["sigma_min"]["min_sigma_outside"],
                                           "kept": kept, "by_source": check}
        fig, across = plot_sigma_across_windows(robot, factors, sets, w_sigma, threshold,
                                                20_000 if s.quick else 100_000, seed)
        reach_low = ", ".join(f"{a['factor']} {a['largest_distance_below_threshold']:.3g}" for a in across)
        s.figure(fig, "sigma_across_windows",
                 "σ_min against the distance from each singular set (configurations inside the other factors' σ_min "
                 f"windows left out). In this sample σ_min falls below {threshold:g} up to a distance of {reach_low} "
                 "rad; the σ_min windows reach a little further (they are built for 1.2 × the threshold, from more "
                 "samples, including the corners where two singular sets meet). The margin windows stop inside the "
                 "low region; the learned windows stop wherever the network's error does.")
        s.results["sigma_across_windows"] = across

        s.heading("Which windows to trust")
        wl_w = by_kind["wrist"].width if "wrist" in by_kind else float("nan")
        cs, cm = check["sigma_min"], check["margin"]
        s.text(f"**Plan around the σ_min windows.** Their width follows from a requirement you can state — "
               f"{v_tool:g} of tool twist within {qdot_max:g} rad/s of joint speed, σ_min ≥ {threshold:g} — and "
               f"check: on {cs['outside']:,} fresh configurations outside them the smallest σ_min is "
               f"{cs['min_sigma_outside']:.3g}. Change the requirement and the windows follow.\n\n"
               f"**The margin windows** (±{margin:g} rad) are a guess with nothing to check it against: just outside "
               f"them σ_min drops to {cm['min_sigma_outside']:.2g}, so a path that clears them can still ask for "
               f"{v_tool / cm['min_sigma_outside']:.0f} rad/s of joint speed per {v_tool:g} of tool twist.\n\n"
               f"**The learned-IK windows** — the thesis's method — measure a network, not the arm: ±{wl_w:.3g} rad "
               f"around q5 = 0 here ({wrist_range[0]:.3g} to {wrist_range[1]:.3g} rad over the training runs above), "
               "and a shoulder window that covers "
               f"{comparison.get('shoulder', {}).get('share_percent', {}).get('learned') or 0:.0f} % of the joint "
               "space. The width is the network's largest joint error at singular poses, which is about its error "
               "anywhere on its branch (compare the held-out error column); other training poses, another seed or "
               "another network give another width, and none of it says how much dexterity the arm has left. The "
               "thesis found only the wrist singularity, so its method could give a q5 window only; "
               "docs/machines.md records no width for it, so none is quoted here.")
        wtxt = ", ".join(f"{f.kind} ±{w_sigma.windows[k].width:.3g}" for k, f in enumerate(factors))
        s.finding(f"σ_min ≥ {threshold:g} windows: {wtxt} rad (margin ±{margin:g}; learned IK ±{wl_w:.3g} rad at the "
                  f"wrist); outside them σ_min ≥ {cs['min_sigma_outside']:.3g} on {cs['outside']:,} samples", ok=kept)

    # ------------------------------------------------------------------------------------------
    with s.section("A planned move"):
        start, goal = np.array(PLAN_START), np.array(PLAN_GOAL)
        line = np.linspace(0.0, 1.0, 2001)[:, None] * (goal - start) + start
        entered = {w.kind: int(w.contains(line).sum()) for w in w_margin.windows}
        inside = " and ".join(k for k, v in entered.items() if v) or "no"
        goal_in_sigma = [w.kind for w in w_sigma.windows if w.contains(goal)]
        s.text(f"The move of `studies/default_study.toml`, from q = ({', '.join(f'{x:g}' for x in PLAN_START)}) to "
               f"({', '.join(f'{x:g}' for x in PLAN_GOAL)}) rad. Its straight joint-space line enters the {inside} "
               f"margin window ({max(entered.values())} of 2001 points on it), so a controller interpolating joints "
               "would take the arm that close to a singularity. The goal lies inside the σ_min "
               f"window{'s' if len(goal_in_sigma) > 1 else ''} of the {' and '.join(goal_in_sigma) or '—'} (its own "
               f"σ_min is {robot.sigma_min(goal):.3g}, but a window must keep σ_min up for every value of the joints "
               "it does not name), so the plan goes around the **margin windows** and keeps the dexterity "
               "requirement as a "
               f"**σ_min floor of {threshold:g}** checked along the path. OMPL's RRTConnect finds the path; rmtkit "
               "then proves, segment by segment, that no point of it is inside a window.")
        try:
            res = sections.planned_path(s, robot, w_margin, start, goal, time_limit=plan_time, seed=seed,
                                        sigma_min=threshold)
        except PlanningError as e:      # e.g. a wider margin puts the start or goal inside a window
            res = None
            s.text(f"**No plan**: {e}. Choose a start and goal outside every window (or a narrower margin).")
        s.results["straight_line"] = {"points": 2001, "inside_margin_windows": entered,
                                      "min_sigma": float(robot.sigma_min(line).min()),
                                      "goal_inside_sigma_windows": goal_in_sigma}
        if res is not None and res.success:
            s.figure(plot_plan(robot, w_margin, res.path, threshold), "plan",
                     "The planned path (solid) and the straight line (dashed) against the fraction of each one's "
                     "joint-space length: joint values with the windows near them shaded, the shoulder factor |g| "
                     "against its window, and σ_min with the floor.")
            s.finding(f"planned move: {len(res.path)} waypoints, "
                      f"{'proven clear of every window' if res.proven else 'windows only sampled, not proven'}, "
                      f"min σ_min {res.min_sigma:.3g}; the straight line is "
                      f"{'valid' if res.straight_line_valid else 'not valid (it enters the ' + inside + ' window)'}",
                      ok=res.proven and not res.straight_line_valid)
        elif res is None:
            s.finding("the move could not be planned: its start or goal is inside a window", ok=False)
        else:
            s.finding(f"the planner found no path ({res.status})", ok=False)

    # ------------------------------------------------------------------------------------------
    with s.section("The functional workspace"):
        path = res.path if res is not None and res.success else None
        # red: below the dexterity requirement of the σ_min windows
        ws = sections.workspace(s, robot, n_workspace, seed, q_view=start, path=path, threshold=threshold)
        s.text(f"Reach {ws.reach:.3g} m from the base origin; {100 * ws.near_singular_fraction:.1f} % of the samples "
               f"are below the dexterity requirement σ_min ≥ {threshold:g} (red). They gather along the axis of joint "
               "1 (the shoulder singularity: the wrist centre on that axis) and around the shoulder, where the folded "
               "arm brings the wrist centre back (the elbow singularity at q3 = 1.4365 ± π rad); the wrist "
               "singularity q5 = 0 does not depend on where the tool is, so its points are scattered through the "
               "whole cloud. The 3-D view animates the planned move.")

    # ------------------------------------------------------------------------------------------
    with s.section("A weld seam"):
        seam = load_toolpath(SEAM_FILE, robot)
        s.input("weld seam", f"studies/toolpaths/{SEAM_FILE.name}")
        s.code(SEAM_FILE.read_text(encoding="utf-8"), f"The tool path `{SEAM_FILE.name}`.", collapsed=True)
        rep = validate_toolpath(robot, seam, windows=w_sigma, start_q=np.array(SEAM_START), branch_seed=seed,
                                sigma_min=threshold)
        d = toolpath_json(rep, robot)
        q0 = rep.q[0]
        branch = {f.kind: float(f(q0[None])[0]) for f in factors}
        same_branch = all(np.all(np.sign(f(rep.q)) == np.sign(branch[f.kind])) for f in factors)
        # the branch in words: the side of q5 = 0, the stretch of q3 between two elbow singularities, the
        # side of joint 1's axis the wrist centre is on (the shoulder factor is > 0 at q = 0, reaching forward)
        roots = [-math.inf, *[f for f in factors if f.kind == "elbow"][0].solutions["values"], math.inf]
        k = next(i for i in range(len(roots) - 1) if roots[i] < q0[2] < roots[i + 1])
        branch_text = (f"q5 {'>' if q0[4] > 0 else '<'} 0; q3 between the elbow singularities at {roots[k]:.4g} and "
                       f"{roots[k + 1]:.4g} rad; the wrist centre on the "
                       + ("same side of joint 1’s axis as at q = 0" if branch["shoulder"] > 0
                          else "far side of joint 1’s axis"))
        s.text(f"An L-shaped fillet weld on a table in front of the robot: {rep.s[-1] * 1000:.0f} mm at 10 mm/s, the "
               "torch pointing down with a 15° push angle and turning with the seam at the corner. The tool path is "
               "followed with continuous inverse kinematics from the configuration below, and every waypoint is "
               f"checked: reachable, within the joint limits, outside the σ_min windows, σ_min ≥ {threshold:g}, no "
               f"jump between IK branches.\n\n**{d['verdict']}**")
        s.table(["q1 (rad)", "q2 (rad)", "q3 (rad)", "q4 (rad)", "q5 (rad)", "q6 (rad)", "wrist: sin q5",
                 "elbow factor", "shoulder factor (m)", "same signs all along"],
                [[*q0.tolist(), branch["wrist"], branch["elbow"], branch["shoulder"], same_branch]],
                f"The IK branch at the first waypoint, given by the signs of the three singular factors: "
                f"{branch_text}. "
                f"{'They stay the same' if same_branch else 'They do **not** stay the same'} along the seam.",
                fmt=".4g")
        s.table(["waypoints", "length (m)", "duration (s)", "min σ_min", "min limit margin (rad)",
                 "max IK error (m)", "max joint speed (rad/s)", "in windows"],
                [[d["waypoints"], d["length"], d["duration"], d["min_sigma"], min(d["min_limit_margin"]),
                  d["max_position_error"], max(d["max_joint_speed"]), d["waypoints_in_windows"]]],
                "The seam's validation (`rmt validate-toolpath fanuc_m16ib20 fanuc_weld_seam --sigma-min "
                f"{threshold:g} --start {' '.join(f'{x:g}' for x in SEAM_START)}`).", fmt=".4g")
        with tempfile.TemporaryDirectory(prefix="rmt-fig-") as tmp:
            p = Path(tmp) / "weld_seam.png"
            plot_toolpath_report(rep, robot, p, title="FANUC M-16iB/20: weld seam")
            s.image(p, "The joints along the seam and σ_min with its floor; a window is shaded where it comes within "
                       "the plotted range of a joint.", name="weld_seam")
        s.view3d(robot_view(robot, q0, path=rep.q, title="Weld seam"), "weld_seam_3d",
                 "The arm over the seam; the slider moves it along the tool path.")
        s.results["weld_seam"] = {**d, "file": SEAM_FILE.name, "start_q": q0.tolist(), "branch": branch,
                                  "same_branch": same_branch}
        s.finding(f"weld seam {'valid' if rep.ok else 'INVALID'}: {d['waypoints']} waypoints over "
                  f"{d['length'] * 1000:.0f} mm, min σ_min {d['min_sigma']:.3g} (floor {threshold:g}), one IK branch",
                  ok=rep.ok and same_branch)


if __name__ == "__main__":
    raise SystemExit(main(sys.modules[__name__]))

"""The homework's drawing task (docs/machines.md §6): a "UR3-like" arm with a pen draws a closed "D"
in a vertical plane, starting at a singular pose, first with the homework's method — q += J⁻¹·ẋ·Δt,
with its wrong Jacobian (joint axes z1…z6) and with the correct one (z0…z5) — then with rmtkit's OSQP
path follower, which bounds joint speeds and keeps out of singular windows unless the path forces it
in. The homework's Jacobian blows up at the first step. The correct naive method and the follower both
finish the drawing within 1 mm and 1°, but only because the path allows it: when the pen axis is held,
every point of the drawing is a wrist singularity (θ5 = 0). So "completes" comes with a caveat: the
arm spends the whole drawing inside the wrist window. Only when the pen may tilt does the follower get
out, within the first second.

The report shows, for each method, what share of the waypoints lies in the wrist window, whether the
path forces that, σ_min, the peak joint speed and the largest tracking error. The closed form shows
from the path alone why the window is forced.
"""
from __future__ import annotations

import math
import sys
import tempfile
from pathlib import Path

import numpy as np
from matplotlib.figure import Figure

from planning.follow import follow_path
from studies.plots.drawing import plot_drawing
from studies.report.view3d import robot_view
from studies.study import Study, main, sections
from studies.study.drawing import START_Q, drawing_path, drawing_windows, run_drawing_study
from studies.study.follow import solver_output_silenced

NAME = "ur3_drawing"
TITLE = "UR3-like homework arm: the pen drawing from a singular start, naive J⁻¹ against the QP follower"

#: (series key, label, colour, line style) of every method, in the report's order
METHODS = [("naive_homework", "naive J⁻¹, homework Jacobian (z1…z6)", "#d62728", "-"),
           ("naive", "naive J⁻¹, correct Jacobian (z0…z5)", "k", "--"),
           ("qp_pose", "QP follower, pose mode", "#1f77b4", "-"),
           ("qp_axis", "QP follower, pen-axis mode", "#2ca02c", ":"),
           ("qp_position", "QP follower, position mode", "#9467bd", "-.")]
LABELS = {key: label for key, label, _, _ in METHODS}


def _length(m: float) -> str:
    """A small length in the unit that shows it best (nm, µm or mm)."""
    return (f"{m * 1e9:.2g} nm" if m < 1e-6 else f"{m * 1e6:.2g} µm" if m < 1e-3 else f"{m * 1e3:.3g} mm")


def _deg_range(lo: float, hi: float) -> str:
    lo, hi = (round(math.degrees(x), 1) + 0.0 for x in (lo, hi))      # + 0.0: no "−0.0"
    return f"{lo:.1f}° … {hi:.1f}°".replace("-", "−")


def run(s: Study) -> None:
    robot = s.robot("ur3_homework_pen")
    margin_deg = s.input("wrist (and every) window half-width (°)", 5.0)
    tol_mm, tol_deg = s.input("tolerance: position (mm)", 1.0), s.input("tolerance: orientation (°)", 1.0)
    # how the window width changes the picture: a few widths in quick mode, more in full mode
    sweep_deg = s.input("window widths compared (°)", [2.0, 20.0] if s.quick else [1.0, 2.0, 5.0, 10.0, 20.0])
    margin, tol = math.radians(margin_deg), (tol_mm * 1e-3, math.radians(tol_deg))

    with s.section("The arm, the pen and the task"):
        s.text("The homework's arm is **not** the real UR3: its DH table is the homework's (docs/machines.md §6); "
               "the pen lengthens d6 to 0.1218 m, and the pen tip is the tool point. Joint limits are not "
               "given by the homework (±2π here).")
        sections.dh_table(s, robot)
        poses, times, seg = drawing_path(robot, START_Q)
        p0 = poses[0, :3, 3]
        s.text(f"The pen starts at q = (0, 0, 90°, −90°, 0, 0), tip at ({p0[0]:.4f}, {p0[1]:.4f}, {p0[2]:.5f}) m "
               "with the pen along −x, and draws counter-clockwise in the plane x = const (seen from +x): a "
               "quarter circle of radius 50 mm, 50 mm down, 100 mm along +y, 50 mm up and the other quarter "
               f"circle back — 5 segments of 4 s with 1000 points each ({len(poses)} waypoints, Δt = "
               f"{1e3 * (times[1] - times[0]):g} ms). The orientation is held throughout.")
        with solver_output_silenced():
            res = run_drawing_study(robot, window_margin=margin, tolerance=tol, series=True)
        st = res["start"]
        s.table(["quantity", "value"],
                [["σ_min(J) at the start", st["sigma_min"]],
                 ["lost twist (vx, vy, vz, ωx, ωy, ωz), base frame", ", ".join(f"{x:.3g}" for x in st["lost_twist"])],
                 ["pen axis (base frame)", ", ".join(f"{round(x, 12) + 0.0:.3g}" for x in st["pen_axis"])],
                 ["lost twist's rotation about the pen axis", st["lost_rotation_about_pen_axis"]]],
                "The start pose: J is exactly singular (θ5 = 0). The lost direction is a rotation about the base y "
                "axis — the pen tilting — not a turn about the pen's own axis.", fmt=".3g")

    with s.section("Why the drawing forces the wrist window"):
        fb = res["forced_by_path"]
        s.text(f"From the path alone, without any follower: {fb['reason']}.")
        rows = []
        for key, label in (("start_branch", "start branch (θ1 = 0 at the start)"),
                           ("other_branch", "the other shoulder solution")):
            b = fb[key]
            rows.append([label, _deg_range(*b["theta1_rad"]),
                         _deg_range(*(math.asin(x) for x in b["abs_sin_theta5"])).replace("−", ""),
                         b["waypoints_in_window"], 100 * b["share_in_window"]])
        s.table(["inverse-kinematics branch", "θ1 over the drawing", "|θ5| (or 180° − |θ5|)",
                 f"waypoints in the ±{margin_deg:g}° window", "share (%)"], rows,
                f"The two shoulder solutions at each of the {fb['waypoints']} waypoints, in closed form from the pen "
                "tip and the pen axis (`studies.study.drawing.wrist_branches`). Pose mode and pen-axis mode hold the "
                "same tip and axis, so this holds for both.", fmt=".4g")
        s.text("The other solution is not singular, but it has joint 1 turned by about 150°: the arm cannot get "
               "there while the pen stays on the drawing. Any method that holds the pen axis on this path — the "
               "naive method, the follower in pose or pen-axis mode — therefore stays in the wrist window from "
               "the first waypoint to the last. That is the path's doing, not the method's.")
        # the follower's own test agrees: at every step its probe found no configuration outside the
        # window that meets the next target (forced steps = all steps, in pose and in pen-axis mode)
        steps = fb["waypoints"] - 1
        probe = {m: res["qp"][m]["forced_steps"] for m in ("pose", "axis")}
        s.text(f"The follower's own test agrees: at every step inside a window it asks whether some configuration "
               f"outside still meets the next target within 10 % of the tolerance; it found none at "
               f"{probe['pose']}/{steps} steps in pose mode and {probe['axis']}/{steps} in pen-axis mode.")
        s.results["forced_by_path"] = fb | {"follower_forced_steps": probe, "steps": steps}
        agree = fb["forced"] == (probe["pose"] == steps) == (probe["axis"] == steps)
        s.finding(f"the path forces the wrist window: with the pen axis held, θ5 = 0 at all {fb['waypoints']} "
                  f"waypoints of the start branch (closed form; the follower's probe finds no way out at "
                  f"{probe['pose']}/{steps} steps); the other IK branch (θ1 ≈ "
                  f"{math.degrees(np.mean(fb['other_branch']['theta1_rad'])):.0f}°) is not reachable along the path"
                  if fb["forced"] else "the closed form finds waypoints of the start branch outside the wrist window",
                  ok=agree)

    with s.section("Naive J⁻¹ against the QP follower"):
        n = res["path"]["waypoints"]
        rows, methods = [], {}
        for key, label, _, _ in METHODS:
            d = res[key] if key.startswith("naive") else res["qp"][key[3:]]
            orient = d["max_axis_error_rad"] if d["task"] == "axis" else d["max_orientation_error_rad"]
            ranges = "; ".join(", ".join(f"{a}–{b}" for a, b in w["ranges"]) for w in d["windows_entered"])
            forced = {True: "yes", False: "no", None: "— (does not follow the path)"}[d["forced_by_path"]]
            # σ_min after the start (the start itself is exactly singular for every method)
            sig = np.asarray(res["series"][key]["sigma_min"], float)[1:]
            sig_min, sig_med = float(np.nanmin(sig)), float(np.nanmedian(sig))
            rows.append([label, d["task"], d["waypoints_in_window"], 100 * d["share_in_window"], ranges or "none",
                         forced, sig_min, sig_med, d["peak_joint_speed"], d["max_position_error_m"] * 1e3,
                         None if d["task"] == "position" else math.degrees(orient)])
            methods[key] = {"label": label, "task": d["task"], "waypoints_in_window": d["waypoints_in_window"],
                            "share_in_window": d["share_in_window"], "windows_entered": d["windows_entered"],
                            "forced_by_path": d["forced_by_path"], "min_sigma": d["min_sigma"],
                            "min_sigma_after_start": sig_min, "median_sigma": sig_med,
                            "peak_joint_speed_rad_s": d["peak_joint_speed"],
                            "max_position_error_m": d["max_position_error_m"],
                            "max_orientation_error_deg": None if d["task"] == "position" else math.degrees(orient),
                            "within_tolerance": d["within_tolerance"], "verdict": d["verdict"]}
        s.table(["method", "task", "waypoints in a window", "share (%)", "waypoint ranges", "forced by the path",
                 "σ_min after the start: min (SI)", "σ_min: median (SI)", "peak joint speed (rad/s)",
                 "max position error (mm)", "max orientation error (°)"],
                rows, f"Every method on the {n} waypoints; windows of ±{margin_deg:g}° around the wrist, elbow and "
                      "shoulder factors (only the wrist window is ever entered). σ_min of the 6×6 Jacobian (mixed "
                      "units, m/rad and rad/rad rows; 0 at the exactly singular start for every method, so the "
                      "minimum is taken from waypoint 1 on). Orientation error: the full "
                      "rotation angle (pose), the pen-axis angle (pen-axis mode); position mode leaves the "
                      "orientation free.", fmt=".3g")
        s.table(["method", "verdict"], [[LABELS[k], m["verdict"]] for k, m in methods.items()],
                f"Verdicts: tolerance {tol_mm:g} mm, {tol_deg:g}°.")
        s.results["methods"] = methods
        fig = wrist_figure(res)
        s.figure(fig, "theta5_along_drawing",
                 f"θ5 and σ_min along the drawing; the orange band is the ±{margin_deg:g}° wrist window, the blue "
                 "band the |θ5| the other shoulder solution would have; grey lines mark the segment corners.")
        tips = {}
        for key, _, _, _ in METHODS:
            Q = res["series"][key]["q"]
            ok = np.all(np.isfinite(Q), axis=1)
            P = np.full((len(Q), 2), np.nan)
            P[ok] = robot.fk(Q[ok])[:, 1:3, 3]
            tips[key] = P
        s.figure(drawn_figure(res, poses[:, 1:3, 3], tips), "drawn",
                 "What each method draws in the plane of the drawing (the target in grey).")
        with tempfile.TemporaryDirectory(prefix="rmt-fig-") as tmp:
            p = plot_drawing(res, Path(tmp) / "speeds_and_errors.png")
            s.image(p, "Joint speeds of the homework's naive method (log scale) and of the follower in pose mode, "
                       "and the position error of every method against time.", name="speeds_and_errors")
        s.view3d(robot_view(robot, np.array(START_Q), path=res["series"]["qp_pose"]["q"][::20],
                            title="The follower's drawing (pose mode)"), "drawing_3d",
                 "The arm at the start pose and the pen path of the follower in pose mode (the slider moves the arm "
                 "along it).")
        # the drawing's explanation, without the two sentences the section above already gives
        for line in res["explanation"]:
            if not line.startswith(("The path alone says so", "Pose mode", "Axis mode", "Pose and axis mode")):
                s.text(line)
        nh, nv, qp = res["naive_homework"], res["naive"], res["qp"]
        s.finding(f"the homework's naive method (Jacobian with axes z1…z6) blows up at the first step: joint speeds up "
                  f"to {nh['peak_joint_speed']:.2g} rad/s and a {nh['max_position_error_m'] * 1e3:.0f} mm tracking "
                  "error")
        s.finding(f"with the correct Jacobian the naive method draws within tolerance "
                  f"({_length(nv['max_position_error_m'])} drift, peak {nv['peak_joint_speed']:.3g} rad/s) — inside "
                  f"the wrist window at {nv['waypoints_in_window']}/{n} waypoints, as the path forces",
                  ok=nv["within_tolerance"])
        for m in ("pose", "axis"):
            d = qp[m]
            s.finding(f"QP follower, {m} mode: within tolerance ({_length(d['max_position_error_m'])}, peak "
                      f"{d['peak_joint_speed']:.3g} rad/s), but inside the wrist window at {d['waypoints_in_window']}/"
                      f"{n} waypoints ({100 * d['share_in_window']:.0f} %) — forced by the path, not a choice of the "
                      "follower", ok=d["within_tolerance"])
        d = qp["position"]
        last = max(b for w in d["windows_entered"] for _, b in w["ranges"]) if d["windows_entered"] else -1
        s.finding(f"QP follower, position mode (pen free to tilt): in the wrist window only at waypoints 0–{last} "
                  f"({100 * d['share_in_window']:.1f} %, the first {times[last + 1]:.2g} s), then out for good; the "
                  f"pen tilts by up to {math.degrees(d['pen_tilt_max_rad']):.2g}°", ok=d["within_tolerance"])
        s.results["drawing"] = {k: v for k, v in res.items() if k != "series"}

    with s.section("How the window width changes the picture"):
        rows, sweep = [], []
        for w_deg in sweep_deg:
            ws = drawing_windows(robot, math.radians(w_deg))
            for mode in ("pose", "position"):
                with solver_output_silenced():
                    fr = follow_path(robot, (poses, times), np.array(START_Q), ws, mode=mode, tolerance=tol)
                inside = fr.in_window >= 0
                last = int(np.flatnonzero(inside)[-1]) if inside.any() else -1
                row = {"half_width_deg": w_deg, "mode": mode, "waypoints_in_window": int(inside.sum()),
                       "share_in_window": float(inside.mean()), "last_waypoint_in_window": last,
                       "forced_steps": int(fr.forced.sum()), "peak_joint_speed_rad_s": fr.peak_joint_speed,
                       "max_position_error_m": fr.max_tracking_error,
                       "pen_tilt_max_deg": math.degrees(float(fr.axis_error.max())),
                       "within_tolerance": fr.within_tolerance}
                sweep.append(row)
                rows.append([w_deg, mode, row["waypoints_in_window"], 100 * row["share_in_window"], last,
                             row["forced_steps"], row["peak_joint_speed_rad_s"], row["max_position_error_m"] * 1e3,
                             row["pen_tilt_max_deg"]])
        s.table(["half-width (°)", "mode", "waypoints in a window", "share (%)", "last waypoint inside",
                 "forced steps", "peak joint speed (rad/s)", "max position error (mm)", "pen tilt max (°)"], rows,
                "The follower with narrower and wider windows (the same path, start and tolerance).", fmt=".3g")
        dt = float(times[1] - times[0])
        pos = "; ".join(
            f"±{r['half_width_deg']:g}°: out after waypoint {r['last_waypoint_in_window']} "
            f"({(r['last_waypoint_in_window'] + 1) * dt:.2g} s), {r['forced_steps']} forced steps, pen tilt up to "
            f"{r['pen_tilt_max_deg']:.2g}°" if r["last_waypoint_in_window"] < n - 1 else
            f"±{r['half_width_deg']:g}°: **inside at all {n} waypoints** ({r['forced_steps']} forced steps)"
            for r in sweep if r["mode"] == "position")
        stuck = [r["half_width_deg"] for r in sweep if r["mode"] == "position" and r["share_in_window"] == 1.0]
        s.text("Pose mode stays in the wrist window at every width: θ5 = 0 belongs to the path, and no width moves "
               f"it. Position mode — {pos}. The path never forces position mode into the window (the pen may tilt), "
               "but the follower's test of whether a step is forced looks one step ahead: it asks for a configuration "
               "outside the window that meets the next waypoint within 10 % of the tolerance, and the wider the "
               "window, the further θ5 has to move to clear it. Where no single step can do that, the follower counts "
               "the step as forced and stays in — so its \"forced steps\" are a verdict on one step, not on the "
               "path; the closed form above is the statement about the path.")
        s.results["window_width_sweep"] = sweep
        if stuck:
            s.finding(f"with a ±{', ±'.join(f'{w:g}' for w in stuck)}° window "
                      "the follower in position mode stays in the "
                      "wrist window for the whole drawing although the path does not force it (the pen may tilt): its "
                      "forced-window test looks only one step ahead")
        pose_all = all(r["share_in_window"] == 1.0 for r in sweep if r["mode"] == "pose")
        s.finding(f"at every window half-width tried ({', '.join(f'{w:g}' for w in sweep_deg)}°) "
                  "pose mode stays in the "
                  "wrist window at every waypoint: the width does not change what the path forces", ok=pose_all)


# ---- figures (matplotlib's Figure API, no pyplot state) -------------------------------------------
def _corners(ax, t, corners) -> None:
    for c in corners:
        ax.axvline(t[c], color="grey", lw=0.5, alpha=0.5)


def wrist_figure(result: dict) -> Figure:
    """Two panels over time: θ5 (deg) of every method with the wrist window ±w shaded and the two
    closed-form branches (the start branch θ5 = 0, the other shoulder solution's |θ5|), and σ_min of
    the Jacobian (log scale).  ``result``: :func:`studies.study.drawing.run_drawing_study` with series."""
    s, fb = result["series"], result["forced_by_path"]
    t, corners = s["t"], result["path"]["corners"]
    w = math.degrees(fb["margin_rad"])
    fig = Figure(figsize=(12, 7.5), layout="constrained")
    ax1, ax2 = fig.subplots(2, 1, sharex=True)
    ax1.axhspan(-w, w, color="#f4a582", alpha=0.45, lw=0, label=f"wrist window |θ5| ≤ {w:g}°")
    ob = fb["other_branch"]["abs_sin_theta5"]
    ax1.axhspan(math.degrees(math.asin(ob[0])), math.degrees(math.asin(ob[1])), color="#92c5de", alpha=0.35, lw=0,
                label="|θ5| of the other shoulder solution (closed form)")
    top = 1.3 * math.degrees(math.asin(ob[1]))
    off_scale = []
    for key, label, colour, ls in METHODS:
        if key not in s:
            continue
        q5 = np.degrees(s[key]["q"][:, 4])
        if np.nanmax(np.abs(q5)) > 10 * top:
            k = int(np.argmax(np.abs(q5) > top))
            off_scale.append(f"{label}: |θ5| = {np.nanmax(np.abs(q5)):.1e}° from t = {t[k]:.3g} s (off the plot)")
            continue
        ax1.plot(t, q5, color=colour, ls=ls, lw=1.2, label=label)
    ax1.set_ylim(-2 * w, top)
    ax1.set_ylabel("θ5 (°)")
    ax1.ticklabel_format(axis="y", useOffset=False, style="plain")
    ax1.legend(fontsize=8, loc="upper left", bbox_to_anchor=(1.01, 1.0))
    title = "θ5 along the drawing: the start branch lies on θ5 = 0 throughout"
    if off_scale:
        title += "\n" + "; ".join(off_scale)
    ax1.set_title(title, fontsize=9)
    floor = 1e-16
    for key, label, colour, ls in METHODS:
        if key in s:
            sm = np.asarray(s[key]["sigma_min"], float)
            ax2.plot(t, np.maximum(np.where(np.isfinite(sm), sm, np.nan), floor), color=colour, ls=ls, lw=1.1,
                     label=label)
    ax2.set_yscale("log")
    ax2.set_ylim(floor / 3, 3)
    ax2.set_ylabel("σ_min of J (SI; ≤ 1e-16 drawn at 1e-16)")
    ax2.set_xlabel("time (s)")
    ax2.legend(fontsize=8, loc="upper left", bbox_to_anchor=(1.01, 1.0))
    for ax in (ax1, ax2):
        _corners(ax, t, corners)
        ax.grid(True, alpha=0.3)
    return fig


def drawn_figure(result: dict, target_yz: np.ndarray, tips_yz: dict[str, np.ndarray]) -> Figure:
    """The drawing in the y–z plane (mm): the target and each method's pen tip (``tips_yz``: series
    key → (N, 2) in m; NaN rows skipped).  Left: zoomed on the target (methods that leave it are named);
    right: the methods that left it, at their own scale."""
    fig = Figure(figsize=(13, 6), layout="constrained")
    ax, ax_far = fig.subplots(1, 2, width_ratios=[1.2, 1])
    ty = target_yz * 1e3
    lo, hi = ty.min(axis=0), ty.max(axis=0)
    pad = 0.25 * (hi - lo).max()
    far_keys = []
    for a in (ax, ax_far):
        a.plot(ty[:, 0], ty[:, 1], color="#bbbbbb", lw=6, solid_capstyle="round", label="target")
    for key, label, colour, ls in METHODS:
        if key not in tips_yz:
            continue
        p = tips_yz[key] * 1e3
        p = p[np.all(np.isfinite(p), axis=1)]
        far = np.any((p < lo - pad) | (p > hi + pad), axis=1)
        if far.mean() > 0.5:
            far_keys.append(f"{label}: {100 * far.mean():.0f} % of its points off this view (right)")
            ax_far.plot(p[:, 0], p[:, 1], ".", color=colour, ms=1.5, label=f"{label} (every waypoint)")
        else:
            ax.plot(p[:, 0], p[:, 1], color=colour, ls=ls, lw=1.2, label=label)
    ax.set_aspect("equal")
    for a in (ax, ax_far):
        a.plot(*ty[0], "o", color="k", ms=5, label="start (singular pose)")
        a.ticklabel_format(useOffset=False, style="plain")
        a.set_xlabel("y (mm)")
        a.set_ylabel("z (mm)")
        a.grid(True, alpha=0.3)
        a.legend(fontsize=8, loc="upper left", bbox_to_anchor=(0.0, -0.16))
    ax.set_xlim(lo[0] - pad, hi[0] + pad)
    ax.set_ylim(lo[1] - pad, hi[1] + pad)
    ax.set_title("The pen tip in the drawing plane" + ("\n" + "\n".join(far_keys) if far_keys else ""), fontsize=9)
    ax_far.set_title("Where the methods that leave the drawing go (pen tip projected onto y–z)", fontsize=9)
    if not far_keys:
        ax_far.set_title("Every method stays on the drawing (same view)", fontsize=9)
    return fig


if __name__ == "__main__":
    raise SystemExit(main(sys.modules[__name__]))

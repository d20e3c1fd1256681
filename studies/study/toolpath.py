"""A tool path's validation as JSON in the robot file's units: what ``rmt validate-toolpath --json``
prints and what a study keeps of a validated tool path (:func:`toolpath_json`)."""
from __future__ import annotations

import numpy as np

import kin
from studies.jsonio import finite_or_none, jsonable
from studies.units import joint_units, unit_names

__all__ = ["toolpath_json"]


def toolpath_json(report, robot: kin.Robot, waypoints: bool = False) -> dict:
    """A :class:`~planning.toolpath.ToolPathReport` of ``robot`` as a JSON-ready dict: its verdict and
    SI summary converted to the robot file's units (σ_min stays SI); with ``waypoints`` the
    per-waypoint arrays too."""
    from planning.toolpath.check import KINDS
    c = robot.chain
    L, A, var = c.length_scale, c.angle_scale, c.variable_scale
    d = report.summary()
    fp = report.first_problem
    reach = report.reachable
    margins = np.minimum(report.q - c.lower, c.upper - report.q) / var     # per joint, file units
    out = {
        "valid": report.ok,
        "first_problem": None if fp is None else {"index": fp.index, "kind": fp.kind, "detail": fp.detail,
                                                  "s": fp.s / L, "t": fp.t, "origin": fp.origin,
                                                  "segment": [fp.index, fp.index + 1] if fp.segment else None},
        "verdict": report.verdict(),
        "waypoints": report.n_waypoints, "reachable": int(reach.sum()),
        "min_sigma": d["min_sigma"], "min_sigma_index": d["min_sigma_index"],
        "min_manipulability": d["min_manipulability"],
        "max_position_error": None if d["max_position_error"] is None else d["max_position_error"] / L,
        "max_orientation_error": None if d["max_orientation_error"] is None else d["max_orientation_error"] / A,
        "min_limit_margin": [finite_or_none(m) for m in (margins[reach].min(axis=0) if reach.any()
                                                         else np.full(c.n, np.nan))],
        "max_joint_speed": None if d["max_joint_speed"] is None else (np.array(d["max_joint_speed"]) / var).tolist(),
        "max_speed_ratio": d["max_speed_ratio"],
        "counts": report.counts, "segment_counts": d["segment_counts"], "segments_check": d["segments_check"],
        "segment_problems": d["segment_problems"], "windows": report.window_names,
        "waypoints_in_windows": d["waypoints_in_windows"],
        "length": report.s[-1] / L, "duration": d["duration"], "mode": report.mode,
        "robot": report.robot, "source": report.source, "elapsed_s": report.elapsed_s, "stats": report.stats,
        "units": {**unit_names(c), "joints": joint_units(c), "time": "s", "sigma_min": "SI",
                  "min_limit_margin": "per joint, file units", "max_joint_speed": "per joint, file units / s"},
    }
    if waypoints:
        qd = report.joint_speed / var
        out["per_waypoint"] = {
            "s": (report.s / L).tolist(), "t": None if report.t is None else report.t.tolist(),
            "q": (report.q / var).tolist(), "reachable": reach.tolist(),
            "position_error": (report.position_error / L).tolist(),
            "orientation_error": (report.orientation_error / A).tolist(),
            "limit_margin": margins.min(axis=1).tolist(), "sigma_min": report.sigma_min.tolist(),
            "manipulability": report.manipulability.tolist(), "window": report.window.tolist(),
            "joint_speed": qd.tolist(), "speed_ratio": report.speed_ratio.tolist(),
            "problems": {k: report.problems(k).tolist() for k in KINDS}}
    return jsonable(out)

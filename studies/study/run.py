"""A study file run as a study (``rmt study my_study.toml``): kinematics at the file's configurations,
the singular set, its windows, the functional workspace and a planned joint path around the windows.

The file's format (every key, unit and default) is in docs/studies.md ("Study files") and is validated by
:func:`studies.study.kinematics.load_study` before anything runs.  :func:`run_study` writes
``report.html``, ``results.json`` (strict JSON), ``workspace.png`` and ``plan.csv`` into a fresh
directory that replaces ``out_dir`` only when the study has finished
(:func:`studies.study.context.run_study_function`).
"""
from __future__ import annotations

from pathlib import Path

import numpy as np

from studies.study import sections as sec
from studies.study.context import Study, run_study_function
from studies.study.windows import factor_margins
from studies.taskrows import require_task_rows

__all__ = ["run_study", "file_study"]


def file_study(study: dict):
    """The study function of a loaded study file (:func:`~studies.study.kinematics.load_study`)."""

    def run(s: Study) -> None:
        robot = require_task_rows(s.robot(study["robot"]))
        c = robot.chain
        s.input("study file robot", study["robot"])
        with s.section("Kinematics"):
            sec.dh_table(s, robot)
            sec.configurations_table(s, robot, study["configurations"])
            s.results["backend"] = robot.backend
        analysis = windows = None
        if "singularities" in study or "windows" in study or "plan" in study:
            with s.section("Singular set"):
                analysis = sec.singular_set(s, robot)
        if "windows" in study:
            from planning.windows import build_windows
            with s.section("Windows"):
                margin = study["windows"]["margin"]
                s.input("windows: margin (file units)", margin)
                margins = factor_margins(c, analysis, margin, "windows.margin")
                windows = build_windows(robot, margin=margins, analysis=analysis)
                w = sec.windows_table(s, robot, windows, f"margin {margin:g}", key="margin")
                s.results["windows"] = {**windows.to_dict(), "share_of_joint_space": w["share_of_joint_space"]}
        plan_res = None
        if "plan" in study:
            p = study["plan"]
            with s.section("Planned path"):
                plan_res = sec.planned_path(s, robot, windows, c.to_si(p["start"]), c.to_si(p["goal"]),
                                            planner=p["planner"], time_limit=p["time_limit"], seed=p["seed"],
                                            objective=p["objective"])
                if not plan_res.success:
                    s.finding(f"The plan found no path ({plan_res.status}).", ok=False)
                else:
                    s.finding(f"Planned path: {len(plan_res.path)} waypoints, windows "
                              f"{'proven clear' if plan_res.proven else 'clear at sampled states'}.")
        if "workspace" in study:
            w = study["workspace"]
            with s.section("Workspace"):
                path = plan_res.path if plan_res is not None and plan_res.success else None
                q_view = path[0] if path is not None else np.zeros(c.n)
                sec.workspace(s, robot, w["samples"], w["seed"], q_view=q_view, path=path)
    return run


def run_study(study: dict, out_dir: str | Path, progress=None, quick: bool = False) -> dict:
    """Run a loaded study file into ``out_dir``; returns the results dict also written to
    ``out_dir/results.json``.  ``results["ok"]`` is False when the plan section found no path."""
    _, results = run_study_function(file_study(study), study["name"], study.get("title") or study["name"], out_dir,
                                    quick=quick, progress=progress)
    return results


"""Published values that rmtkit's results are set beside, each with its source.

The core packages (``kin``, ``planning``, ``design``) compute by method and know nothing of who
published what; the history — what a thesis printed, to be compared with what the method gives
when it is made reproducible — lives here, and the comparison is made where it is shown: the
bundled studies and ``rmt windows --learned``.

:data:`PUBLISHED_LEARNED_WINDOWS` holds the published learned-IK error windows (robot name → the
singular joint, 1-based, and its interval in rad, with the source);
:func:`compare_learned_window` sets one beside a report of
:func:`design.learned.learned_window`::

    from design.learned import learned_windows, jsonable_report
    from studies.published import compare_learned_window
    windows, reports = learned_windows(robot)
    published = compare_learned_window(reports[0], robot.name)   # None: nothing published to compare
"""
from __future__ import annotations

from typing import Any, Mapping

__all__ = ["PUBLISHED_LEARNED_WINDOWS", "compare_learned_window"]

#: Published learned-IK windows: robot name → ``joint`` (1-based), ``interval`` (rad) and ``source``.
PUBLISHED_LEARNED_WINDOWS: dict[str, dict[str, Any]] = {
    "scara_rrp": {"joint": 2, "interval": (-0.01, 0.01),
                  "source": "thesis on singularities and reach (docs/machines.md §2): θ2 ∈ [−0.01, 0.01] rad"},
}


def compare_learned_window(report: Mapping, robot_name: str) -> dict | None:
    """The published learned-IK window of ``robot_name`` beside a learned-window report (a dict of
    :func:`design.learned.learned_window`, with or without its ``"data"``).

    Returns None unless a window was published for this robot and the report is a computed
    (``"status": "ok"``) window of a one-joint factor on the published joint.  Otherwise:
    ``joint`` ("q2"), ``interval`` [lo, hi] and ``width`` (half-width) as published (rad),
    ``source``, and the report's own ``ours_intervals``, ``ours_width`` and
    ``ours_over_published`` (its half-width over the published one).
    """
    published = PUBLISHED_LEARNED_WINDOWS.get(robot_name)
    if published is None or report.get("status") != "ok":
        return None
    if list(report["factor"]["joints"]) != [published["joint"]]:
        return None
    lo, hi = published["interval"]
    width = 0.5 * (hi - lo)
    return {"joint": f"q{published['joint']}", "interval": [lo, hi], "width": width, "source": published["source"],
            "ours_intervals": report["intervals"], "ours_width": report["width"],
            "ours_over_published": report["width"] / width}

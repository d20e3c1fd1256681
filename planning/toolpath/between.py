"""Between waypoints: the joint motion from one solved waypoint to the next.

The waypoints of a tool path are checked one by one (:mod:`planning.toolpath.check`); between two of
them the arm moves continuously, and a motion can leave a singular window or the σ_min floor behind
and come back before the next waypoint.  :func:`check_segments` checks every segment between two
consecutive reachable waypoints that are themselves clear of the windows and the floor:

* **singular crossing (a proof).**  det J is a product of exact factors g(q) (:mod:`kin.singular`);
  where one is zero, σ_min is zero.  When a factor has opposite signs at two consecutive waypoints,
  every continuous joint motion between them — whatever the controller does — passes through its
  zero set: the arm is singular on the way.  Only factors of an exact analysis whose zero sets are
  confirmed singular (σ_min vanishes at points sampled on them) are used: :func:`planning.certify.signs.floor_factors`.
* **windows and the σ_min floor along the joint-space segment**, densely and by proof
  (:func:`planning.validate.check_path`, which proves the windows and the floor between its rows).
  Joint limits need no check here: the limit box is convex, so a segment between two waypoints inside
  it stays inside.

A segment whose end waypoint is unreachable or a branch jump is not checked (the waypoint's problem
is reported); a segment starting or ending at a waypoint inside a window or below the floor is
neither (its problem is the waypoint's).  Nothing here prints.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from planning.certify.signs import sign_changes
from planning.validate import check_path

__all__ = ["SEGMENT_KINDS", "SegmentProblem", "check_segments"]

#: problem kinds of a segment, in the order they rank on one segment
SEGMENT_KINDS = ("singular_crossing", "window", "sigma_min")
#: segments checked by one call of check_path (a failure restarts after it: the work stays linear)
_BLOCK = 64


@dataclass(frozen=True)
class SegmentProblem:
    """A problem on the joint motion from waypoint ``index`` to ``index + 1``: ``kind`` (one of
    :data:`SEGMENT_KINDS`), a text, and whether it is proven (``"proven"``) or found at a sampled
    state (``"sampled"``)."""

    index: int
    kind: str
    detail: str
    check: str


def _crossings(robot, factors, Q: np.ndarray, ok: np.ndarray) -> dict[int, SegmentProblem]:
    """Segments (where ``ok``) across which an exact factor changes sign."""
    out: dict[int, SegmentProblem] = {}
    if not factors or len(Q) < 2:
        return out
    chain = robot.chain
    for f, i, g in sign_changes(factors, Q):
        if not ok[i] or i in out:
            continue
        names = ", ".join(f"q{j}" for j in f.joints)
        at = ", ".join(f"q{j} {Q[i, j - 1] / chain.variable_scale[j - 1]:.4g} → "
                       f"{Q[i + 1, j - 1] / chain.variable_scale[j - 1]:.4g}" for j in f.joints)
        out[int(i)] = SegmentProblem(
            int(i), "singular_crossing",
            f"the {f.kind} factor {f.expr} ({names}) is {g[i]:+.3g} at waypoint {i} and {g[i + 1]:+.3g} at "
            f"waypoint {i + 1} ({at}): every continuous joint motion between them passes through its zero "
            f"set, where σ_min = 0 (proven by continuity)", "proven")
    return out


def _dense(robot, Q: np.ndarray, ok: np.ndarray, windows, sigma_min) -> tuple[dict[int, SegmentProblem], str]:
    """Window and floor problems along the joint segments (where ``ok``), by check_path over runs."""
    out: dict[int, SegmentProblem] = {}
    has_windows = windows is not None and bool(windows.windows)
    if not (has_windows or sigma_min is not None):
        return out, "proven"
    check = "proven"
    edges = np.flatnonzero(np.diff(np.concatenate([[0], ok.astype(int), [0]])))
    for a, b in zip(edges[::2], edges[1::2]):       # segments a … b-1 are to be checked: rows a … b
        pos = int(a)
        while pos < b:
            end = min(pos + _BLOCK, int(b))
            res = check_path(robot, Q[pos:end + 1], windows if has_windows else None, sigma_min,
                             limit_tol=math.inf)
            for c in (res.windows_check, res.sigma_check):
                if c == "sampled":
                    check = "sampled"
            v = res.first_violation
            if v is None:
                pos = end
                continue
            i = pos + v.index
            proven = v.detail.endswith("(proven)")
            detail = v.detail.replace(f"rows {v.index} and {v.index + 1}", f"waypoints {i} and {i + 1}")
            detail = detail.replace(f"row {v.index}", f"waypoint {i}").replace("of the segment", "of the joint motion")
            out[i] = SegmentProblem(i, v.kind, detail, "proven" if proven else "sampled")
            pos = i + 1
    return out, check


def check_segments(robot, Q: np.ndarray, checkable: np.ndarray, clear: np.ndarray, windows=None,
                   sigma_min: float | None = None, factors=()) -> tuple[list[SegmentProblem], str]:
    """The problems of the segments between consecutive waypoints (sorted by segment, one per
    segment, ranked by :data:`SEGMENT_KINDS`), and how the windows and floor were decided along them
    (``"proven"`` or ``"sampled"``).

    ``Q`` (N, n) SI; ``checkable`` (N − 1,) which segments to check at all (both ends reachable, no
    branch jump); ``clear`` (N,) waypoints clear of the windows and the floor; ``factors``: exact
    singular factors (:func:`planning.certify.signs.floor_factors`) whose sign changes are crossings.
    """
    Q = np.asarray(Q, dtype=float)
    checkable = np.asarray(checkable, bool)
    found = _crossings(robot, factors, Q, checkable)
    both_clear = checkable & clear[:-1] & clear[1:] if len(Q) > 1 else checkable
    dense, how = _dense(robot, Q, both_clear, windows, sigma_min)
    rank = {k: r for r, k in enumerate(SEGMENT_KINDS)}
    for i, p in dense.items():
        if i not in found or rank[p.kind] < rank[found[i].kind]:
            found[i] = p
    return [found[i] for i in sorted(found)], how

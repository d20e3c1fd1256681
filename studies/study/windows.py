"""Window widths given in the robot file's units, as study files (``[windows] margin``) and the
command line (``--margin``) give them: :func:`factor_margins` turns one margin into an SI width per
singular factor for :func:`planning.windows.build_windows`."""
from __future__ import annotations

import math

import kin
from planning.errors import WindowError

__all__ = ["factor_margins"]


def factor_margins(chain: kin.Chain, analysis, margin: float, what: str = "--margin") -> list[float]:
    """One margin in file units → SI per factor: an angle for factors with a revolute joint, a length
    for purely prismatic ones.  An angle margin is at most π rad (half a turn); a length margin at
    most the largest prismatic joint range.  ``what`` names the margin in the error
    (:class:`planning.errors.WindowError`)."""
    if not (math.isfinite(margin) and margin >= 0):
        raise WindowError(f"{what} {margin} must be a finite number ≥ 0 (robot file units)")
    out = []
    for f in analysis.factors:
        if any(chain.joints[j - 1].is_revolute for j in f.joints):
            m, top, unit = margin * chain.angle_scale, math.pi, chain.angle_unit
            scale = chain.angle_scale
        else:
            m, unit, scale = margin * chain.length_scale, chain.length_unit, chain.length_scale
            top = max(j.limits[1] - j.limits[0] for j in chain.joints if not j.is_revolute)
        if m > top:
            raise WindowError(f"{what} {margin:g} {unit} is too wide for the {f.kind} window; allowed: "
                              f"0 to {top / scale:.6g} {unit}")
        out.append(m)
    return out

"""The singular set as JSON in the robot file's units: what ``rmt singularities --json`` prints and
what a study's ``results.json`` holds under ``"singularities"`` (:func:`singularities_json`)."""
from __future__ import annotations

import kin
from studies.units import joint_value_to_file, unit_names

__all__ = ["singularities_json"]


def singularities_json(robot: kin.Robot, analysis) -> dict:
    """A :class:`kin.singular.SingularityAnalysis` of ``robot`` as a JSON-ready dict: every factor
    (expression, kind, joints, meaning, solutions in SI and, as ``*_file_units``, in the robot
    file's units), the method, derivation, budget and time of the analysis."""
    chain = robot.chain
    factors = []
    for f in analysis.factors:
        d = f.to_dict()
        sol = dict(d["solutions"])
        if sol.get("type") == "values":
            j = sol["joint"]
            sol["values_file_units"] = [joint_value_to_file(chain, j, v) for v in sol["values"]]
        elif sol.get("type") == "manifold":
            sol["ranges_file_units"] = {k: None if r is None else [joint_value_to_file(chain, int(k[1:]), x) for x in r]
                                        for k, r in sol["ranges"].items()}
        factors.append({"expr": d["expr"], "kind": d["kind"], "joints": d["joints"], "meaning": d["meaning"],
                        "solutions": sol, "symbolic": d["symbolic"], "multiplicity": d["multiplicity"],
                        **{k: d[k] for k in ("lost_motion", "kind_shares", "resolution", "points") if k in d}})
    return {"robot": chain.name, "factors": factors, "method": analysis.method, "derivation": analysis.derivation,
            "budget": analysis.budget, "rows": list(analysis.rows),
            "units": {"expr": "q in rad (revolute) or m (prismatic), lengths in m",
                      "values": "rad or m; *_file_units in the robot file's units", **unit_names(chain)},
            "lengths": analysis.lengths, "seconds": analysis.seconds}

"""Naming the factors of the singular set by the geometry of their zero sets."""
from __future__ import annotations

import numpy as np

from kin.singular.determinant import numeric_axes


def _parallel_pairs(Z: np.ndarray, revolute: list[int], tol: float = 1e-6) -> set[tuple[int, int]]:
    out = set()
    for a in range(len(revolute)):
        for b in range(a + 1, len(revolute)):
            i, j = revolute[a], revolute[b]
            if np.linalg.norm(np.cross(Z[i], Z[j])) < tol:
                out.add((i, j))
    return out


def classify(robot, factor_joints: tuple[int, ...], block: str, samples: np.ndarray,
              wc: tuple[int, np.ndarray] | None) -> tuple[str, str]:
    """(kind, one-line meaning) of a factor from its zero-set samples."""
    chain = robot.chain
    n = chain.n
    names = ", ".join(f"q{j}" for j in factor_joints)
    revolute = [i for i, j in enumerate(chain.joints) if j.is_revolute]
    positioning_only = set(robot.task_rows) <= {0, 1, 2}
    point = "wrist centre" if wc is not None else "tool point"
    if all(not chain.joints[j - 1].is_revolute for j in factor_joints):
        return "prismatic", (f"prismatic joint{'s' if len(factor_joints) > 1 else ''} {names} at zero extension: "
                             f"the {point} sits on the axes of the joints before it")
    if len(samples) == 0:
        return "other", f"{names}: no configuration inside the joint limits reaches this factor's zero set"
    generic = robot.random_configurations(1, seed=12345)[0]
    Zg, _ = numeric_axes(robot, generic[None])
    generic_pairs = _parallel_pairs(Zg[0], revolute)
    use = samples[: min(len(samples), 12)]
    Z, O = numeric_axes(robot, use)
    if block in ("wrist", "rotary axes"):
        pairs = set.intersection(*[_parallel_pairs(z, revolute) - generic_pairs for z in Z]) if len(Z) else set()
        pair = " and ".join(f"{i + 1}" for i in sorted(pairs)[0]) if pairs else "of the wrist"
        what = "the wrist" if block == "wrist" else "the rotary head"
        return "wrist", f"axes of joints {pair} become parallel: {what} loses one rotation ({names} singular)"
    votes: dict[str, int] = {}
    for q, z, o in zip(use, Z, O):
        new_pairs = _parallel_pairs(z, revolute) - generic_pairs
        if block == "full" and any(i >= n - 3 and j >= n - 3 for i, j in new_pairs):
            votes["wrist"] = votes.get("wrist", 0) + 1
            continue
        if block == "positioning" and wc is not None:
            k, w_local = wc
            F = np.array(robot.symbolic.frames_function(q, chain.parameter_values)[0])
            w = (F[:, 4 * k:4 * (k + 1)] @ w_local)[:3]
            cols = [np.cross(z[i], w - o[i]) if chain.joints[i].is_revolute else z[i] for i in range(3)]
            M = np.array(cols).T
            idx = [0, 1, 2]
        else:
            M = robot.jacobian(q)[list(robot.task_rows)]
            idx = list(range(n))
        v = np.linalg.svd(M)[2][-1]
        support = [idx[i] for i in range(len(idx)) if abs(v[i]) > 0.05 * np.abs(v).max()]
        # stretched/folded: the lost motion comes from revolute joints whose axes are all parallel
        # to the factor's own joint axes (joints 2 and 3 of an arm, 1 and 2 of a SCARA)
        own = [j - 1 for j in factor_joints]
        parallel = all(chain.joints[i].is_revolute for i in support + own) and all(
            np.linalg.norm(np.cross(z[own[0]], z[i])) < 1e-6 for i in support + own)
        if parallel and 0 not in [j - 1 for j in factor_joints]:
            kind = "boundary" if positioning_only else "elbow"
        elif 0 in support and chain.joints[0].is_revolute:
            kind = "shoulder"
        else:
            kind = "other"
        votes[kind] = votes.get(kind, 0) + 1
    kind = max(votes, key=lambda k: votes[k])
    meaning = {
        "wrist": f"two wrist axes become parallel: the wrist loses one rotation ({names} singular)",
        "elbow": f"arm stretched or folded ({names}): the {point} is at the boundary of its reach and cannot move along the arm",
        "boundary": f"arm stretched or folded ({names}): the {point} is on the workspace boundary",
        "shoulder": f"the {point} lies on the axis of joint 1 (or on its offset surface): joint 1 cannot move it sideways",
        "other": f"joints {names} lose a direction of motion together",
    }[kind]
    return kind, meaning



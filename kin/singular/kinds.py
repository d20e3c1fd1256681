"""Naming the factors of the singular set by the geometry of their zero sets: :func:`classify` for
the exact factors, :func:`name_point` and :func:`lost_motion` for points of a numerically found
component (:mod:`kin.singular.numeric`)."""
from __future__ import annotations

import math

import numpy as np

from kin.singular.determinant import ROW_NAMES, closest_point, numeric_axes


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
    Z, origins = numeric_axes(robot, use)
    if block in ("wrist", "rotary axes"):
        pairs = set.intersection(*[_parallel_pairs(z, revolute) - generic_pairs for z in Z]) if len(Z) else set()
        pair = " and ".join(f"{i + 1}" for i in sorted(pairs)[0]) if pairs else "of the wrist"
        what = "the wrist" if block == "wrist" else "the rotary head"
        return "wrist", f"axes of joints {pair} become parallel: {what} loses one rotation ({names} singular)"
    votes: dict[str, int] = {}
    for q, z, o in zip(use, Z, origins):
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
        "elbow": f"arm stretched or folded ({names}): the {point} is at the boundary of its reach "
                 "and cannot move along the arm",
        "boundary": f"arm stretched or folded ({names}): the {point} is on the workspace boundary",
        "shoulder": f"the {point} lies on the axis of joint 1 (or on its offset surface): "
                    "joint 1 cannot move it sideways",
        "other": f"joints {names} lose a direction of motion together",
    }[kind]
    return kind, meaning


# ---- points of a numerically found component ---------------------------------------------------
def axis_lines(robot, Q: np.ndarray):
    """Joint axes from the Jacobian: directions Z (N, n, 3) and points ``origins`` (N, n, 3) on each
    revolute axis (the point nearest the tool point), tool points P (N, 3) and tool rotations R (N, 3, 3)."""
    T, J = robot.fk_jacobian(Q)
    T, J = T.reshape(-1, 4, 4), J.reshape(-1, 6, robot.n)
    P = T[:, :3, 3]
    rev = robot.chain.revolute_mask
    Z = np.where(rev[None, :, None], np.transpose(J[:, 3:, :], (0, 2, 1)), np.transpose(J[:, :3, :], (0, 2, 1)))
    origins = P[:, None, :] + np.cross(Z, np.transpose(J[:, :3, :], (0, 2, 1)))
    return Z, origins, P, T[:, :3, :3]


def parallel(a: np.ndarray, b: np.ndarray, tol: float = 1e-5) -> bool:
    return float(np.linalg.norm(np.cross(a, b))) < tol


def name_point(robot, q: np.ndarray, own: list[int], generic_parallel: set, wc_frame) -> str:
    """wrist / elbow / boundary / shoulder / prismatic / other for one configuration on the set."""
    chain = robot.chain
    n = chain.n
    rev = [i for i in range(n) if chain.joints[i].is_revolute]
    if all(not chain.joints[j].is_revolute for j in own):
        return "prismatic"
    Z, origins, P, _ = (x[0] for x in axis_lines(robot, q[None]))
    last = [i for i in rev if i >= n - 3]
    for a in range(len(last)):
        for b in range(a + 1, len(last)):
            i, j = last[a], last[b]
            if (i, j) not in generic_parallel and parallel(Z[i], Z[j]):
                return "wrist"
    reach = max(float(np.linalg.norm(P - origins[0])), 1e-9)
    if wc_frame is not None:
        # positioning Jacobian at the wrist centre (the intersection of the last three axes)
        w, dist = closest_point(Z[n - 3], origins[n - 3], Z[n - 2], origins[n - 2])
        if not math.isfinite(dist):
            w, _ = closest_point(Z[n - 2], origins[n - 2], Z[n - 1], origins[n - 1])
        k = n - 3
        M = np.stack([np.cross(Z[i], w - origins[i]) if chain.joints[i].is_revolute else Z[i] for i in range(k)], 1)
        point, idx = w, list(range(k))
        U, _, Vt = np.linalg.svd(M)
        lost = U[:, -1]
    else:
        rows = list(robot.task_rows)
        M = robot.jacobian(q)[rows]
        point, idx = P, list(range(n))
        U, _, Vt = np.linalg.svd(M)
        u6 = np.zeros(6)
        u6[rows] = U[:, -1]
        lost = u6[:3] / np.linalg.norm(u6[:3]) if np.linalg.norm(u6[:3]) > 0.5 else None
    if M.shape[0] == M.shape[1]:
        # square: the null motion is unique — stretched/folded when it comes from parallel axes only
        v = Vt[-1]
        support = [idx[i] for i in range(len(idx)) if abs(v[i]) > 0.05 * np.abs(v).max()]
        group = support + own
        if 0 not in own and all(chain.joints[i].is_revolute for i in group) and all(
                parallel(Z[own[0]], Z[i], 1e-6) for i in group):
            return "boundary" if set(robot.task_rows) <= {0, 1, 2} else "elbow"
        if wc_frame is not None and 0 in support and chain.joints[0].is_revolute:
            return "shoulder"
    if len(own) == 1 and own[0] != 0 and chain.joints[own[0]].is_revolute and lost is not None:
        # stretched/folded about one joint: the lost motion is along the line from its axis to the point
        r = point - origins[own[0]]
        r = r - (r @ Z[own[0]]) * Z[own[0]]
        if np.linalg.norm(r) > 1e-6 * reach and abs(lost @ r) / np.linalg.norm(r) > 0.999:
            return "boundary" if set(robot.task_rows) <= {0, 1, 2} else "elbow"
    if chain.joints[0].is_revolute and np.linalg.norm(np.cross(Z[0], point - origins[0])) < 1e-6 * reach:
        return "shoulder"
    return "other"


NUMERIC_MEANINGS = {
    "wrist": "two wrist axes become parallel: the wrist loses one rotation",
    "elbow": "arm stretched or folded: it cannot move along the arm",
    "boundary": "arm stretched or folded: the tool point is on the workspace boundary",
    "shoulder": "the wrist centre (or tool point) lies on the axis of joint 1 or on its offset surface",
    "prismatic": "prismatic joints at zero extension",
    "other": "the joints lose a direction of motion together (no simpler geometric name)",
}


def lost_motion(robot, Q: np.ndarray, U: np.ndarray) -> dict:
    """The tool-frame direction the arm cannot move in, summarised over a component's points."""
    rows = list(robot.task_rows)
    _, _, _, R = axis_lines(robot, Q)
    u6 = np.zeros((len(Q), 6))
    u6[:, rows] = U
    tool = np.concatenate([np.einsum("nji,nj->ni", R, u6[:, :3]), np.einsum("nji,nj->ni", R, u6[:, 3:])], axis=1)
    _, s, Vt = np.linalg.svd(tool, full_matrices=False)
    d = Vt[0] * np.sign(Vt[0][np.argmax(np.abs(Vt[0]))])
    lin = float(np.mean(np.sum(tool[:, :3] ** 2, axis=1)))
    return {"frame": "tool", "rows": [ROW_NAMES[r] for r in range(6)],
            "direction": np.round(d, 6).tolist(), "consistency": float(s[0] ** 2 / max(np.sum(s ** 2), 1e-300)),
            "linear_share": lin, "type": "linear" if lin > 0.9 else "angular" if lin < 0.1 else "mixed"}

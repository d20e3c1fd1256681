"""Peer models for the kinematics benchmark: the same arm in pinocchio and roboticstoolbox-python.

:mod:`studies.benchmarks.bench_kin` compares rmtkit against two peers built here from a chain's
numeric DH table (standard or modified convention, joint offsets, base and tool):

* pinocchio — a ``pin.Model`` joint by joint (RZ / PZ joints) with an operational frame at the tool
  (:func:`pinocchio_model`), evaluated by one ``computeFrameJacobian`` call (:func:`pinocchio_fk_jacobian`);
* roboticstoolbox-python — a ``DHRobot`` (:func:`rtb_robot`) turned into an ``ETS``
  (:func:`rtb_ets`) whose ``eval``/``jacob0`` run in the toolbox's C++ extension;

each used the fast way its documentation shows, plus the peers' evaluation loops that the benchmark
times (:func:`pinocchio_loops`, :func:`rtb_loops`) and evaluates for agreement (:func:`pinocchio_batch`,
:func:`rtb_batch`), and an independent reference: a central finite-difference geometric Jacobian
(:func:`fd_jacobian`, with the
rotation log :func:`_log_so3`).  pinocchio and roboticstoolbox are imported only inside the functions
that need them (the optional ``bench`` extra).
"""
from __future__ import annotations

import math
from typing import Callable, NamedTuple

import numpy as np


# ---- small numpy transforms (independent of kin.transforms) ----------------------------------
def _rx(a: float) -> np.ndarray:
    c, s = math.cos(a), math.sin(a)
    return np.array([[1.0, 0, 0, 0], [0, c, -s, 0], [0, s, c, 0], [0, 0, 0, 1.0]])


def _rz(a: float) -> np.ndarray:
    c, s = math.cos(a), math.sin(a)
    return np.array([[c, -s, 0, 0], [s, c, 0, 0], [0, 0, 1.0, 0], [0, 0, 0, 1.0]])


def _tx(x: float) -> np.ndarray:
    T = np.eye(4)
    T[0, 3] = x
    return T


def _tz(z: float) -> np.ndarray:
    T = np.eye(4)
    T[2, 3] = z
    return T


def dh_pre_post(joint_type: str, convention: str, a: float, alpha: float, d: float, theta: float):
    """Split one DH row into fixed transforms around the joint's own motion: A_i = pre · M(q) · post.

    M(q) is Rz(q) (revolute) or Tz(q) (prismatic), the motion of a pinocchio RZ / PZ joint.

    * standard:  A = Rz(θ)·Tz(d)·Tx(a)·Rx(α)
        revolute  θ = q + theta:  pre = Rz(theta),        post = Tz(d)·Tx(a)·Rx(α)
                                  (Rz(q) and Tz(d) commute)
        prismatic d = q + d:      pre = Rz(theta)·Tz(d),  post = Tx(a)·Rx(α)
    * modified:  A = Rx(α)·Tx(a)·Rz(θ)·Tz(d)   (the row holds a_{i-1}, α_{i-1})
        revolute:                 pre = Rx(α)·Tx(a)·Rz(theta),        post = Tz(d)
        prismatic:                pre = Rx(α)·Tx(a)·Rz(theta)·Tz(d),  post = I
    """
    if convention == "standard":
        if joint_type == "revolute":
            return _rz(theta), _tz(d) @ _tx(a) @ _rx(alpha)
        return _rz(theta) @ _tz(d), _tx(a) @ _rx(alpha)
    if convention == "modified":
        head = _rx(alpha) @ _tx(a) @ _rz(theta)
        if joint_type == "revolute":
            return head, _tz(d)
        return head @ _tz(d), np.eye(4)
    raise ValueError(f"convention {convention!r} unknown")


def _segments(chain):
    """Per joint (type, pre, post) from the chain's numeric DH table."""
    table = chain.dh_table()
    return [(j.type, *dh_pre_post(j.type, chain.convention, *row)) for j, row in zip(chain.joints, table)]


# ---- peer models ---------------------------------------------------------------------------
def pinocchio_model(chain):
    """A ``pin.Model`` of the chain, joint by joint, plus the id of an operational frame at the tool.

    Joint i's placement in its parent joint's frame is post_{i-1} · pre_i (post_0 = base), so that
    pinocchio's joint frame i is base · A_1 ⋯ A_{i-1} · pre_i · M(q_i); the tool frame sits at
    post_n · tool in the last joint's frame.  World frame = rmtkit's base (reference) frame.
    """
    import pinocchio as pin

    model = pin.Model()
    model.name = chain.name
    parent, carry = 0, chain.base.matrix
    for i, ((jtype, pre, post), (lo, hi)) in enumerate(zip(_segments(chain), chain.limits), 1):
        jm = pin.JointModelRZ() if jtype == "revolute" else pin.JointModelPZ()
        big = np.array([1e3])
        parent = model.addJoint(parent, jm, pin.SE3(carry @ pre), f"joint{i}", big, big,
                                np.array([lo]), np.array([hi]))
        carry = post
    fid = model.addFrame(pin.Frame("tool", parent, 0, pin.SE3(carry @ chain.tool.matrix), pin.FrameType.OP_FRAME))
    return model, fid


def pinocchio_fk_jacobian(model, data, fid, q):
    """(T 4×4, J 6×n) at the tool frame, the fast way pinocchio's docs show: one
    ``computeFrameJacobian(model, data, q, frame, LOCAL_WORLD_ALIGNED)`` (rows vx vy vz wx wy wz),
    which also updates the frame's placement ``data.oMf[frame]``."""
    import pinocchio as pin

    J = pin.computeFrameJacobian(model, data, q, fid, pin.ReferenceFrame.LOCAL_WORLD_ALIGNED)
    return data.oMf[fid].homogeneous, J


def rtb_robot(chain):
    """A ``roboticstoolbox.DHRobot`` of the chain (standard or modified links, offsets, base, tool)."""
    import roboticstoolbox as rtb
    from spatialmath import SE3

    links = []
    mod = chain.convention == "modified"
    for j, (a, alpha, d, theta), (lo, hi) in zip(chain.joints, chain.dh_table(), chain.limits):
        qlim = [lo, hi]
        if j.type == "revolute":
            cls = rtb.RevoluteMDH if mod else rtb.RevoluteDH
            links.append(cls(d=d, a=a, alpha=alpha, offset=theta, qlim=qlim))
        else:
            cls = rtb.PrismaticMDH if mod else rtb.PrismaticDH
            links.append(cls(theta=theta, a=a, alpha=alpha, offset=d, qlim=qlim))
    return rtb.DHRobot(links, name=chain.name, base=SE3(chain.base.matrix, check=False),
                       tool=SE3(chain.tool.matrix, check=False))


def rtb_ets(chain):
    """The chain as a roboticstoolbox ``ETS`` (base, DH links, tool): its ``eval`` and ``jacob0`` run
    in the toolbox's C++ extension, the fast path (the ``DHRobot`` methods are pure Python)."""
    return rtb_robot(chain).ets()


# ---- evaluation loops and batches ----------------------------------------------------------
class PeerLoops(NamedTuple):
    """Zero-argument callables over the rows of Q, for timing a peer (one thread, a Python loop
    around the peer's compiled calls, the lookups hoisted out)."""

    fk_j_manip: Callable[[], np.ndarray]  # FK + Jacobian + |det J| of every row → (N,)
    fk_j: Callable[[], None]              # FK + Jacobian of every row
    single_fk_j: Callable[[], tuple]      # one FK + Jacobian call at Q[0]
    fk_batch: Callable[[], np.ndarray] | None = None  # the peer's own batch FK, where it has one


def pinocchio_loops(chain, Q: np.ndarray) -> PeerLoops:
    """pinocchio: ``computeFrameJacobian`` (LOCAL_WORLD_ALIGNED), pose from the updated frame placement."""
    import pinocchio as pin

    model, fid = pinocchio_model(chain)
    data = model.createData()
    LWA = pin.ReferenceFrame.LOCAL_WORLD_ALIGNED
    det, cfj = np.linalg.det, pin.computeFrameJacobian
    M = data.oMf[fid]  # a reference, updated in place by computeFrameJacobian

    def loop_full():
        res = np.empty(len(Q))
        for k in range(len(Q)):
            J = cfj(model, data, Q[k], fid, LWA)
            M.homogeneous
            res[k] = abs(det(J))
        return res

    def loop_fkj():
        for k in range(len(Q)):
            cfj(model, data, Q[k], fid, LWA)
            M.homogeneous

    q0 = Q[0]
    return PeerLoops(loop_full, loop_fkj, lambda: (cfj(model, data, q0, fid, LWA), M.homogeneous))


def rtb_loops(chain, Q: np.ndarray) -> PeerLoops:
    """roboticstoolbox through its C++ ETS path: ``ets.eval`` (also batch) and ``ets.jacob0``."""
    ets = rtb_ets(chain)
    ev, jac, det = ets.eval, ets.jacob0, np.linalg.det

    def loop_full():
        res = np.empty(len(Q))
        for k in range(len(Q)):
            ev(Q[k])
            res[k] = abs(det(jac(Q[k])))
        return res

    def loop_fkj():
        for k in range(len(Q)):
            ev(Q[k])
            jac(Q[k])

    q0 = Q[0]
    return PeerLoops(loop_full, loop_fkj, lambda: (ev(q0), jac(q0)), lambda: ev(Q))


def pinocchio_batch(chain, Q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """pinocchio's tool poses (N, 4, 4) and Jacobians (N, 6, n) at configurations Q (N, n)."""
    model, fid = pinocchio_model(chain)
    data = model.createData()
    pairs = [pinocchio_fk_jacobian(model, data, fid, q) for q in Q]
    return np.array([p[0] for p in pairs]), np.array([p[1] for p in pairs])


def rtb_batch(chain, Q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """roboticstoolbox's tool poses (N, 4, 4) (batch ``ets.eval``) and Jacobians (N, 6, n) (``ets.jacob0``)."""
    ets = rtb_ets(chain)
    return np.asarray(ets.eval(Q)).reshape(-1, 4, 4), np.array([ets.jacob0(q) for q in Q])


# ---- finite differences ------------------------------------------------------------------
def _log_so3(R: np.ndarray) -> np.ndarray:
    """Rotation vectors of rotation matrices (..., 3, 3); robust for small angles (not near π)."""
    w = 0.5 * np.stack([R[..., 2, 1] - R[..., 1, 2], R[..., 0, 2] - R[..., 2, 0], R[..., 1, 0] - R[..., 0, 1]], -1)
    s = np.linalg.norm(w, axis=-1)
    c = 0.5 * (np.trace(R, axis1=-2, axis2=-1) - 1.0)
    th = np.arctan2(s, c)
    k = np.where(s > 1e-300, th / np.where(s > 1e-300, s, 1.0), 1.0)
    return w * k[..., None]


def fd_jacobian(fk_batch, Q: np.ndarray, h: float, revolute: np.ndarray | None = None) -> np.ndarray:
    """Central-difference geometric Jacobian (N, 6, n) from a batch FK (M, n) → (M, 4, 4).

    Position rows: (p(q + h e_i) − p(q − h e_i)) / 2h; angular rows: log(R(q + h e_i) R(q − h e_i)ᵀ) / 2h.
    """
    N, n = Q.shape
    E = np.eye(n) * h
    Qp = (Q[:, None, :] + E[None]).reshape(-1, n)
    Qm = (Q[:, None, :] - E[None]).reshape(-1, n)
    Tp, Tm = fk_batch(Qp).reshape(N, n, 4, 4), fk_batch(Qm).reshape(N, n, 4, 4)
    J = np.empty((N, 6, n))
    J[:, :3, :] = ((Tp[..., :3, 3] - Tm[..., :3, 3]) / (2 * h)).transpose(0, 2, 1)
    W = _log_so3(Tp[..., :3, :3] @ Tm[..., :3, :3].swapaxes(-1, -2)) / (2 * h)
    J[:, 3:, :] = W.transpose(0, 2, 1)
    return J

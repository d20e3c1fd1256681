"""Inverse dynamics of a chain in CasADi: recursive Newton–Euler, τ(q, q̇, q̈; p).

The graph is symbolic in the joint positions, velocities and accelerations and in the design
parameters p, like the kinematics of :mod:`kin.symbolic`, so every function can be differentiated
with respect to any of them.

Each DH row is split around the joint's own motion, A_i = pre_i · M(q_i) · post_i, with M(q) = Rz(q)
(revolute) or Tz(q) (prismatic), both conventions alike:

* standard  A = Rz(θ)·Tz(d)·Tx(a)·Rx(α):  revolute pre = Rz(theta), post = Tz(d)·Tx(a)·Rx(α);
  prismatic pre = Rz(theta)·Tz(d), post = Tx(a)·Rx(α)
* modified  A = Rx(α)·Tx(a)·Rz(θ)·Tz(d):  revolute pre = Tx(a)·Rx(α)·Rz(theta), post = Tz(d);
  prismatic pre = Tx(a)·Rx(α)·Rz(theta)·Tz(d), post = I

The recursion runs in the joint frames J_i = base·A_1⋯A_{i−1}·pre_i·M(q_i), whose z axis is joint i's
axis through its origin (Craig's outward/inward Newton–Euler).  Body i (DH frame i = J_i·post_i)
and, on the last joint, the payload (tool frame = J_n·post_n·tool) are carried into J_i.  A body
without inertial data (None) is massless.  Gravity ``chain.gravity`` is given in the base placement's
frame and rotated into frame 0 by ``chain.base``.

Per joint, τ_i adds the motor (rotor) inertia ``motor_inertia·q̈_i`` and the friction
``viscous·q̇_i + coulomb·sign(q̇_i)``.  The Coulomb term uses sign (sign(0) = 0), so τ is not smooth
(not even continuous) at q̇_i = 0; the payload's motor inertia and friction are not used.  Derived:
the mass matrix M(q) (motor inertias on its diagonal), the gravity vector g(q) and the Coriolis and
centrifugal vector c(q, q̇) = τ(q, q̇, 0) − g(q) without friction; so τ = M q̈ + c + g + friction.
"""
from __future__ import annotations

from functools import cached_property

import casadi as ca
import numpy as np

from kin.chain import Chain
from kin.errors import DynamicsError
from kin.symbolic import _cs, _rz_tz_cs, _tx_rx
from kin.vmmap import map_rows

__all__ = ["InverseDynamics", "has_inertia"]

_Z = ca.DM([0.0, 0.0, 1.0])


def has_inertia(chain: Chain) -> bool:
    """True when some body of the chain (a link or the payload) has a mass."""
    bodies = [j.inertia for j in chain.joints] + [chain.payload]
    return any(b is not None and b.mass > 0 for b in bodies)


def _pre_post(chain: Chain, joint, val) -> tuple[ca.SX, ca.SX]:
    """The fixed transforms around joint's motion: A = pre · M(q) · post (symbolic in p)."""
    a, alpha, d, theta = val(joint.a), val(joint.alpha), val(joint.d), val(joint.theta)
    ct, st = _cs(theta)
    if chain.convention == "modified":
        head = _tx_rx(a, alpha)        # Rx(α)·Tx(a) == Tx(a)·Rx(α)
        if joint.is_revolute:
            return head @ _rz_tz_cs(ct, st, 0.0), _rz_tz_cs(1.0, 0.0, d)
        return head @ _rz_tz_cs(ct, st, d), ca.SX.eye(4)
    tail = _tx_rx(a, alpha)
    if joint.is_revolute:
        return _rz_tz_cs(ct, st, 0.0), _rz_tz_cs(1.0, 0.0, d) @ tail
    return _rz_tz_cs(ct, st, d), tail


def _carried(inertia, T: ca.SX) -> tuple[float, ca.SX, ca.SX] | None:
    """(mass, com, inertia about the com) of a body given in frame T, in the joint frame; None if massless."""
    if inertia is None or inertia.mass == 0.0:
        return None
    R, o = T[:3, :3], T[:3, 3]
    com = R @ ca.DM(inertia.com) + o
    return inertia.mass, com, R @ ca.DM(inertia.tensor) @ R.T


class InverseDynamics:
    """The Newton–Euler graph of one chain and its :class:`casadi.Function` wrappers.

    Attributes (CasADi SX): ``q``, ``qd``, ``qdd`` (n,), ``p`` (n_p,), ``tau`` (n,).
    Functions: :attr:`tau_function` (q, qd, qdd, p) → tau, :attr:`mass_matrix_function` (q, p) → M,
    :attr:`gravity_function` (q, p) → g, :attr:`coriolis_function` (q, qd, p) → c.
    """

    def __init__(self, chain: Chain):
        if not has_inertia(chain):
            raise DynamicsError(f"{chain.name}: no body has inertial data (a mass); inverse dynamics needs "
                                f"Joint.inertia or Chain.payload (kin.dynamics.LinkInertia)")
        self.chain = chain
        self.n = n = chain.n
        self.q = ca.SX.sym("q", n)
        self.c = ca.SX.sym("c", n)     # cos q and sin q given: the compiled kernel's inputs
        self.s = ca.SX.sym("s", n)
        self.qd = ca.SX.sym("qd", n)
        self.qdd = ca.SX.sym("qdd", n)
        self.p = ca.SX.sym("p", len(chain.parameters))
        names = list(chain.parameters)

        def val(v):
            return self.p[names.index(v)] if isinstance(v, str) else float(v)

        self._pre, self._post, self._bodies = [], [], []
        for k, j in enumerate(chain.joints):
            pre, post = _pre_post(chain, j, val)
            self._pre.append(pre)
            self._post.append(post)
            bodies = [_carried(j.inertia, post)]
            if k == n - 1:
                bodies.append(_carried(chain.payload, post @ ca.SX(chain.tool.matrix)))
            self._bodies.append([b for b in bodies if b is not None])
        R0 = chain.base.matrix[:3, :3]
        self.g0 = R0.T @ np.asarray(chain.gravity, dtype=float)     # gravity in frame 0
        inert = [j.inertia for j in chain.joints]
        self._motor = np.array([0.0 if b is None else b.motor_inertia for b in inert])
        self._viscous = np.array([0.0 if b is None else b.viscous for b in inert])
        self._coulomb = np.array([0.0 if b is None else b.coulomb for b in inert])
        self.tau = self.rnea(self.q, self.qd, self.qdd, self.g0, friction=True)

    def rnea(self, q, qd, qdd, g0, friction: bool = True, cs: tuple | None = None) -> ca.SX:
        """τ (n,) for the given (symbolic or numeric) q, q̇, q̈ and gravity g0 (frame 0); motor inertia
        always, friction when ``friction``; ``cs``: (cos q, sin q) to use instead of computing them
        (q then read for prismatic joints only)."""
        n = self.n
        w, wd, vd = ca.SX.zeros(3), ca.SX.zeros(3), ca.SX(-ca.DM(g0))
        Rs, Ps, Fs, Ns = [], [], [], []
        for i, j in enumerate(self.chain.joints):
            X = (self._post[i - 1] if i else ca.SX.eye(4)) @ self._pre[i]
            if j.is_revolute:
                cq, sq = (cs[0][i], cs[1][i]) if cs is not None else (ca.cos(q[i]), ca.sin(q[i]))
                X = X @ _rz_tz_cs(cq, sq, 0.0)
            else:
                X = X @ _rz_tz_cs(1.0, 0.0, q[i])
            R, P = X[:3, :3], X[:3, 3]
            Rt = R.T
            vd = Rt @ (ca.cross(wd, P) + ca.cross(w, ca.cross(w, P)) + vd)
            if j.is_revolute:
                wr = Rt @ w
                w = wr + qd[i] * _Z
                wd = Rt @ wd + ca.cross(wr, qd[i] * _Z) + qdd[i] * _Z
            else:
                w, wd = Rt @ w, Rt @ wd
                vd = vd + 2 * ca.cross(w, qd[i] * _Z) + qdd[i] * _Z
            F, N = ca.SX.zeros(3), ca.SX.zeros(3)
            for m, c, Ic in self._bodies[i]:
                Fk = m * (vd + ca.cross(wd, c) + ca.cross(w, ca.cross(w, c)))
                F = F + Fk
                N = N + Ic @ wd + ca.cross(w, Ic @ w) + ca.cross(c, Fk)
            Rs.append(R)
            Ps.append(P)
            Fs.append(F)
            Ns.append(N)
        tau = [None] * n
        f, nm = ca.SX.zeros(3), ca.SX.zeros(3)
        for i in range(n - 1, -1, -1):
            if i < n - 1:
                Rf = Rs[i + 1] @ f
                nm = Ns[i] + Rs[i + 1] @ nm + ca.cross(Ps[i + 1], Rf)
                f = Fs[i] + Rf
            else:
                f, nm = Fs[i], Ns[i]
            t = nm[2] if self.chain.joints[i].is_revolute else f[2]
            t = t + self._motor[i] * qdd[i]
            if friction:
                t = t + self._viscous[i] * qd[i] + self._coulomb[i] * ca.sign(qd[i])
            tau[i] = t
        return ca.vertcat(*tau)

    # ---- derived quantities -------------------------------------------------------------------
    @cached_property
    def mass_matrix(self) -> ca.SX:
        """M(q) (n×n): column i is τ with q̈ = e_i, no velocity, no gravity (symmetrised)."""
        zero = ca.DM.zeros(self.n)
        cols = [self.rnea(self.q, zero, ca.DM(np.eye(self.n)[i]), np.zeros(3), friction=False)
                for i in range(self.n)]
        M = ca.horzcat(*cols)
        return (M + M.T) / 2

    @cached_property
    def gravity(self) -> ca.SX:
        """g(q) (n,): τ at rest."""
        zero = ca.DM.zeros(self.n)
        return self.rnea(self.q, zero, zero, self.g0, friction=False)

    @cached_property
    def coriolis(self) -> ca.SX:
        """c(q, q̇) (n,) = τ(q, q̇, 0) − g(q), friction left out."""
        zero = ca.DM.zeros(self.n)
        return self.rnea(self.q, self.qd, zero, np.zeros(3), friction=False)

    @cached_property
    def path_coefficients(self) -> tuple[ca.SX, ca.SX, ca.SX]:
        """(A, B, C) (n,) each, symbolic in q, q′ = ``qd`` and q″ = ``qdd`` read as path derivatives:
        along a path q(s) traversed forwards (ṡ ≥ 0), τ = A·s̈ + B·ṡ² + C + viscous·q′·ṡ with
        A = M(q)·q′, B = M(q)·q″ + c(q, q′) (Coriolis and centrifugal at unit path speed), C = g(q) +
        coulomb·sign(q′) (the sign of q̇ is the sign of q′ while ṡ > 0).  Motor inertias are in M; the
        viscous term, not linear in ṡ², is left to the caller (:attr:`viscous`)."""
        zero = ca.DM.zeros(self.n)
        g0 = np.zeros(3)
        A = self.rnea(self.q, zero, self.qd, g0, friction=False)
        B = self.rnea(self.q, self.qd, self.qdd, g0, friction=False)
        C = self.gravity + self._coulomb * ca.sign(self.qd)
        return A, B, C

    @property
    def viscous(self) -> np.ndarray:
        """Viscous friction coefficients per joint (n,) (N·m·s/rad or N·s/m)."""
        return self._viscous.copy()

    # ---- casadi.Function wrappers --------------------------------------------------------------
    @cached_property
    def tau_function(self) -> ca.Function:
        """inverse_dynamics(q, qd, qdd, p) → tau (n,)."""
        return ca.Function("inverse_dynamics", [self.q, self.qd, self.qdd, self.p], [self.tau],
                           ["q", "qd", "qdd", "p"], ["tau"])

    @cached_property
    def mass_matrix_function(self) -> ca.Function:
        """mass_matrix(q, p) → M (n×n)."""
        return ca.Function("mass_matrix", [self.q, self.p], [self.mass_matrix], ["q", "p"], ["M"])

    @cached_property
    def gravity_function(self) -> ca.Function:
        """gravity(q, p) → g (n,)."""
        return ca.Function("gravity", [self.q, self.p], [self.gravity], ["q", "p"], ["g"])

    @cached_property
    def coriolis_function(self) -> ca.Function:
        """coriolis(q, qd, p) → c (n,)."""
        return ca.Function("coriolis", [self.q, self.qd, self.p], [self.coriolis], ["q", "qd", "p"], ["c"])

    @cached_property
    def path_coefficients_function(self) -> ca.Function:
        """path_coefficients(q, d1, d2, p) → ABC (n×3): the columns A, B, C of :attr:`path_coefficients`."""
        return ca.Function("path_coefficients", [self.q, self.qd, self.qdd, self.p],
                           [ca.horzcat(*self.path_coefficients)], ["q", "d1", "d2", "p"], ["ABC"])

    @cached_property
    def cs_functions(self) -> dict[str, ca.Function]:
        """The five functions with cos q and sin q as inputs (``c``, ``s``; q read for prismatic joints
        only), for the compiled kernel, which computes them vectorised: ``tau`` (c, s, q, qd, qdd, p),
        ``mass_matrix`` (c, s, q, p), ``gravity`` (c, s, q, p), ``coriolis`` (c, s, q, qd, p),
        ``path_coefficients`` (c, s, q, d1, d2, p); the same operations as the functions above
        otherwise."""
        cs = (self.c, self.s)
        zero, g0 = ca.DM.zeros(self.n), np.zeros(3)

        def rnea(qd, qdd, grav, friction=False):
            return self.rnea(self.q, qd, qdd, grav, friction, cs)

        M = ca.horzcat(*[rnea(zero, ca.DM(np.eye(self.n)[i]), g0) for i in range(self.n)])
        grav = rnea(zero, zero, self.g0)
        path = ca.horzcat(rnea(zero, self.qd, g0), rnea(self.qd, self.qdd, g0),
                          grav + self._coulomb * ca.sign(self.qd))
        head, p = [self.c, self.s, self.q], [self.p]
        qd, qdd = [self.qd], [self.qd, self.qdd]
        return {"tau": ca.Function("tau_cs", head + qdd + p, [rnea(self.qd, self.qdd, self.g0, True)]),
                "mass_matrix": ca.Function("mass_matrix_cs", head + p, [(M + M.T) / 2]),
                "gravity": ca.Function("gravity_cs", head + p, [grav]),
                "coriolis": ca.Function("coriolis_cs", head + qd + p, [rnea(self.qd, zero, g0)]),
                "path_coefficients": ca.Function("path_coefficients_cs", head + qdd + p, [path])}

    # ---- batches --------------------------------------------------------------------------------
    def evaluate(self, f: ca.Function, args: list[np.ndarray]) -> np.ndarray:
        """Evaluate ``f`` on rows: each argument (N, k) → (N, *output shape), through ``f.map``
        (serial, sizes rounded up to powers of two so that few mapped functions are built)."""
        out = np.empty((len(args[0]), *f.size_out(0)))
        maps = self.__dict__.setdefault("_maps", {})
        for s, k, (r,) in map_rows(f, args, maps):
            out[s:s + k] = r
        return out

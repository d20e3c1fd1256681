"""Inverse dynamics (kin.dynamics.rnea, Robot.inverse_dynamics / mass_matrix / gravity) against
independent values: the planar 2R closed form, a world-frame numpy Newton–Euler written here (the
wrench of all outboard bodies projected on each joint axis, no recursion over forces), pinocchio
(rnea, crba, computeGeneralizedGravity), and the identities M = Mᵀ ≻ 0, τ = M q̈ + c + g, and a
design-parameter derivative by finite differences."""
import dataclasses
import math

import casadi as ca
import numpy as np
import pytest

import kin
from kin.chain import Chain, Joint, Placement
from kin.dynamics import LinkInertia
from kin.dynamics.rnea import InverseDynamics
from kin.errors import ConfigurationError, DynamicsError

DESIGN_2R = "studies/tasks/robots/planar_2r_design.toml"


def rel_err(a, b) -> float:
    a, b = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
    return float(np.abs(a - b).max() / max(1.0, np.abs(b).max()))


# ---- the planar 2R closed form ---------------------------------------------------------------
def rods_2r(m1=2.0, m2=1.5, g=9.81):
    """Two uniform rods along x_k, ending at DH frame k's origin (com (−L/2, 0, 0)); gravity −y."""
    chain = kin.load_chain(DESIGN_2R)
    L = chain.parameter_values
    rods = [LinkInertia(m, (-Lk / 2, 0, 0), (0.0, m * Lk**2 / 12, m * Lk**2 / 12, 0, 0, 0))
            for m, Lk in zip((m1, m2), L)]
    joints = tuple(dataclasses.replace(j, inertia=r) for j, r in zip(chain.joints, rods))
    return dataclasses.replace(chain, joints=joints, gravity=(0.0, -g, 0.0))


def closed_form_2r(q, qd, m1, m2, L1, L2, g):
    """Lagrange's equations of two rods: M, c, g (the textbook planar 2R)."""
    l1, l2, I1, I2 = L1 / 2, L2 / 2, m1 * L1**2 / 12, m2 * L2**2 / 12
    c2, s2 = math.cos(q[1]), math.sin(q[1])
    M = np.array([[I1 + I2 + m1 * l1**2 + m2 * (L1**2 + l2**2 + 2 * L1 * l2 * c2), I2 + m2 * (l2**2 + L1 * l2 * c2)],
                  [I2 + m2 * (l2**2 + L1 * l2 * c2), I2 + m2 * l2**2]])
    h = m2 * L1 * l2 * s2
    c = np.array([-h * (2 * qd[0] * qd[1] + qd[1]**2), h * qd[0]**2])
    g2 = m2 * g * l2 * math.cos(q[0] + q[1])
    gv = np.array([(m1 * l1 + m2 * L1) * g * math.cos(q[0]) + g2, g2])
    return M, c, gv


def test_planar_2r_matches_the_closed_form():
    m1, m2, g = 2.0, 1.5, 9.81
    robot = kin.Robot(rods_2r(m1, m2, g), backend="vm")
    L1, L2 = robot.chain.parameter_values
    rng = np.random.default_rng(1)
    Q, QD, QDD = (rng.uniform(-3, 3, (7, 2)) for _ in range(3))
    tau = robot.inverse_dynamics(Q, QD, QDD)
    M, G, C = robot.mass_matrix(Q), robot.gravity(Q), robot.coriolis(Q, QD)
    for k in range(len(Q)):
        Mr, cr, gr = closed_form_2r(Q[k], QD[k], m1, m2, L1, L2, g)
        assert rel_err(M[k], Mr) < 1e-12 and rel_err(G[k], gr) < 1e-12 and rel_err(C[k], cr) < 1e-12
        assert rel_err(tau[k], Mr @ QDD[k] + cr + gr) < 1e-12
    # one configuration: no batch axis
    assert robot.inverse_dynamics(Q[0], QD[0], QDD[0]).shape == (2,) and robot.mass_matrix(Q[0]).shape == (2, 2)
    np.testing.assert_allclose(robot.gravity(Q[0]), G[0], rtol=1e-14)
    assert robot.mass_matrix(np.zeros((0, 2))).shape == (0, 2, 2)


# ---- random chains ---------------------------------------------------------------------------
def random_rotation(rng):
    Q, R = np.linalg.qr(rng.normal(size=(3, 3)))
    Q = Q * np.sign(np.diag(R))
    return Q if np.linalg.det(Q) > 0 else -Q


def random_inertia(rng, motor=False):
    """A valid body: a box's principal moments in a random orientation, a random com."""
    m = rng.uniform(0.2, 5.0)
    a, b, c = rng.uniform(0.05, 0.6, 3)
    R = random_rotation(rng)
    t = R @ np.diag([m / 12 * (b * b + c * c), m / 12 * (a * a + c * c), m / 12 * (a * a + b * b)]) @ R.T
    extra = {}
    if motor:
        extra = dict(motor_inertia=rng.uniform(0, 0.5), viscous=rng.uniform(0, 2), coulomb=rng.uniform(0, 3))
    return LinkInertia(m, tuple(rng.uniform(-0.3, 0.3, 3)), (t[0, 0], t[1, 1], t[2, 2], t[0, 1], t[0, 2], t[1, 2]),
                       **extra)


def random_chain(seed: int, convention: str, n: int = 5, motor: bool = False) -> Chain:
    rng = np.random.default_rng(seed)
    joints = []
    for k in range(n):
        typ = "prismatic" if rng.random() < 0.35 else "revolute"
        a, alpha, d, theta = rng.uniform(-0.5, 0.5), rng.uniform(-3, 3), rng.uniform(-0.5, 0.5), rng.uniform(-3, 3)
        lim = (-3.0, 3.0) if typ == "revolute" else (-1.0, 1.0)
        inertia = None if k == 1 and seed % 2 else random_inertia(rng, motor)     # some chains: a massless body
        joints.append(Joint(typ, a, alpha, d, theta, lim, inertia=inertia))
    base = Placement(tuple(rng.uniform(-1, 1, 3)), tuple(rng.uniform(-3, 3, 3)))
    tool = Placement(tuple(rng.uniform(-0.3, 0.3, 3)), tuple(rng.uniform(-3, 3, 3)))
    g = rng.normal(size=3)
    return Chain(f"random{seed}", tuple(joints), convention, base=base, tool=tool, payload=random_inertia(rng),
                 gravity=tuple(9.81 * g / np.linalg.norm(g)))


def _rx(a):
    c, s = math.cos(a), math.sin(a)
    return np.array([[1.0, 0, 0, 0], [0, c, -s, 0], [0, s, c, 0], [0, 0, 0, 1]])


def _rz(a):
    c, s = math.cos(a), math.sin(a)
    return np.array([[c, -s, 0, 0], [s, c, 0, 0], [0, 0, 1.0, 0], [0, 0, 0, 1]])


def _t(x, y, z):
    T = np.eye(4)
    T[:3, 3] = x, y, z
    return T


def numpy_rnea(chain: Chain, q, qd, qdd, friction=True):
    """Textbook Newton–Euler in the base placement's (world) frame, written independently: frames by
    plain DH products, each body's (ω, ω̇, a reference point and its acceleration) joint by joint,
    then τ_j = axis_j · (the summed wrench of bodies j..n about a point on axis j)."""
    table = chain.dh_table()
    T = chain.base.matrix
    w, wd = np.zeros(3), np.zeros(3)
    ref, acc = np.zeros(3), -np.asarray(chain.gravity)      # a point of the moving body and its acceleration
    axes, bodies = [], []

    def accel(x):
        r = x - ref
        return acc + np.cross(wd, r) + np.cross(w, np.cross(w, r))

    for k, (j, (a, alpha, d, theta)) in enumerate(zip(chain.joints, table)):
        rev = j.is_revolute
        th, dd = (theta + q[k], d) if rev else (theta, d + q[k])
        if chain.convention == "modified":
            T = T @ _rx(alpha) @ _t(a, 0, 0)
            z, o = T[:3, 2].copy(), T[:3, 3].copy()
            T = T @ _rz(th) @ _t(0, 0, dd)
        else:
            z, o = T[:3, 2].copy(), T[:3, 3].copy()
            T = T @ _rz(th) @ _t(0, 0, dd) @ _t(a, 0, 0) @ _rx(alpha)
        a_o = accel(o)
        if rev:       # o stays on the axis in both bodies
            wd = wd + qdd[k] * z + np.cross(w, qd[k] * z)
            w = w + qd[k] * z
            ref, acc = o, a_o
        else:         # relative translation along z (fixed in the parent): Coriolis 2 ω × v_rel
            ref, acc = o, a_o + qdd[k] * z + 2 * np.cross(w, qd[k] * z)
        axes.append((rev, z, o))
        items = [(j.inertia, T)] + ([(chain.payload, T @ chain.tool.matrix)] if k == chain.n - 1 else [])
        wrench_f, wrench_n, at = np.zeros(3), np.zeros(3), o
        for li, Tb in items:
            if li is None:
                continue
            R = Tb[:3, :3]
            c = Tb[:3, :3] @ np.array(li.com) + Tb[:3, 3]
            Iw = R @ li.tensor @ R.T
            F = li.mass * accel(c)
            wrench_f += F
            wrench_n += Iw @ wd + np.cross(w, Iw @ w) + np.cross(c - at, F)
        bodies.append((wrench_f, wrench_n, at))
    tau = np.zeros(chain.n)
    for jdx, (rev, z, o) in enumerate(axes):
        f = sum(b[0] for b in bodies[jdx:])
        n_o = sum(b[1] + np.cross(b[2] - o, b[0]) for b in bodies[jdx:])
        tau[jdx] = z @ (n_o if rev else f)
        li = chain.joints[jdx].inertia
        if li is not None:
            tau[jdx] += li.motor_inertia * qdd[jdx]
            if friction:
                tau[jdx] += li.viscous * qd[jdx] + li.coulomb * np.sign(qd[jdx])
    return tau


def random_state(chain, rng, N=6):
    Q = rng.uniform(chain.lower, chain.upper, (N, chain.n))
    return Q, rng.uniform(-2, 2, (N, chain.n)), rng.uniform(-5, 5, (N, chain.n))


@pytest.mark.parametrize("convention", ["standard", "modified"])
@pytest.mark.parametrize("seed", range(4))
def test_random_chains_match_a_numpy_newton_euler(seed, convention):
    chain = random_chain(seed, convention, n=5 + seed % 2, motor=True)
    robot = kin.Robot(chain, backend="vm")
    Q, QD, QDD = random_state(chain, np.random.default_rng(seed))
    tau = robot.inverse_dynamics(Q, QD, QDD)
    M, G = robot.mass_matrix(Q), robot.gravity(Q)
    for k in range(len(Q)):
        assert rel_err(tau[k], numpy_rnea(chain, Q[k], QD[k], QDD[k])) < 1e-10
        assert rel_err(G[k], numpy_rnea(chain, Q[k], 0 * Q[k], 0 * Q[k])) < 1e-10
        flat = dataclasses.replace(chain, gravity=(0.0, 0.0, 0.0))
        Mn = np.column_stack([numpy_rnea(flat, Q[k], 0 * Q[k], e) for e in np.eye(chain.n)])
        assert rel_err(M[k], Mn) < 1e-10


# ---- pinocchio -------------------------------------------------------------------------------
def pinocchio_dynamics_model(chain):
    """peers.pinocchio_model's joints, with each body's inertia placed at DH frame k = J_k · post_k
    (pinocchio's joint frame k is J_k = base · A_1 ⋯ A_{k−1} · pre_k · M(q_k)) and the payload at
    post_n · tool; gravity in pinocchio's world frame = rmtkit's base placement frame."""
    pin = pytest.importorskip("pinocchio")
    from studies.benchmarks.peers import _segments, pinocchio_model

    model, _ = pinocchio_model(chain)
    for k, ((_, _, post), j) in enumerate(zip(_segments(chain), chain.joints), 1):
        items = [(j.inertia, post)] + ([(chain.payload, post @ chain.tool.matrix)] if k == chain.n else [])
        for li, T in items:
            if li is not None:
                model.appendBodyToJoint(k, pin.Inertia(li.mass, np.array(li.com), li.tensor), pin.SE3(T))
    model.gravity = pin.Motion(np.asarray(chain.gravity, dtype=float), np.zeros(3))
    return model


@pytest.mark.parametrize("convention", ["standard", "modified"])
@pytest.mark.parametrize("seed", range(10, 14))
def test_random_chains_match_pinocchio(seed, convention):
    pin = pytest.importorskip("pinocchio")
    chain = random_chain(seed, convention, n=6)
    assert "prismatic" in chain.joint_types or seed != 10          # the seeds hold prismatic joints
    model = pinocchio_dynamics_model(chain)
    data = model.createData()
    robot = kin.Robot(chain, backend="vm")
    Q, QD, QDD = random_state(chain, np.random.default_rng(seed))
    tau, M, G = robot.inverse_dynamics(Q, QD, QDD), robot.mass_matrix(Q), robot.gravity(Q)
    worst = {"rnea": 0.0, "crba": 0.0, "gravity": 0.0}
    for k in range(len(Q)):
        t = pin.rnea(model, data, Q[k], QD[k], QDD[k]).copy()
        Mp = pin.crba(model, data, Q[k]).copy()
        Mp = np.triu(Mp) + np.triu(Mp, 1).T
        gp = pin.computeGeneralizedGravity(model, data, Q[k]).copy()
        worst["rnea"] = max(worst["rnea"], rel_err(tau[k], t))
        worst["crba"] = max(worst["crba"], rel_err(M[k], Mp))
        worst["gravity"] = max(worst["gravity"], rel_err(G[k], gp))
    print(f"{chain.name} {convention} {chain.joint_types}: max relative error vs pinocchio {worst}")
    assert max(worst.values()) < 1e-10, worst


# ---- identities and derivatives --------------------------------------------------------------
@pytest.mark.parametrize("convention", ["standard", "modified"])
def test_mass_matrix_is_spd_and_tau_splits(convention):
    chain = random_chain(21, convention, n=6, motor=True)
    robot = kin.Robot(chain, backend="vm")
    Q, QD, QDD = random_state(chain, np.random.default_rng(3), N=20)
    M, C, G = robot.mass_matrix(Q), robot.coriolis(Q, QD), robot.gravity(Q)
    np.testing.assert_array_equal(M, np.swapaxes(M, 1, 2))
    assert (np.linalg.eigvalsh(M).min(axis=1) > 0).all()
    fr = np.array([[0.0 if j.inertia is None else j.inertia.viscous * v + j.inertia.coulomb * np.sign(v)
                    for j, v in zip(chain.joints, row)] for row in QD])
    tau = robot.inverse_dynamics(Q, QD, QDD)
    assert rel_err(tau, np.einsum("kij,kj->ki", M, QDD) + C + G + fr) < 1e-12
    # params per row give the same answer as the nominal ones
    np.testing.assert_allclose(robot.gravity(Q, params=np.zeros((len(Q), 0))), G, rtol=1e-15)


def test_design_parameter_derivative_by_finite_differences():
    chain = rods_2r()
    dyn = InverseDynamics(chain)
    q, qd, qdd = np.array([0.4, -1.1]), np.array([0.7, 1.3]), np.array([-0.5, 2.0])
    dtau_dp = ca.Function("d", [dyn.q, dyn.qd, dyn.qdd, dyn.p], [ca.jacobian(dyn.tau, dyn.p)])
    p0 = chain.parameter_values
    D = np.asarray(dtau_dp(q, qd, qdd, p0))
    robot = kin.Robot(chain, backend="vm")
    h = 1e-6
    for i, name in enumerate(chain.parameter_names):
        e = np.eye(len(p0))[i] * h
        up, down = (robot.inverse_dynamics(q, qd, qdd, params=p0 + s * e) for s in (1, -1))
        fd = (up - down) / (2 * h)
        assert rel_err(D[:, i], fd) < 1e-7, name
        # and by name, through the Robot API
        assert rel_err(robot.inverse_dynamics(q, qd, qdd, params={name: p0[i] + h}),
                       robot.inverse_dynamics(q, qd, qdd, params=p0 + e)) < 1e-15


# ---- the API's refusals ----------------------------------------------------------------------
def test_no_inertial_data_is_one_clear_error():
    robot = kin.Robot(kin.load_chain(DESIGN_2R), backend="vm")
    with pytest.raises(DynamicsError, match="no body has inertial data") as e:
        robot.mass_matrix(np.zeros(2))
    assert "\n" not in str(e.value) and isinstance(e.value, kin.RmtError)


def test_payload_alone_is_enough():
    chain = dataclasses.replace(kin.load_chain(DESIGN_2R), payload=LinkInertia(1.0), gravity=(0, -9.81, 0))
    g = kin.Robot(chain, backend="vm").gravity(np.zeros(2))
    np.testing.assert_allclose(g, [9.81 * 1.0, 9.81 * 0.3], rtol=1e-14)


@pytest.mark.parametrize("args, match", [
    ((np.zeros(2), np.zeros(3), np.zeros(2)), "qd has shape"),
    ((np.zeros((4, 2)), np.zeros(2), np.zeros((4, 2))), "must match q's"),
    ((np.zeros(2), np.zeros(2), [np.nan, 0.0]), "qdd holds a non-finite"),
    ((np.zeros(2), ["a", "b"], np.zeros(2)), "qd must hold real numbers"),
    (([np.inf, 0.0], np.zeros(2), np.zeros(2)), "q holds a non-finite"),
])
def test_bad_arguments_are_refused_with_one_line(args, match):
    robot = kin.Robot(rods_2r(), backend="vm")
    with pytest.raises(ConfigurationError, match=match) as e:
        robot.inverse_dynamics(*args)
    assert "\n" not in str(e.value)


@pytest.mark.parametrize("convention", ["standard", "modified"])
def test_path_coefficients_reproduce_tau_along_a_path(convention):
    """τ(q, q′ṡ, q′s̈ + q″ṡ²) of the plain numpy Newton–Euler = A·s̈ + B·ṡ² + C + viscous·q′·ṡ, at
    several (ṡ, s̈) for the same (q, q′, q″) — including Coulomb friction (sign of q′)."""
    chain = random_chain(5, convention, motor=True)
    robot = kin.Robot(chain)
    rng = np.random.default_rng(11)
    q = rng.uniform(chain.lower, chain.upper, (4, chain.n))
    d1, d2 = rng.normal(size=q.shape), rng.normal(size=q.shape)
    A, B, C = robot.path_torque_coefficients(q, d1, d2)
    vis = robot.dynamics.viscous
    for sd, sdd in ((0.4, 2.0), (1.7, -3.0), (2.5, 0.0)):
        ref = np.array([numpy_rnea(chain, q[k], d1[k] * sd, d1[k] * sdd + d2[k] * sd ** 2) for k in range(4)])
        assert rel_err(A * sdd + B * sd ** 2 + C + vis * d1 * sd, ref) < 1e-12

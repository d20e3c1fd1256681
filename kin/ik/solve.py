"""`solve_ik`: the entry point of inverse kinematics — the compiled solver (:mod:`kin.ik.compiled`)
when a C compiler works, the numpy solver (:mod:`kin.ik.numeric`) otherwise.

Both minimise the same weighted pose error with the same damped least-squares step and the same
honest verdict: success only when the position and orientation errors of the returned
configuration (inside the joint limits) are within the tolerances.  They differ in how restarts
end: the compiled solver stops at the first start that succeeds (the warm start ``q0`` first), the
numpy one runs a round of starts and keeps the successful one nearest ``q0`` (or the home
configuration).
"""
from __future__ import annotations

from kin.errors import ArgumentError, CompileError, ConfigurationError
from kin.ik import numeric
from kin.ik.compiled import compiled_ik
from kin.ik.numeric import IKResult, prepare

METHODS = ("auto", "compiled", "numeric")


def solve_ik(robot, T, seed: int = 0, q0=None, mode: str = "auto", restarts: int = 8, rounds: int = 12,
             max_iter: int = 150, tol_position: float = 1e-6, tol_orientation: float = 1e-6,
             params=None, method: str = "auto", threads: int | None = None) -> IKResult:
    """Inverse kinematics of ``robot`` for one target or a batch.

    Parameters
    ----------
    T : target pose (4, 4) or batch (N, 4, 4), base frame, SI; or a position (3,) / (N, 3).  A pose
        must be a rigid transform (else :class:`~kin.errors.ConfigurationError`).
    seed : seed of the random starts (same seed and target, same answer: alone or in any batch, on any
        number of threads).
    q0 : warm start (n,) or (N, n), tried first (e.g. the previous waypoint of a path).
    mode : ``"pose"``, ``"position"`` or ``"auto"`` (pose for a chain that controls all six rows
        and a 4×4 target, position otherwise).
    restarts, rounds : at most ``restarts · rounds`` random starts (uniform within the limits) after
        the first one (q0, or one more random start).
    max_iter : iterations per start.
    tol_position, tol_orientation : success tolerances (m, rad); 1e-10 is reachable.
    params : design parameters (mapping, (n_p,) or (N, n_p)); None: nominal.
    method : ``"auto"`` (compiled, numpy without a compiler), ``"compiled"`` (raise
        :class:`~kin.errors.CompileError` without one) or ``"numeric"``.
    threads : threads of a batch (compiled solver); None: ``$RMTKIT_THREADS`` or the CPUs this process may use.

    Returns :class:`IKResult`: for a target out of reach, success False and the configuration with
    the smallest residual found.
    """
    if method not in METHODS:
        raise ArgumentError(f"method {method!r} unknown; allowed: {', '.join(METHODS)}")
    if method == "numeric":
        return numeric.solve_ik(robot, T, seed=seed, q0=q0, mode=mode, restarts=restarts, rounds=rounds,
                                max_iter=max_iter, tol_position=tol_position, tol_orientation=tol_orientation,
                                params=params)
    solver = compiled_ik(robot)
    if solver is None:
        if method == "compiled":
            raise CompileError(f"no compiled IK for {robot.name}: no working C compiler (set CC or RMTKIT_CC)")
        return numeric.solve_ik(robot, T, seed=seed, q0=q0, mode=mode, restarts=restarts, rounds=rounds,
                                max_iter=max_iter, tol_position=tol_position, tol_orientation=tol_orientation,
                                params=params)
    Pt, Rt, single, Q0, P = prepare(robot, T, q0, mode, params, tol_position, tol_orientation)
    for name, v in (("restarts", restarts), ("rounds", rounds), ("max_iter", max_iter)):
        if int(v) < 0 or int(v) != v:
            raise ConfigurationError(f"IK {name} = {v} must be a non-negative integer")
    out = solver.solve(Pt, Rt, Q0, P, seed=seed,
                       max_starts=1 + max(int(restarts), 1) * max(int(rounds), 1), max_iter=int(max_iter),
                       tol_position=tol_position, tol_orientation=tol_orientation, threads=threads)
    return _result(out, single)


def _result(out: dict, single: bool) -> IKResult:
    if single:
        return IKResult(bool(out["success"][0]), out["q"][0], float(out["position_error"][0]),
                        float(out["orientation_error"][0]))
    return IKResult(out["success"], out["q"], out["position_error"], out["orientation_error"])


def local_ik(robot, T, q, mode: str = "auto", max_iter: int = 150, tol_position: float = 1e-6,
             tol_orientation: float = 1e-6, params=None, method: str = "auto", threads: int | None = None) -> IKResult:
    """Warm-started IK: one Levenberg–Marquardt run per target from ``q`` (n,) or (N, n) — projected
    onto the joint limits — and no restarts, no reach test.  For continuation along a path, where the
    previous solution seeds the next target and a jump to another branch is unwanted.

    Arguments and result as :func:`solve_ik`; success False when this one run does not converge.
    """
    if method not in METHODS:
        raise ArgumentError(f"method {method!r} unknown; allowed: {', '.join(METHODS)}")
    if q is None:
        raise ConfigurationError("local IK needs a warm start q")
    solver = None if method == "numeric" else compiled_ik(robot)
    if solver is None:
        if method == "compiled":
            raise CompileError(f"no compiled IK for {robot.name}: no working C compiler (set CC or RMTKIT_CC)")
        return numeric.local_ik(robot, T, q, mode=mode, max_iter=max_iter, tol_position=tol_position,
                                tol_orientation=tol_orientation, params=params)
    Pt, Rt, single, Q0, P = prepare(robot, T, q, mode, params, tol_position, tol_orientation)
    out = solver.solve(Pt, Rt, Q0, P, max_starts=1, max_iter=int(max_iter),
                       tol_position=tol_position, tol_orientation=tol_orientation, reach=False, threads=threads)
    return _result(out, single)

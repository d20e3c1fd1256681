"""What the URDF importer writes is what a robot file holds (:mod:`kin.robotfile`): lengths of 0 or
1 nm to 10 km, rigid base and tool transforms.

* **Rounding noise.** The DH values, base and tool transforms are products of the URDF's frames, whose
  numbers are printed to some digits (robowflex's Panda writes π/2 as 1.57079632679), so a length
  the URDF means as 0 comes out as ±1e-12 m or so.  A length within :data:`ROUNDING` of the chain's
  size — the largest distance of a DH frame origin or the tip from the base link's origin at q = 0
  — is below the precision URDFs are written to (9 digits: 1 nm per metre) and written as exactly 0;
  FK changes by less than that, and the chain's ``source`` says how many lengths were.
* **Refused.** A length left between 0 and 1 nm, or beyond 10 km, is not rounding noise: one
  :class:`~kin.urdf.errors.UrdfError` naming the URDF file, the joint (the DH row's, or the base or
  tool transform), the value and the allowed range.
* **Round trip.** The robot-file text of the chain is read back (:func:`kin.robotfile.loads_robot`);
  a refusal there would be a defect of the importer, reported as a :class:`UrdfError` naming the
  field, never as a robot file that cannot be loaded.
"""
from __future__ import annotations

from dataclasses import replace

import numpy as np

from kin.chain import Chain, Placement
from kin.errors import RobotFileError
from kin.robotfile import MAX_LENGTH, MIN_LENGTH, dumps_robot, loads_robot
from kin.urdf.errors import UrdfError

#: lengths within this fraction of the chain's size of 0 are rounding noise, written as 0
ROUNDING = 1e-9
#: entries of a rotation this close to 0 (or ±1) are written as 0 (±1): rounding noise
ROTATION_SNAP = 1e-14


def chain_scale(frames: list[np.ndarray]) -> float:
    """The chain's size (m): the largest distance from the base link's origin of the DH frame origins
    and the tip at q = 0 (``frames``, (4, 4) each, base-link frame)."""
    return float(max((np.linalg.norm(F[:3, 3]) for F in frames), default=0.0))


def _length(x: float, tol: float, path: str, where: str, what: str, snapped: list | None = None) -> float:
    """``x`` (m) as written: 0 within ``tol`` (appended to ``snapped`` when it was not 0), else checked
    against the robot file's range."""
    if abs(x) <= tol:
        if x != 0.0 and snapped is not None:
            snapped.append(x)
        return 0.0
    if abs(x) < MIN_LENGTH or abs(x) > MAX_LENGTH:
        raise UrdfError(f"{what} = {x:.6g} m, made from the URDF's joint origins and axes; allowed: 0 or "
                        f"{MIN_LENGTH:g} to {MAX_LENGTH:g} m in magnitude (1 nm to 10 km; lengths within "
                        f"{tol:.3g} m, {ROUNDING:g} of the chain's size, are rounding noise, written as 0)",
                        path, where)
    return x


def _placement(pl: Placement, tol: float, path: str, where: str, snapped: list) -> Placement:
    if pl.is_identity:
        return Placement()
    T = pl.matrix
    R = T[:3, :3]
    R = np.where(np.abs(R) < ROTATION_SNAP, 0.0, R)
    R = np.where(np.abs(np.abs(R) - 1.0) < ROTATION_SNAP, np.sign(R), R)
    out = np.eye(4)
    out[:3, :3] = R
    out[:3, 3] = [_length(float(x), tol, path, where, f"its translation {'xyz'[i]}", snapped)
                  for i, x in enumerate(T[:3, 3])]
    return Placement() if np.array_equal(out, np.eye(4)) else Placement.from_matrix(out)


def writable(chain: Chain, sc, scale: float) -> Chain:
    """``chain`` (imported from the URDF serial chain ``sc``) with its rounding noise written as 0
    and every length checked (see the module docstring), read back through the robot-file reader."""
    tol = ROUNDING * scale
    path = sc.path
    joints, snapped = [], []
    for uj, j in zip(sc.joints, chain.joints):
        where = f"joint {uj.name!r}"
        joints.append(replace(j, a=_length(float(j.a), tol, path, where, "its DH a", snapped),
                              d=_length(float(j.d), tol, path, where, "its DH d", snapped)))
    chain = replace(chain, joints=tuple(joints),
                    base=_placement(chain.base, tol, path, f"the base transform (link {sc.base!r} → DH frame 0)",
                                    snapped),
                    tool=_placement(chain.tool, tol, path, f"the tool transform (last DH frame → link {sc.tip!r})",
                                    snapped))
    if snapped:
        chain = replace(chain, source=f"{chain.source}; {len(snapped)} length{'s' if len(snapped) > 1 else ''} within "
                                      f"{tol:.3g} m of 0 (up to {max(map(abs, snapped)):.2g} m: rounding of the "
                                      "URDF's numbers) written as 0")
    try:
        loads_robot(dumps_robot(chain), path)
    except RobotFileError as e:
        raise UrdfError(f"the robot file made of it would be refused ({e.field}: {str(e).split(': ', 2)[-1]}); "
                        "please report this URDF", path) from None
    return chain

"""The inertial model of an imported URDF: each link's <inertial> element expressed in the DH frame of
the body that carries it.

* **Bodies** are those of :mod:`kin.urdf.read`: body 0 (the base link and what is fixed to it)
  does not move and is left out; body k (1 ≤ k ≤ n, moved by joint k) gets the links fixed to it in
  DH frame k; the tool body (the links below the last joint's own link: through fixed joints, and
  through joints off the chain held at their stated values — a gripper and its fingers) becomes the
  chain's payload, in the tool frame.
* **Placing.** An <inertial> with origin C (its centre of mass and principal-axes frame) of a link
  whose frame is L (both at q = 0, base-link frame) is, in the body's frame F, at T = F⁻¹·L·C: the
  centre of mass is T's translation and the tensor R·I·Rᵀ with R its rotation.  Several links on
  one body are combined by the parallel-axis theorem (:meth:`kin.dynamics.LinkInertia.combined`).
* Links moved by joints off the chain that cannot be held (not below the last joint) ride on no
  body: their mass is left out and named in the chain's ``source``.
* A **placeholder** — mass 0 with a non-zero tensor, which some URDFs give massless frames — is left
  out with a :class:`~kin.urdf.errors.UrdfWarning` naming the link.

Every unphysical value (negative or NaN mass, a tensor that is not positive semi-definite or breaks
the triangle inequality, a centre of mass beyond 10 km) is one :class:`~kin.urdf.errors.UrdfError`
naming the file and the link.
"""
from __future__ import annotations

import warnings

import numpy as np

from kin.dynamics.inertia import InertiaError, LinkInertia
from kin.robotfile import MAX_LENGTH
from kin.urdf.errors import UrdfError, UrdfWarning


def link_inertia(lk, path: str) -> LinkInertia | None:
    """The <inertial> of ``lk`` (a :class:`~kin.urdf.read.RigidLink`) in its own link frame; None when it
    has none or its mass is 0 (a placeholder too: mass 0 with a non-zero tensor)."""
    el = lk.inertial
    if el is None:
        return None
    where = f"link {lk.name!r} inertial"
    C = np.eye(4) if el.origin is None else np.asarray(el.origin, dtype=float)
    m = el.mass if el.mass is not None else 0.0
    I3 = np.zeros((3, 3)) if el.inertia is None else np.asarray(el.inertia, dtype=float)
    if not np.all(np.isfinite(C)) or not np.isfinite(m) or I3.shape != (3, 3) or not np.all(np.isfinite(I3)):
        raise UrdfError("its <origin>, <mass> or <inertia> holds a NaN or infinite value", path, where)
    if m == 0.0:
        return None
    if np.abs(C[:3, 3]).max() > MAX_LENGTH:
        raise UrdfError(f"its <origin> xyz {C[:3, 3].tolist()} (the centre of mass); allowed: at most "
                        f"{MAX_LENGTH:g} m (10 km) in each coordinate", path, where)
    try:
        li = LinkInertia(float(m), (0.0, 0.0, 0.0), (I3[0, 0], I3[1, 1], I3[2, 2], I3[0, 1], I3[0, 2], I3[1, 2]))
    except InertiaError as e:
        raise UrdfError(f"not a rigid body's: {e}", path, where) from None
    return li.transformed(C)


def placeholder(lk) -> bool:
    """Whether the <inertial> of ``lk`` is a placeholder: mass 0 with a non-zero tensor."""
    el = lk.inertial
    return el is not None and not el.mass and el.inertia is not None and bool(np.asarray(el.inertia).any())


def inertial_model(sc, frames: list[np.ndarray]) -> tuple[list[LinkInertia | None], LinkInertia | None, list[str]]:
    """The inertial models of bodies 1 … n (DH frames 1 … n) and the payload (tool frame) of the chain's
    links; ``frames`` are the poses at q = 0 (base-link frame) of bodies 0 … n + 1 (DH frames 0 … n,
    then the tip).  A body without any <inertial> (or only massless ones) gets None.  Placeholders
    (:func:`placeholder`) are left out with a :class:`UrdfWarning` each, and named: the third item."""
    n = sc.n
    parts: dict[int, list[LinkInertia]] = {}
    placeholders: list[str] = []
    inv = [np.linalg.inv(F) for F in frames]
    for lk in sc.links:
        if lk.body == 0:
            continue
        li = link_inertia(lk, sc.path)
        if li is None:
            if placeholder(lk):
                I3 = np.asarray(lk.inertial.inertia, dtype=float)
                warnings.warn(UrdfWarning(f"{sc.path}: link {lk.name!r} inertial: mass 0 with the inertia tensor "
                                          f"diagonal {I3[0, 0]:g} {I3[1, 1]:g} {I3[2, 2]:g} (a placeholder of a "
                                          "massless link): left out"), stacklevel=3)
                placeholders.append(lk.name)
            continue
        parts.setdefault(lk.body, []).append(li.transformed(inv[lk.body] @ lk.pose))
    labels = {**{k: f"joint {k}" for k in range(1, n + 1)}, n + 1: "payload"}
    out: dict[int, LinkInertia] = {}
    for k, ps in parts.items():
        try:
            out[k] = _snapped(LinkInertia.combined(ps, labels[k]))
        except InertiaError as e:
            raise UrdfError(f"the links of body {k} do not make a rigid body: {e}", sc.path) from None
    return [out.get(k) for k in range(1, n + 1)], out.get(n + 1), placeholders


def _snapped(li: LinkInertia) -> LinkInertia:
    """Centre-of-mass coordinates below 1 nm and tensor entries below 1e-15 of its largest are rounding
    noise of the frame changes: 0."""
    big = max(abs(x) for x in li.inertia) or 1.0
    com = tuple(0.0 if abs(x) < 1e-9 else x for x in li.com)
    inertia = tuple(0.0 if abs(x) < 1e-15 * big else x for x in li.inertia)
    return LinkInertia(li.mass, com, inertia, li.motor_inertia, li.viscous, li.coulomb, li.body)  # type: ignore[arg-type]

"""Link geometry: the capsules a robot is made of, obstacle shapes, body frames, the motion bound of
the collision proofs and the compiled clearance kernel.

* :mod:`kin.geometry.shapes` — :class:`LinkCapsule`, :class:`Shape`, :class:`Obstacle`;
* :mod:`kin.geometry.model` — :class:`RobotGeometry` (capsules per body, allowed pairs);
* :mod:`kin.geometry.default` — :func:`default_geometry` along the DH offsets;
* :mod:`kin.geometry.frames` — :func:`body_frames` (numpy);
* :mod:`kin.geometry.motion` — :func:`reach_radii`, the Lipschitz bound of body motion;
* :mod:`kin.geometry.clearance` — :class:`ClearanceModel`, the signed clearance of the capsules
  against obstacles and each other (compiled kernel ``clearance.c``; numpy fallback
  :mod:`kin.geometry.clearance_numpy`), :class:`Contact`.
* :mod:`kin.geometry.convex` — certified GJK distances between convex solids;
  :mod:`kin.geometry.hulls` — clearances raised to the bodies' hulls (:class:`LinkHull`) where the
  capsules come too close; :mod:`kin.geometry.hull_fit` — a mesh's hull thinned to few points;
* :mod:`kin.geometry.enclose` — capsules enclosing boxes, cylinders, point sets and meshes, with their
  over-estimate (robot files, URDF import, the bundled arms); :mod:`kin.geometry.meshfit` — a mesh
  cut into slabs, the fast and the exhaustive search for the cut.
"""
from kin.geometry.clearance import ClearanceModel, Contact
from kin.geometry.default import chain_length, default_geometry, default_radius
from kin.geometry.frames import body_frames
from kin.geometry.model import RobotGeometry, body_names
from kin.geometry.motion import reach_radii, row_lengths
from kin.geometry.shapes import SHAPE_KINDS, LinkCapsule, LinkHull, Obstacle, Shape

__all__ = ["SHAPE_KINDS", "ClearanceModel", "Contact", "LinkCapsule", "LinkHull", "Obstacle", "RobotGeometry", "Shape",
           "body_frames", "body_names", "chain_length", "default_geometry", "default_radius", "reach_radii",
           "row_lengths"]

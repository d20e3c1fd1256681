"""Work cells: the obstacles around a robot, where it stands, the tool it carries and the pairs
never checked, read from a TOML cell file (docs/cells.md).

* :mod:`planning.cell.model` — :class:`Cell`, :meth:`Cell.resolve` → :class:`ResolvedCell`; names
  that could be a body or an obstacle (``body:`` / ``obstacle:``);
* :mod:`planning.cell.reader` — :func:`load_cell`, :func:`parse_cell` (every field checked),
  :func:`cell_tcp` (the tool centre point alone);
* :mod:`planning.cell.fields` — checked access to one table's fields, units converted;
* :mod:`planning.cell.obstacles` — the obstacle types (primitives, cones, meshes, point clouds,
  compounds of several parts) as :class:`kin.geometry.Obstacle`;
* :mod:`planning.cell.mesh` — STL/OBJ/PLY meshes, bounded before parsing;
* :mod:`planning.cell.points` — PLY/CSV point clouds, bounded before parsing;
* :mod:`planning.cell.enclose` — spheres that provably enclose meshes and point clouds;
* :mod:`planning.cell.keep_out` — :func:`cell_from_keep_out`, keep-out boxes as a cell.
"""
from planning.cell.enclose import SphereCover, enclose_points, enclose_triangles
from planning.cell.keep_out import cell_from_keep_out
from planning.cell.mesh import load_mesh
from planning.cell.model import Cell, ResolvedCell, body_lookup
from planning.cell.points import load_points
from planning.cell.reader import OBSTACLE_TYPES, TOOL_TYPES, cell_tcp, load_cell, parse_cell
from planning.errors import CellError

__all__ = ["OBSTACLE_TYPES", "TOOL_TYPES", "Cell", "CellError", "ResolvedCell", "SphereCover", "body_lookup",
           "cell_from_keep_out", "cell_tcp", "enclose_points", "enclose_triangles", "load_cell", "load_mesh",
           "load_points", "parse_cell"]

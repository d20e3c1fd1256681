"""``--tcp X Y Z [R P Y]``: a tool-centre-point offset after the robot file's [tool] (robot file
units), applied where every command loads its robot (:func:`robot_loader`, wired in
:mod:`studies.cli.main`) by :func:`kin.tcp.with_tcp`.  A work cell given with ``--cell`` may set the
tool centre point too (``[[tool]] tcp``, the cell's units, :func:`planning.cell.cell_tcp`): the
commands that take ``--tcp`` use it, and ``--tcp`` overrides it (with a note on stderr)."""
from __future__ import annotations

import sys

#: the commands whose answers depend on the tool point (poses, Jacobians, σ_min): they take --tcp
TCP_COMMANDS = frozenset({"fk", "jacobian", "ik", "workspace", "windows", "singularities", "plan", "check-path",
                          "reach", "place", "follow", "validate-toolpath", "coverage", "view"})


def tcp_args(sp) -> None:
    sp.add_argument("--tcp", nargs="+", metavar="V",
                    help="X Y Z [ROLL PITCH YAW]: a tool-centre-point offset after the robot file's [tool], in its "
                         "tool frame, robot file units (lengths within ±10 km, angles within ±360°); overrides a "
                         "--cell's [[tool]] tcp")


def robot_loader(args, load):
    """``load`` (name → :class:`kin.Robot`) with the command's tool centre point applied: ``--tcp`` if
    given, else the ``[[tool]] tcp`` of its ``--cell`` if that sets one."""
    takes_tcp = hasattr(args, "tcp")
    values = getattr(args, "tcp", None)
    cell = getattr(args, "cell", None) if takes_tcp else None
    if values is None and cell is None:
        return load
    noted = []

    def load_with_tcp(name):
        from kin.tcp import tcp_transform, with_tcp
        robot = load(name)
        c = robot.chain
        T = None if values is None else tcp_transform(values, c.length_unit, c.angle_unit, "--tcp")
        if cell is not None:
            from planning.cell import cell_tcp
            from studies.cli.common import cell_file
            path = cell_file(cell)
            T_cell = cell_tcp(path)
            if T is None:
                T = T_cell
            elif T_cell is not None and not noted:
                noted.append(path)
                print(f"note: --tcp overrides the tool centre point of cell {path} ([[tool]] tcp)", file=sys.stderr)
        return robot if T is None else with_tcp(robot, T)
    return load_with_tcp


def with_task_cell_tcp(args, robot, cell):
    """``robot`` with the tool centre point of ``cell`` when it is a task file's (no ``--cell``: the
    loader applied that one) and ``--tcp`` is not given (it overrides the cell's, with the note)."""
    if cell is None or cell.tcp is None or getattr(args, "cell", None) is not None:
        return robot
    if getattr(args, "tcp", None) is not None:
        print(f"note: --tcp overrides the tool centre point of cell {cell.where} ([[tool]] tcp)", file=sys.stderr)
        return robot
    return cell.with_tcp(robot)


__all__ = ["TCP_COMMANDS", "tcp_args", "robot_loader", "with_task_cell_tcp"]

"""``--tcp X Y Z [R P Y]``: a tool-centre-point offset after the robot file's ``[tool]`` (robot file
units), applied where every command loads its robot (:func:`robot_loader`, wired in
:mod:`studies.cli.main`) by :func:`kin.tcp.with_tcp`."""
from __future__ import annotations

#: the commands whose answers depend on the tool point (poses, Jacobians, σ_min): they take --tcp
TCP_COMMANDS = frozenset({"fk", "jacobian", "ik", "workspace", "windows", "singularities", "plan", "check-path",
                          "reach", "place", "follow", "validate-toolpath", "coverage"})


def tcp_args(sp) -> None:
    sp.add_argument("--tcp", nargs="+", metavar="V",
                    help="X Y Z [ROLL PITCH YAW]: a tool-centre-point offset after the robot file's [tool], in its "
                         "tool frame, robot file units (lengths within ±10 km, angles within ±360°)")


def robot_loader(args, load):
    """``load`` (name → :class:`kin.Robot`) with the command's ``--tcp`` applied, if given."""
    values = getattr(args, "tcp", None)
    if values is None:
        return load

    def load_with_tcp(name):
        from kin.tcp import tcp_transform, with_tcp
        robot = load(name)
        c = robot.chain
        return with_tcp(robot, tcp_transform(values, c.length_unit, c.angle_unit, "--tcp"))
    return load_with_tcp


__all__ = ["TCP_COMMANDS", "tcp_args", "robot_loader"]

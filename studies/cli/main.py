"""The ``rmt`` command line.

Every command takes ROBOT as a bundled name (``rmt robots``) or a path to a robot file, reads and
prints values in the robot file's units, and with ``--json`` prints one JSON object.  Bad input
exits with code 2 and one line on stderr; ``rmt ik`` exits 1 when it finds no solution.

Start-up is light: ``kin`` loads ``Robot`` (CasADi) on first use, and the command modules import
their heavy dependencies (CasADi, OMPL, OSQP, sympy, matplotlib, the design layer) inside their
command functions, so ``rmt --help`` and ``rmt fk``
load only what they use.  A new command group is one module with ``add_commands(add)``, listed in
:data:`GROUPS`.
"""
from __future__ import annotations

import argparse
import re
import sys
from typing import Sequence

import kin
from studies.cli import (
    assemble,
    cell,
    compose,
    design,
    export,
    follow,
    ik,
    kinematics,
    place,
    plan,
    reach,
    scene,
    singular,
    study,
    sweep,
    timing,
    toolpath,
    urdf,
    view,
)
from studies.cli.common import EXIT_OK, EXIT_USAGE
from studies.cli.tcp import TCP_COMMANDS, robot_loader, tcp_args

#: the command groups, in the order ``rmt --help`` lists their commands
GROUPS = (kinematics, ik, singular, plan, timing, export, cell, scene, toolpath, follow, study, design, reach, place,
          sweep, urdf, assemble, compose, view)


class UsageError(Exception):
    """Bad command-line input (exit code 2)."""


class _Parser(argparse.ArgumentParser):
    def __init__(self, *args, **kwargs):
        super().__init__(*args, **kwargs)
        # argparse takes "-1e-5" for an option; joint values in exponent form are numbers too
        self._negative_number_matcher = re.compile(r"^-(\d+\.?\d*|\.\d+)([eE][-+]?\d+)?$")

    def error(self, message):  # one line, exit 2 (argparse prints usage + message by default)
        # main() prints "rmt: error: …": the top-level parser adds no second "rmt: ", a command's names itself
        raise UsageError(message if self.prog == "rmt" else f"{self.prog}: {message}")


# ---- parser ------------------------------------------------------------------------------------
def build_parser() -> argparse.ArgumentParser:
    p = _Parser(prog="rmt", description="rmtkit: kinematics, singularities and motion planning of "
                                        "reconfigurable machine tools and robot arms")
    sub = p.add_subparsers(dest="command", metavar="COMMAND", parser_class=_Parser)
    sub.required = True

    def add(name, func, help_):
        # argparse %-formats the help shown in `rmt --help`: a literal "%" (as in "reach %") must be doubled
        sp = sub.add_parser(name, help=help_.replace("%", "%%"), description=help_)
        sp.set_defaults(func=func)
        sp.add_argument("--json", action="store_true", help="print one JSON object")
        if name in TCP_COMMANDS:
            tcp_args(sp)
        return sp

    for group in GROUPS:
        group.add_commands(lambda name, func, text: add(
            name, lambda args, f=func: f(args, robot_loader(args, kin.load_robot)), text))
    return p


def main(argv: Sequence[str] | None = None) -> int:
    """Run one command; returns the exit code (0 ok, 1 a negative answer, 2 bad input, 130 interrupted)."""
    try:
        parser = build_parser()
        args, extra = parser.parse_known_args(argv)
        if extra:        # name the command the arguments were given to (argparse's top level cannot)
            raise UsageError(f"rmt {args.command}: unrecognized arguments: {' '.join(extra)}")
        return args.func(args)
    except (UsageError, kin.RmtError) as e:
        print(f"rmt: error: {e}", file=sys.stderr)
    except SystemExit as e:         # argparse after --help
        return e.code if isinstance(e.code, int) else EXIT_OK
    except BrokenPipeError:
        return EXIT_OK
    except KeyboardInterrupt:
        print("rmt: interrupted", file=sys.stderr)
        return 130
    return EXIT_USAGE


if __name__ == "__main__":
    sys.exit(main())

"""Helpers shared by the ``rmt`` commands: number parsing and windows from the command line (JSON is
:mod:`studies.jsonio`)."""
from __future__ import annotations

import argparse
import math
import sys
from pathlib import Path
from typing import Sequence

import numpy as np

import kin

EXIT_OK, EXIT_FAIL, EXIT_USAGE = 0, 1, 2
#: seeds are 32-bit (numpy and OMPL)
MAX_SEED = 2**32 - 1
#: the longest planning time a command accepts, s
MAX_TIME_LIMIT = 3600.0
#: the largest σ_min threshold or floor (SI; no arm of human size comes near it)
MAX_SIGMA = 1e3


class CliInputError(kin.RmtError):
    """Bad command-line input (the CLI exits with code 2)."""


def seed(text: str) -> int:
    """argparse type of ``--seed``: an integer 0 … 2³²−1."""
    try:
        v = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not an integer (allowed: 0 to {MAX_SEED})") from None
    if not 0 <= v <= MAX_SEED:
        raise argparse.ArgumentTypeError(f"{v} is outside the allowed range 0 to {MAX_SEED}")
    return v


def bounded(lo: float, hi: float, unit: str, open_low: bool = False, integer: bool = False):
    """An argparse type: a finite number in [lo, hi] (or (lo, hi] with ``open_low``), ``unit`` named
    in the error."""
    def parse(text: str):
        try:
            v = int(text) if integer else float(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"{text!r} is not {'an integer' if integer else 'a number'}") from None
        if not (math.isfinite(v) and (v > lo if open_low else v >= lo) and v <= hi):
            rng = (f"{'(' if open_low else '['}{lo:g}, {hi:g}]" if math.isfinite(hi)
                   else f"{'>' if open_low else '≥'} {lo:g}, finite")
            raise argparse.ArgumentTypeError(f"{text} is outside the allowed range {rng} {unit}".rstrip())
        return v
    return parse


def output_file(arg: str | None):
    """Check an output path (``--out``, ``--plot``) before any work: see :func:`kin.output.check_output`."""
    if arg is not None:
        from kin.output import check_output
        check_output(arg)
    return arg


def numbers(values: Sequence[str], what: str) -> list[float]:
    """Parse finite numbers; ``what`` names the argument in the error."""
    out = []
    for v in values:
        try:
            x = float(v)
        except ValueError:
            raise CliInputError(f"{what}: {v!r} is not a number") from None
        if not math.isfinite(x):
            raise CliInputError(f"{what}: {v!r} is not a finite number")
        out.append(x)
    return out


def positions(chain, values: Sequence[str], what: str) -> np.ndarray:
    """Coordinates given in the robot file's length unit → SI (m), each within ±10 km."""
    from kin.robotfile import MAX_LENGTH
    xyz = np.array(numbers(values, what)) * chain.length_scale
    if np.abs(xyz).max() > MAX_LENGTH:
        raise CliInputError(f"{what}: coordinates must lie within ±{MAX_LENGTH / chain.length_scale:g} "
                            f"{chain.length_unit} (10 km)")
    return xyz


def joint_values(robot: kin.Robot, values: Sequence[str], what: str = "joint values") -> np.ndarray:
    """A configuration given in the robot file's units → SI, checked for count and finiteness; a single
    word that is not a number names one of the robot's states (:mod:`kin.states`: ``home``)."""
    from kin.states import UnknownStateError, is_number, state
    if len(values) == 1 and not is_number(values[0]):
        try:
            return state(robot.chain, values[0])
        except UnknownStateError as e:
            raise CliInputError(f"{what}: {values[0]!r} is neither a number nor a named state: {e}") from None
    q = numbers(values, what)
    if len(q) != robot.n:
        units = ", ".join(c.angle_unit if j.is_revolute else c.length_unit
                          for c in [robot.chain] for j in c.joints)
        raise CliInputError(f"{what}: got {len(q)} values; {robot.name} has {robot.n} joints ({units})")
    return robot.chain.to_si(q)


def require_within_limits(robot, P: np.ndarray, where) -> None:
    """Refuse a path (M, n) SI with a joint value outside the robot's limits (1e-12 SI of slack): one line
    naming ``where(i)`` (i the 0-based index of the configuration: e.g. "P.csv: data row 3"), the joint, its value and
    the allowed range in robot file units (:func:`studies.jointpath.outside_limits`).  Beyond the limits a path's
    length can overflow and its time vanish (1e300 rad: "zero-length path")."""
    from studies.jointpath import outside_limits
    why = outside_limits(robot, P, where)
    if why is not None:
        raise CliInputError(why)


def leaving_limits(robot, path, shape: str) -> list[tuple[int, str]]:
    """The joints (0-based) a timed path (``tr.path``, a shaped path with ``joint_range()``) takes
    beyond the robot's limits (1e-12 SI of slack), each with its sentence in robot file units:
    "the blend path leaves joint J2's limits [..]: it spans [..] (deg)"."""
    from studies.units import joint_units
    c = robot.chain
    lo, hi = path.joint_range()
    names, units = c.joint_names(), joint_units(c)
    lo_f, hi_f, lim_lo, lim_hi = c.from_si(lo), c.from_si(hi), c.from_si(c.lower), c.from_si(c.upper)
    return [(j, f"the {shape} path leaves joint {names[j]}'s limits [{lim_lo[j]:.6g}, {lim_hi[j]:.6g}]: it spans "
                f"[{lo_f[j]:.6g}, {hi_f[j]:.6g}] ({units[j]})")
            for j in range(robot.n) if lo[j] < c.lower[j] - 1e-12 or hi[j] > c.upper[j] + 1e-12]


def limits_from(args) -> dict:
    """Where ``rmt time``'s speed and acceleration limits came from: the options or the robot file."""
    return {"v_max": "--v-max" if args.v_max else "robot file", "a_max": "--a-max" if args.a_max else "robot file"}


def window_width_args(sp, required: bool = False,
                      sigma_help: str = "singular windows from a σ_min threshold (SI)"):
    """Add ``--margin X | --sigma-min S``, the inputs of :func:`windows_from_args`, to a command's
    parser; returns their mutually exclusive group (a command may add another width source to it)."""
    g = sp.add_mutually_exclusive_group(required=required)
    g.add_argument("--margin", type=bounded(0, math.inf, "(robot file units)"), metavar="X",
                   help="singular windows of this half-width in the robot file's units: its angle unit for "
                        "factors with a revolute joint (5 on a robot in deg is ±5°), its length unit otherwise")
    g.add_argument("--sigma-min", type=bounded(0, MAX_SIGMA, "(SI)", open_low=True), metavar="S", help=sigma_help)
    return g


def windows_label(chain, margin: float | None, sigma_min: float | None) -> str | None:
    """The windows of ``--margin``/``--sigma-min`` in words, the margin in the robot file's unit with
    the option echoed: "windows of ±5° (--margin 5, robot file unit deg)"; None without windows."""
    if margin is not None:
        kinds = {j.is_revolute for j in chain.joints}
        units = [u for rev, u in ((True, chain.angle_unit), (False, chain.length_unit)) if rev in kinds]
        widths = " or ".join(f"±{margin:g}°" if u == "deg" else f"±{margin:g} {u}" for u in units)
        which = (f"unit {units[0]}" if len(units) == 1
                 else f"units {chain.angle_unit} for angles, {chain.length_unit} for lengths")
        return f"windows of {widths} (--margin {margin:g}, robot file {which})"
    if sigma_min is not None:
        return f"windows where σ_min < {sigma_min:g} (SI) (--sigma-min {sigma_min:g})"
    return None


def windows_from_args(robot: kin.Robot, margin: float | None, sigma_min: float | None,
                      exact_timeout: float | None = None):
    """Windows from ``--margin`` (file units) or ``--sigma-min`` (SI threshold); None when neither.
    The same for every command and seed (:func:`planning.windows.build_windows`); built once per
    robot content and width and then read from the cache (:mod:`planning.windows.cache`) — unless
    ``exact_timeout`` (s) sets another budget for the exact analysis: then built without the cache,
    whose files are made under the default budget."""
    if margin is None and sigma_min is None:
        return None
    if margin is not None and not (math.isfinite(margin) and margin >= 0):
        raise CliInputError(f"--margin {margin} must be a finite number ≥ 0 (robot file units)")
    from planning.windows.cache import cached

    def build():
        from kin.singular import analyse_singularities
        from planning.windows import build_windows
        from planning.windows.build import WINDOW_SAMPLES, WINDOW_SEED
        from studies.cli.progress import TerminalProgress
        budget = {} if exact_timeout is None else {"exact_timeout": exact_timeout}
        with TerminalProgress() as progress:
            analysis = analyse_singularities(robot, samples=WINDOW_SAMPLES, seed=WINDOW_SEED, progress=progress,
                                             **budget)
        if margin is not None:
            from studies.study.windows import factor_margins
            return build_windows(robot, margin=factor_margins(robot.chain, analysis, margin), analysis=analysis)
        return build_windows(robot, sigma_min=sigma_min, analysis=analysis)
    if exact_timeout is not None:
        return build()
    request = {"margin": float(margin)} if margin is not None else {"sigma_min": float(sigma_min)}
    return cached(robot, request, build, unstored=lambda text: print(f"note: {text}", file=sys.stderr))


def sampled_windows_note(ws, floor_hint: str) -> str | None:
    """One line for stderr when some windows are sampled (point-set windows of a numeric analysis):
    how much of their singular set they miss, and that a verdict then does not exclude singular
    configurations; None when every window is exact or proven."""
    sampled = [w for w in (ws.windows if ws is not None else []) if getattr(w, "is_point_set", False)]
    if not sampled:
        return None
    missed = sum((w.detail.get("miss") or {}).get("outside_window") or 0 for w in sampled)
    fresh = sum((w.detail.get("miss") or {}).get("fresh_set_points") or 0 for w in sampled)
    share = f": together they miss {missed} of {fresh} fresh points of the singular set" if fresh else ""
    many = len(sampled) != 1
    return (f"note: {len(sampled)} window{'s' if many else ''} of this robot {'are' if many else 'is'} sampled (its "
            f"singular set was found numerically){share}, so a path clear of them may still pass near or through "
            f"a singularity; {floor_hint}")


#: the bundled work cells (``--cell NAME``)
CELL_DIR = Path(__file__).resolve().parent.parent / "cells"


def bundled_cells() -> list[str]:
    """Names of the bundled work cells (studies/cells/*.toml)."""
    return sorted(p.stem for p in CELL_DIR.glob("*.toml"))


def bundled_file(arg: str, folder: Path, what: str) -> Path:
    """A file argument → an existing file: a path, or the name (no suffix, no folder) of a bundled
    ``folder/NAME.toml``; else one line naming the bundled ones (``what``: "cell", "task", …)."""
    p = Path(arg)
    if p.is_file():
        return p
    if not p.suffix and "/" not in arg and (folder / f"{arg}.toml").is_file():
        return folder / f"{arg}.toml"
    bundled = ", ".join(sorted(q.stem for q in folder.glob("*.toml")))
    raise CliInputError(f"{arg}: no such {what} file or bundled {what}; bundled: {bundled}")


def cell_file(arg: str) -> Path:
    """A ``--cell`` argument → an existing file: a path, or the name of a bundled cell."""
    return bundled_file(arg, CELL_DIR, "cell")


def cell_args(sp) -> None:
    """``--cell CELL.toml`` and ``--clearance D``: the work cell a command judges collisions in."""
    sp.add_argument("--cell", metavar="CELL.toml",
                    help="work cell (TOML, docs/cells.md) or a bundled cell's name (" + ", ".join(bundled_cells())
                         + "): robot placement, obstacles, tool geometry, allowed pairs; collisions with it and "
                           "self-collisions are checked (by proof for joint motions)")
    sp.add_argument("--self-collision", action="store_true",
                    help="check the robot against itself (non-adjacent links; implied by --cell)")
    sp.add_argument("--clearance", type=bounded(0, math.inf, "(robot file length unit)"), default=0.0,
                    metavar="D", help="with --cell or --self-collision: the clearance every state needs, robot file "
                                      "length unit (default 0: not touching)")


def world_from_args(robot: kin.Robot, args, keep_out=()):
    """The :class:`planning.collision.CollisionWorld` of ``--cell``/``--self-collision``/``--clearance``
    (and ``keep_out`` boxes, robot base frame), or None when none of them is given."""
    cell = getattr(args, "cell", None)
    clearance = getattr(args, "clearance", 0.0) or 0.0
    if cell is None and not keep_out and not getattr(args, "self_collision", False):
        if clearance:
            raise CliInputError("--clearance needs --cell or --self-collision (what it applies to)")
        return None
    from planning.collision import MAX_MARGIN, collision_world
    margin = clearance * robot.chain.length_scale
    if margin > MAX_MARGIN:
        raise CliInputError(f"--clearance {clearance:g} is outside the allowed range [0, "
                            f"{MAX_MARGIN / robot.chain.length_scale:g}] {robot.chain.length_unit}")
    return collision_world(robot, None if cell is None else cell_file(cell), margin, keep_out=keep_out)

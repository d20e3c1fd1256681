"""``rmt time ROBOT CYCLE.toml``: a cycle of moves with dwells, timed into one trajectory
(:func:`planning.timing.sequence.time_sequence`).  The cycle file (docs/cli.md, "rmt time over a
cycle")::

    [[move]]
    name = "to pick"           # optional, for the report
    path = "to_pick.csv"       # a joint path CSV (rmt plan --out), relative to this file
    dwell = 0.5                # s held after this move (default 0), at most one day

    [[move]]
    waypoints = ["pick", [0, -90, 90, -90, -90, 0]]   # robot file units, or the robot's named states
    dwell = 1.0

Each move is one of ``path`` or ``waypoints`` (at least two configurations, and it must move); a move
starts where the previous one ends (within :data:`~planning.timing.sequence.JOIN_TOLERANCE`, SI): a cycle
inserts no motion of its own, since a connection would be a path nobody checked.
"""
from __future__ import annotations

import sys
import tomllib
from pathlib import Path

import numpy as np

from kin.output import write_output
from kin.validation import Fields
from studies.cli.common import EXIT_FAIL, CliInputError, leaving_limits, limits_from
from studies.jsonio import dump, finite_or_none
from studies.units import joint_units

#: the largest cycle file read
MAX_CYCLE_BYTES = 10 * 2**20
TOP_KEYS = ("move",)
MOVE_KEYS = ("name", "path", "waypoints", "dwell")


class _Reader(Fields):
    def fail(self, field, msg):
        return CliInputError(": ".join(x for x in (self.source, field, msg) if x))


def _configuration(r: _Reader, robot, v, fld: str) -> np.ndarray:
    """One waypoint: a state's name or n numbers in robot file units → SI."""
    from kin.states import UnknownStateError, state
    if isinstance(v, str):
        try:
            return state(robot.chain, v)
        except UnknownStateError as e:
            raise r.fail(fld, str(e)) from None
    return robot.chain.to_si(r.vector(v, fld, robot.n))


def read_cycle_file(robot, path: str | Path) -> list[tuple[str, np.ndarray, float]]:
    """The moves of a cycle file: (name, path (M, n) SI, dwell s) each; one-line errors naming the
    file and the field."""
    from planning.timing.sequence import JOIN_TOLERANCE, MAX_DWELL, MAX_MOVES, join_gap
    from studies.cli.common import require_within_limits
    from studies.cli.plan import read_path_csv

    path = Path(path)
    r = _Reader(str(path))
    from kin.files import FileReadError, read_text
    try:
        doc = tomllib.loads(read_text(path, "cycle file", MAX_CYCLE_BYTES))
    except FileReadError as e:
        raise r.fail(None, e.reason) from None
    except tomllib.TOMLDecodeError as e:
        raise r.fail(None, f"not valid TOML ({e})") from None
    r.table(doc, "", TOP_KEYS)
    raw = doc.get("move")
    if not isinstance(raw, list) or not all(isinstance(m, dict) for m in raw) or not 1 <= len(raw) <= MAX_MOVES:
        raise r.fail("move", f"needs 1 to {MAX_MOVES} [[move]] tables, each with path or waypoints")
    moves = []
    for k, m in enumerate(raw):
        fld = f"move {k + 1}"                # 1-based, as the moves are numbered everywhere
        r.table(m, fld, MOVE_KEYS)
        if ("path" in m) == ("waypoints" in m):
            raise r.fail(fld, "give either path (a joint path CSV) or waypoints (a list of configurations), "
                              "one of them")
        if "path" in m:
            csv_path = Path(r.string(m["path"], f"{fld}.path"))
            csv_path = csv_path if csv_path.is_absolute() else path.parent / csv_path
            P = read_path_csv(robot, csv_path)
            require_within_limits(robot, P, lambda i: f"{csv_path} ({path}, {fld}.path): data row {i + 1}")
            name = str(m.get("name", csv_path.name))
        else:
            w = m["waypoints"]
            if not isinstance(w, list) or not 2 <= len(w) <= 100000:
                raise r.fail(f"{fld}.waypoints", "must be a list of 2 to 100000 configurations (robot file units, "
                                                 "or state names)")
            P = np.array([_configuration(r, robot, v, f"{fld}.waypoints, configuration {i + 1}")
                          for i, v in enumerate(w)])
            require_within_limits(robot, P, lambda i: f"{path}: {fld}.waypoints, configuration {i + 1}")
            name = str(m.get("name", f"move {k + 1}"))
        if "name" in m:
            name = r.string(m["name"], f"{fld}.name")
        dwell = r.number(m.get("dwell", 0.0), f"{fld}.dwell")
        if not 0 <= dwell <= MAX_DWELL:
            raise r.fail(f"{fld}.dwell", f"{dwell:g} s is outside the allowed range [0, {MAX_DWELL:g}] s (one day)")
        if len(P) < 2 or np.all(P == P[0]):
            raise r.fail(fld, "does not move (fewer than 2 configurations, or all the same); a hold is the "
                              "previous move's dwell")
        if moves:
            gap, j = join_gap(moves[-1][1][-1], P[0])
            if gap > JOIN_TOLERANCE:
                c = robot.chain
                u = joint_units(c)[j]
                raise r.fail(fld, f"starts at joint {j + 1} = {c.from_si(P[0])[j]:.10g} {u}, not where move {k} ends "
                                  f"({c.from_si(moves[-1][1][-1])[j]:.10g} {u}); a cycle inserts no motion: start "
                                  "each move at the previous one's last configuration")
        moves.append((name, P, dwell))
    return moves


def time_cycle(args, robot, vmax, amax, jmax, taumax, use_robot: bool, csv_text) -> int:
    """Time the cycle file ``args.path`` and report it (text or JSON); write ``--csv``/``--out``."""
    from planning.timing.sequence import time_sequence

    for opt in ("plot", "path_out"):
        if getattr(args, opt):
            raise CliInputError(f"--{opt.replace('_', '-')} applies to one path; time the move's CSV alone for it")
    c = robot.chain
    moves = read_cycle_file(robot, args.path)
    seq = time_sequence([P for _, P, _ in moves], [d for _, _, d in moves], v_max=vmax, a_max=amax, ds=args.ds,
                        blend=args.blend, j_max=jmax, robot=robot if use_robot else None, tau_max=taumax,
                        shape=args.shape)
    if args.csv:
        write_output(args.csv, csv_text(robot, seq))
    names = c.joint_names()
    rows, leaving = [], []
    for k, ((name, _, _), tr) in enumerate(zip(moves, seq.moves)):
        beyond = leaving_limits(robot, tr.path, args.shape)
        out = [names[j] for j, _ in beyond]
        label = f"move {k + 1}" if name == f"move {k + 1}" else f"move {k + 1} ({name})"     # named once
        leaving += [f"{label}: {text}" for _, text in beyond]
        rows.append({"name": name, "start_s": float(seq.start[k]), "duration_s": tr.duration,
                     "dwell_s": float(seq.dwell[k]), "end_s": float(seq.start[k] + tr.duration + seq.dwell[k]),
                     "samples": len(tr.t), "solver": tr.qp_status, "dense_overshoot": tr.overshoot,
                     "max_torque_ratio": finite_or_none(tr.max_torque_ratio), "joints_leaving_limits": out})
    peak_v = max(float(np.max(np.abs(tr.qd) / tr.v_max)) for tr in seq.moves)
    peak_a = max(float(np.max(np.abs(tr.qdd) / tr.a_max)) for tr in seq.moves)
    total_moves = sum(tr.duration for tr in seq.moves)
    summary = {"cycle": str(args.path), "total_s": seq.duration, "moving_s": total_moves,
               "dwell_s": float(seq.dwell.sum()), "samples": len(seq.t), "moves": rows,
               "peak_velocity_ratio": peak_v, "peak_acceleration_ratio": peak_a, "shape": args.shape,
               "limits_from": limits_from(args),
               "v_max": c.from_si(vmax).tolist(), "a_max": c.from_si(amax).tolist(),
               "units": {"v_max": "robot file units/s", "a_max": "robot file units/s²", "time": "s"}}
    if args.json:
        print(dump(summary))
        return EXIT_FAIL if leaving else 0
    print(f"cycle {args.path}: {len(rows)} move(s), total {seq.duration:.6g} s "
          f"(moving {total_moves:.6g} s, dwells {summary['dwell_s']:.6g} s; {len(seq.t)} samples)")
    w = max(8, *(len(d["name"]) for d in rows))
    print(f"  {'#':>3} {'move':<{w}} {'start s':>9} {'duration s':>11} {'dwell s':>9}")
    for k, d in enumerate(rows, 1):
        print(f"  {k:>3} {d['name']:<{w}} {d['start_s']:9.4f} {d['duration_s']:11.6g} {d['dwell_s']:9.4g}")
    print(f"limits: speeds from {summary['limits_from']['v_max']}, accelerations from "
          f"{summary['limits_from']['a_max']}; peak |q̇|/v {peak_v:.4f}, |q̈|/a {peak_a:.4f}; dense re-check "
          f"overshoot {max(d['dense_overshoot'] for d in rows):.2e}")
    if args.csv:
        print(f"wrote {args.csv}")
    for line in leaving:                  # in the report (stdout), and the first as the error (stderr)
        print(line)
    for line in leaving[:1]:
        print(line, file=sys.stderr)
    return EXIT_FAIL if leaving else 0


def is_cycle_file(arg: str) -> bool:
    """True when the path argument names a cycle file (``.toml``) rather than a joint path CSV."""
    return Path(arg).suffix.lower() == ".toml"


__all__ = ["read_cycle_file", "time_cycle", "is_cycle_file", "MAX_CYCLE_BYTES"]

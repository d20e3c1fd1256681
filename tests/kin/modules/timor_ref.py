"""The same serial robot built in timor-python (TUM): forward kinematics and inverse dynamics as a reference.

timor-python 1.1.1 pins pinocchio < 3 (and with it numpy 1.x), which rmtkit's venv (pinocchio 4, numpy 2)
cannot hold; so timor lives in a venv of its own (``make timor-venv`` → ``.venv-timor``, or any interpreter
named by ``RMT_TIMOR_PYTHON``) and this file is two things:

* in rmtkit's interpreter, :func:`timor_python` finds that interpreter and :func:`timor_reference` runs
  this same file in it (stdlib only on this side: JSON in on stdin, JSON out on stdout);
* in timor's interpreter, :func:`main` builds the robot and answers.

The robot is given as plain numbers (SI, 4×4 matrices as nested lists), one entry per module in chain
order: ``{"kind": "base", "out": T}`` (the robot's base frame in the world), then joints
``{"kind": "joint", "type": "revolute"|"prismatic", "twist": θ, "axis": T, "out": T, "proximal": P,
"distal": P}``, links ``{"kind": "link", "twist": θ, "out": T, "proximal": P}`` and one tool
``{"kind": "tool", "twist": θ, "out": T, "proximal": P}``; a part P is ``{"mass": m, "com": [3],
"inertia": 3×3 about the com}`` in the input frame (proximal) or the output frame (distal).  This is
rmtkit's module description (docs/modules.md), so the mapping to timor is written once, here:

* a module's input frame, output frame, joint frame: rmtkit's frames with z pointing distally.  timor's
  connector frames point *away from their body* and two mated connectors face each other: timor
  places the child connector at parent connector · Rx(π).  So an output connector is rmtkit's output
  frame as it is, and an input connector is the input frame turned about x by π; rmtkit's mating
  "next input = previous output · Rz(twist)" then needs the input connector at Rx(π)·Rz(twist)
  (= Rz(−twist)·Rx(π): a twist about the outward-pointing z of timor's connector has the other sign).
* a joint module is two timor bodies (proximal, in the input frame; distal, in the output frame) and a
  joint with ``poseParent`` = axis and ``poseChild`` = out; a link, a tool and the base are one body.
* the base body carries timor's "base" connector at Rx(π) (so the base body's frame is the world) and its
  output connector at ``out``; the tool carries timor's "eef" connector at ``out`` (the TCP).
* each mating gets its own connector type ``c<k>`` so that timor's ``from_serial_modules`` connects
  module k−1 to module k and nothing else; each position is its own timor module (``m<k>``).

Offline: timor fetches its JSON schemas and the list of CoBRA robots from cobra.cps.cit.tum.de when it
is imported.  :func:`main` runs with HOME set to a temporary directory holding a timor.config whose
``schema_dir`` holds placeholder schemas (timor only checks at import that they exist; the module data
here is ours and is loaded with ``validate=False``, so no schema is used) and a cobra.config whose API
address is unreachable, and it replaces ``cobra.robot.robot.get_available_module_dbs`` (the robot list
download) by "no further robots" — timor 1.1.1 handles only a TimeoutError there, any other failure
ends in an UnboundLocalError.  Nothing of timor's own code is changed; the user's ~/.config is not read.
"""
from __future__ import annotations

import importlib
import json
import math
import os
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[3]
#: where ``make timor-venv`` puts the venv
DEFAULT_VENV = ROOT / ".venv-timor"


# ---- rmtkit's side: find the interpreter, run this file in it ----------------------------------------
#: the exit code of :func:`main` when timor (or its pinocchio, cobra-io) cannot be imported
NO_TIMOR = 3


class TimorUnavailableError(RuntimeError):
    """The interpreter cannot import timor: the comparison is skipped, not failed."""


def timor_python() -> tuple[str | None, str]:
    """(interpreter, "") for ``RMT_TIMOR_PYTHON`` or else ``.venv-timor/bin/python``, or (None, why not).
    Whether it imports timor shows when :func:`timor_reference` runs (:class:`TimorUnavailableError`)."""
    exe = os.environ.get("RMT_TIMOR_PYTHON") or ""
    if exe:
        return exe, ""
    cand = DEFAULT_VENV / "bin" / "python"
    if cand.exists():
        return str(cand), ""
    return None, "no timor-python: run `make timor-venv` or set RMT_TIMOR_PYTHON to an interpreter that has it"


def timor_reference(exe: str, modules: list[dict], states: list[dict], gravity=(0.0, 0.0, -9.81)) -> dict:
    """timor's answer for the robot ``modules`` at each state {"q", "dq", "ddq"}: {"versions": {...},
    "dof": n, "results": [{"tcp": 4×4, "joints": [4×4 joint frames in the world], "tau": [n]}]}."""
    request = {"modules": modules, "states": states, "gravity": list(gravity)}
    try:
        out = subprocess.run([exe, __file__], input=json.dumps(request), capture_output=True, text=True,
                             timeout=600)
    except OSError as e:
        raise TimorUnavailableError(f"{exe}: {e}") from None
    if out.returncode == NO_TIMOR:
        raise TimorUnavailableError(f"{exe} cannot import timor: {out.stderr.strip().splitlines()[-1]}")
    if out.returncode != 0:
        raise RuntimeError(f"timor reference failed:\n{out.stderr[-4000:]}")
    return json.loads(out.stdout)


# ---- timor's side ------------------------------------------------------------------------------------
def _offline(home: Path) -> None:
    """Config files that keep timor and cobra-io off the network (see the module docstring)."""
    cfg = home / ".config"
    schemas = home / "schemata"
    cfg.mkdir(parents=True)
    schemas.mkdir()
    for name in ("PoseSchema", "TaskSchema", "ModuleSchema", "SolutionSchema"):
        (schemas / f"{name}.json").write_text(json.dumps({
            "$schema": "https://json-schema.org/draft/2020-12/schema",
            "$id": f"urn:rmtkit:offline-placeholder:{name}"}))
    (cfg / "timor.config").write_text(f"[FILE_LOCATIONS]\nschema_dir = {schemas}\nrobots = []\n")
    (cfg / "cobra.config").write_text(
        "[LOGGING]\nfilemode = a\nlevel = WARNING\n"
        f"filename = {home / 'cobra.log'}\n"
        f"[FILE_LOCATIONS]\ncache = {home / 'cobra_cache'}\n"
        "[API]\nbase_url = http://127.0.0.1:9/api/\nversion = 2022\n")
    os.environ["HOME"] = str(home)
    # (importlib: cobra/__init__ rebinds the name cobra.robot, so `import cobra.robot.robot as` fails)
    cobra_robot = importlib.import_module("cobra.robot.robot")   # reads ~/.config/cobra.config: the one above

    cobra_robot.get_available_module_dbs = lambda *a, **k: set()


def _matmul(A, B):
    return [[sum(A[i][k] * B[k][j] for k in range(4)) for j in range(4)] for i in range(4)]


def _rx_pi_rz(t: float):
    """Rx(π)·Rz(t): where an input connector sits in its body (see the module docstring)."""
    c, s = math.cos(t), math.sin(t)
    rz = [[c, -s, 0, 0], [s, c, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]]
    rx = [[1, 0, 0, 0], [0, -1, 0, 0], [0, 0, -1, 0], [0, 0, 0, 1]]
    return _matmul(rx, rz)


_EYE = [[1.0 if i == j else 0.0 for j in range(4)] for i in range(4)]


def _connector(cid, pose, gender, ctype):
    return {"ID": cid, "pose": pose, "gender": gender, "type": ctype, "size": []}


def _body(bid, part, connectors):
    part = part or {"mass": 0.0, "com": [0.0, 0.0, 0.0], "inertia": [[0.0] * 3 for _ in range(3)]}
    return {"ID": bid, "mass": part["mass"], "r_com": part["com"], "inertia": part["inertia"],
            "connectors": connectors}


def modules_json(modules: list[dict]) -> dict:
    """timor's modules.json for the chain: one timor module per position (see the module docstring)."""
    out = []
    for k, m in enumerate(modules):
        mid, kind = f"m{k}", m["kind"]
        if (k == 0) != (kind == "base"):
            raise ValueError(f"modules[{k}]: the first module and only it is the base, got {kind}")
        if kind == "base":
            cons = [_connector(f"{mid}_base", _rx_pi_rz(0.0), "f", "base"),
                    _connector(f"{mid}_out", m["out"], "m", f"c{k + 1}")]
            bodies, joints = [_body(f"{mid}_body", None, cons)], []
        else:
            inp = _connector(f"{mid}_in", _rx_pi_rz(m["twist"]), "f", f"c{k}")
            out_con = (_connector(f"{mid}_eef", m["out"], "m", "eef") if kind == "tool"
                       else _connector(f"{mid}_out", _EYE if kind == "joint" else m["out"], "m", f"c{k + 1}"))
            if kind == "joint":
                bodies = [_body(f"{mid}_proximal", m["proximal"], [inp]),
                          _body(f"{mid}_distal", m.get("distal"), [out_con])]
                inf = float("inf")
                joints = [{"ID": f"{mid}_joint", "parent": f"{mid}_proximal", "child": f"{mid}_distal",
                           "type": m["type"], "passive": False, "poseParent": m["axis"], "poseChild": m["out"],
                           "limits": {"positionLower": -inf, "positionUpper": inf, "peakTorque": inf,
                                      "velocity": inf, "acceleration": inf},
                           "gearRatio": 1.0, "motorInertia": 0.0, "frictionCoulomb": 0.0, "frictionViscous": 0.0}]
            elif kind in ("link", "tool"):
                bodies, joints = [_body(f"{mid}_body", m["proximal"], [inp, out_con])], []
            else:
                raise ValueError(f"modules[{k}]: kind {kind!r} is not base, joint, link or tool")
        out.append({"header": {"ID": mid, "name": mid, "date": "2024-01-01"}, "bodies": bodies, "joints": joints})
    if modules[-1]["kind"] != "tool":
        raise ValueError("the last module must be a tool (timor's TCP is its eef connector)")
    return {"modules": out}


def build(modules: list[dict], gravity):
    """timor's PinRobot of the chain (import timor only after :func:`_offline`)."""
    import numpy as np
    import pinocchio as pin
    from timor import ModuleAssembly, ModulesDB

    db = ModulesDB.from_json_data(modules_json(modules), name="rmtkit_assembly", validate=False)
    assembly = ModuleAssembly.from_serial_modules(db, [f"m{k}" for k in range(len(modules))])
    robot = assembly.to_pin_robot()
    robot.model.gravity = pin.Motion(np.r_[np.asarray(gravity, float), 0.0, 0.0, 0.0])
    robot.data = robot.model.createData()
    return robot


def main() -> None:
    with tempfile.TemporaryDirectory(prefix="rmt-timor-") as home:
        try:
            _offline(Path(home))
            import numpy as np
            import pinocchio as pin
            import timor
        except ImportError as e:
            print(f"ImportError: {e}", file=sys.stderr)
            sys.exit(NO_TIMOR)
        req = json.load(sys.stdin)
        robot = build(req["modules"], req["gravity"])
        results = []
        for st in req["states"]:
            q, dq, ddq = (np.asarray(st[k], float) for k in ("q", "dq", "ddq"))
            tcp = robot.fk(q, kind="tcp").homogeneous
            joints = [T.homogeneous.tolist() for T in robot.fk(q, kind="joints")]
            tau = robot.id(q, dq, ddq, motor_inertia=False, friction=False)
            results.append({"tcp": tcp.tolist(), "joints": joints, "tau": np.atleast_1d(tau).tolist()})
        print(json.dumps({"versions": {"timor": timor.__version__, "pinocchio": pin.__version__,
                                       "numpy": np.__version__},
                          "dof": int(robot.dof), "results": results}))


if __name__ == "__main__":
    main()

"""The kinematics study: DH table, forward kinematics and Jacobian metrics at chosen configurations.

A study file (TOML) names the robot and the configurations (in the robot file's units):

    name = "fanuc_m16ib20_kinematics"
    robot = "fanuc_m16ib20"
    [[configurations]]
    label = "home"
    q = [0, 0, 0, 0, 0, 0]

:func:`run_kinematics_study` returns a JSON-ready dict; :func:`write_results` stores it atomically.
"""
from __future__ import annotations

import json
import math
import tomllib
from pathlib import Path

import kin
from kin.chain import DH_FIELDS, LENGTH_FIELDS, NAME_RE
from kin.compiled import numpy_measures
from kin.output import write_output
from studies.jsonio import finite_or_none
from studies.units import jacobian_to_file, joint_units, pose_to_file, unit_names

STUDY_DIR = Path(__file__).parent.parent
DEFAULT_STUDY = STUDY_DIR / "default_study.toml"
STUDY_FIELDS = ("name", "title", "robot", "configurations", "singularities", "windows", "workspace", "plan")
CONFIG_FIELDS = ("label", "q")
#: the largest seed a study accepts (OMPL and numpy take 32-bit seeds)
MAX_SEED = 2**32 - 1
#: the optional sections: key → (type, default (None: required), lowest, highest, meaning)
SECTIONS: dict[str, dict[str, tuple]] = {
    "singularities": {},
    "windows": {"margin": (float, None, 0.0, None, "half-width of every window, robot file units")},
    "workspace": {"samples": (int, 100_000, 1, 10_000_000, "joint-space samples"),
                  "seed": (int, 0, 0, MAX_SEED, "sampling seed")},
    "plan": {"start": (list, None, None, None, "start configuration, robot file units"),
             "goal": (list, None, None, None, "goal configuration, robot file units"),
             "planner": (str, "RRTConnect", None, None, "OMPL planner name"),
             "time_limit": (float, 2.0, 0.001, 600.0, "planning time limit, s"),
             "seed": (int, 0, 0, MAX_SEED, "OMPL seed"),
             "objective": (str, "none", None, None, "none | length | singularity")},
}


class StudyFileError(kin.RmtError):
    """A study file is missing or invalid."""


def _value(path, section: str, key: str, v, spec: tuple):
    kind, _, lo, hi, meaning = spec
    fld = f"{path}: {section}.{key}"
    if kind is float and isinstance(v, (int, float)) and not isinstance(v, bool):
        v = float(v)
        if not math.isfinite(v):
            raise StudyFileError(f"{fld}: must be a finite number ({meaning})")
    elif kind is int and isinstance(v, int) and not isinstance(v, bool):
        pass
    elif kind is str and isinstance(v, str):
        return v
    elif kind is list and isinstance(v, list):
        if not all(isinstance(x, (int, float)) and not isinstance(x, bool) and math.isfinite(x) for x in v):
            raise StudyFileError(f"{fld}: must be a list of finite numbers ({meaning})")
        return [float(x) for x in v]
    else:
        raise StudyFileError(f"{fld}: {v!r} is not {'an' if kind is int else 'a'} "
                             f"{ {float: 'number', int: 'integer', str: 'string', list: 'list'}[kind]} ({meaning})")
    if (lo is not None and v < lo) or (hi is not None and v > hi):
        rng = f"[{lo:g}, {hi:g}]" if hi is not None else f"≥ {lo:g}"
        raise StudyFileError(f"{fld}: {v:g} is outside the allowed range {rng} ({meaning})")
    return v


def _section(path, name: str, raw) -> dict:
    """A validated optional section with its defaults filled in."""
    if not isinstance(raw, dict):
        raise StudyFileError(f"{path}: {name}: must be a table ([{name}])")
    spec = SECTIONS[name]
    unknown = [k for k in raw if k not in spec]
    if unknown:
        raise StudyFileError(f"{path}: {name}.{unknown[0]}: unknown field; allowed: {', '.join(spec) or 'none'}")
    out = {}
    for key, sp in spec.items():
        if key in raw:
            out[key] = _value(path, name, key, raw[key], sp)
        elif sp[1] is None:
            raise StudyFileError(f"{path}: {name}.{key}: missing ({sp[4]})")
        else:
            out[key] = sp[1]
    return out


def _robot_reference(path: Path, robot: str) -> str:
    """A bundled name stays a name; a path is taken relative to the study file's directory."""
    if robot in kin.bundled_robots() and "/" not in robot and not robot.endswith(".toml"):
        return robot
    p = Path(robot).expanduser()
    return str(p if p.is_absolute() else path.parent / p)


def load_study(path: str | Path) -> dict:
    """Read and validate a study file (format: docs/studies.md, "Study files"); returns {name, title, robot,
    configurations: [(label, q_file)], and each optional section with its defaults filled in}.

    Everything is checked before anything runs: unknown fields, types, ranges, the robot (a bundled
    name or a robot file relative to the study file) and every configuration's length."""
    path = Path(path)
    try:
        doc = tomllib.loads(path.read_text(encoding="utf-8"))
    except FileNotFoundError:
        raise StudyFileError(f"{path}: no such study file") from None
    except (OSError, UnicodeDecodeError, tomllib.TOMLDecodeError) as e:
        raise StudyFileError(f"{path}: cannot read study file ({e})") from None
    unknown = [k for k in doc if k not in STUDY_FIELDS]
    if unknown:
        raise StudyFileError(f"{path}: {unknown[0]}: unknown field; allowed: {', '.join(STUDY_FIELDS)}")
    for k in ("name", "robot"):
        if not isinstance(doc.get(k), str):
            raise StudyFileError(f"{path}: {k}: missing or not a string")
    if not NAME_RE.match(doc["name"]):
        raise StudyFileError(f"{path}: name: {doc['name']!r} must match [a-z0-9_]+ (it names the output directory)")
    if not isinstance(doc.get("title", ""), str):
        raise StudyFileError(f"{path}: title: must be a string")
    robot = _robot_reference(path, doc["robot"])
    chain = kin.load_chain(robot)
    units = ", ".join(chain.angle_unit if j.is_revolute else chain.length_unit for j in chain.joints)
    configs = doc.get("configurations", [])
    if not isinstance(configs, list) or not configs:
        raise StudyFileError(f"{path}: configurations: needs at least one [[configurations]] table")
    out = []
    for i, c in enumerate(configs):
        fld = f"configurations[{i}]"
        if not isinstance(c, dict) or any(k not in CONFIG_FIELDS for k in c):
            raise StudyFileError(f"{path}: {fld}: must be a table with fields {', '.join(CONFIG_FIELDS)}")
        q = c.get("q")
        if (not isinstance(q, list) or not all(isinstance(x, (int, float)) and not isinstance(x, bool) for x in q)
                or not all(math.isfinite(x) for x in q)):
            raise StudyFileError(f"{path}: {fld}.q: must be a list of finite numbers (robot file units)")
        if len(q) != chain.n:
            raise StudyFileError(f"{path}: {fld}.q: {len(q)} values; {chain.name} has {chain.n} joints ({units})")
        label = c.get("label", f"config {i + 1}")
        if not isinstance(label, str):
            raise StudyFileError(f"{path}: {fld}.label: must be a string")
        out.append((label, [float(x) for x in q]))
    study = {"name": doc["name"], "title": doc.get("title", ""), "robot": robot, "configurations": out}
    for section in SECTIONS:
        if section in doc:
            study[section] = _section(path, section, doc[section])
    if "plan" in study:
        for what in ("start", "goal"):
            q = study["plan"][what]
            if len(q) != chain.n:
                raise StudyFileError(f"{path}: plan.{what}: {len(q)} values; {chain.name} has {chain.n} joints "
                                     f"({units})")
        if study["plan"]["objective"] not in ("none", "length", "singularity"):
            raise StudyFileError(f"{path}: plan.objective: {study['plan']['objective']!r} unknown; allowed: none, "
                                 "length, singularity")
    return study


def dh_rows(chain: kin.Chain) -> list[dict]:
    """The DH table in the file's units, parameters shown by name."""
    rows = []
    for i, j in enumerate(chain.joints, 1):
        row = {"joint": i, "type": j.type}
        for f in DH_FIELDS:
            v = getattr(j, f)
            scale = chain.length_scale if f in LENGTH_FIELDS else chain.angle_scale
            row[f] = v if isinstance(v, str) else float(v) / scale
        scale = chain.angle_scale if j.is_revolute else chain.length_scale
        row["limits"] = [j.limits[0] / scale, j.limits[1] / scale]
        rows.append(row)
    return rows


def evaluate_configuration(robot: kin.Robot, q_file) -> dict:
    """FK and Jacobian metrics of one configuration given in file units; results in file units."""
    chain = robot.chain
    q = chain.to_si(q_file)
    T, J = robot.fk_jacobian(q)
    m_si = robot.measures(q)
    Jf = jacobian_to_file(chain, J)
    mf = numpy_measures(Jf[None][:, list(robot.task_rows), :])[0]
    violations = [{"joint": i, "value": v / chain.variable_scale[i - 1],
                   "limits": [lim[0] / chain.variable_scale[i - 1], lim[1] / chain.variable_scale[i - 1]]}
                  for i, v, lim in chain.limit_violations(q)]
    return {
        "q": list(map(float, q_file)),
        "T": pose_to_file(chain, T).tolist(),
        "position": (T[:3, 3] / chain.length_scale).tolist(),
        "J": Jf.tolist(),
        "manipulability": finite_or_none(mf[0]), "sigma_min": finite_or_none(mf[1]),
        "condition": finite_or_none(mf[2]),
        "det": None if math.isnan(mf[3]) else float(mf[3]),
        "si": {"manipulability": finite_or_none(m_si.manipulability),
               "sigma_min": finite_or_none(m_si.sigma_min),
               "condition": finite_or_none(m_si.condition),
               "det": None if math.isnan(m_si.det) else float(m_si.det)},
        "within_limits": not violations,
        "limit_violations": violations,
    }


def run_kinematics_study(study: dict) -> dict:
    """Evaluate a loaded study; returns a JSON-ready dict."""
    robot = kin.load_robot(study["robot"])
    chain = robot.chain
    results = []
    for label, q_file in study["configurations"]:
        if len(q_file) != chain.n:
            raise StudyFileError(f"configuration {label!r} has {len(q_file)} values; {chain.name} has {chain.n} joints")
        results.append({"label": label, **evaluate_configuration(robot, q_file)})
    return {
        "study": study["name"], "title": study.get("title", ""),
        "robot": {"name": chain.name, "title": chain.title, "source": chain.source, "n": chain.n,
                  "convention": chain.convention, "units": unit_names(chain), "joint_units": joint_units(chain),
                  "task_rows": [["x", "y", "z", "rx", "ry", "rz"][r] for r in robot.task_rows],
                  "dh": dh_rows(chain)},
        "backend": robot.backend,
        "configurations": results,
    }


def write_results(results: dict, out_dir: str | Path) -> Path:
    """Write ``results.json`` (strict JSON: NaN and infinities are refused) into ``out_dir`` with
    :func:`kin.output.write_output`; returns its path."""
    return write_output(Path(out_dir) / "results.json", json.dumps(results, indent=2, allow_nan=False) + "\n")

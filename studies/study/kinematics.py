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
import os
import tomllib
from pathlib import Path

import kin
from kin.chain import DH_FIELDS, LENGTH_FIELDS
from kin.compiled import numpy_measures

from studies.units import jacobian_to_file, joint_units, pose_to_file, unit_names

STUDY_DIR = Path(__file__).parent.parent
DEFAULT_STUDY = STUDY_DIR / "default_study.toml"
STUDY_FIELDS = ("name", "title", "robot", "configurations", "singularities", "windows", "workspace", "plan")
CONFIG_FIELDS = ("label", "q")


class StudyFileError(kin.RmtError):
    """A study file is missing or invalid."""


def load_study(path: str | Path) -> dict:
    """Read and validate a study file; returns {name, title, robot, configurations: [(label, q_file)]}."""
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
        out.append((str(c.get("label", f"config {i + 1}")), [float(x) for x in q]))
    study = {"name": doc["name"], "title": doc.get("title", ""), "robot": doc["robot"], "configurations": out}
    for section in ("singularities", "windows", "workspace", "plan"):
        if section in doc:
            if not isinstance(doc[section], dict):
                raise StudyFileError(f"{path}: {section}: must be a table ([{section}])")
            study[section] = doc[section]
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
        "manipulability": _num(mf[0]), "sigma_min": _num(mf[1]), "condition": _num(mf[2]),
        "det": None if math.isnan(mf[3]) else float(mf[3]),
        "si": {"manipulability": _num(m_si.manipulability), "sigma_min": _num(m_si.sigma_min),
               "condition": _num(m_si.condition)},
        "within_limits": not violations,
        "limit_violations": violations,
    }


def _num(x: float) -> float | None:
    """JSON has no inf: an infinite condition number (exact singularity) is written as null."""
    x = float(x)
    return x if math.isfinite(x) else None


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
    """Write ``results.json`` into ``out_dir`` atomically; returns its path."""
    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    path = out_dir / "results.json"
    tmp = out_dir / f".results.json.{os.getpid()}.tmp"
    tmp.write_text(json.dumps(results, indent=2) + "\n", encoding="utf-8")
    tmp.replace(path)
    return path

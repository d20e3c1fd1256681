"""Study files: every field validated before anything runs, with one-line errors naming the field."""
from __future__ import annotations

import pytest

from studies.study import StudyFileError, load_study

BASE = '''name = "s"
robot = "scara_rrp"
[[configurations]]
q = [0.0, 0.5, -100.0]
'''


def _study(tmp_path, text, name="s.toml"):
    p = tmp_path / name
    p.write_text(text, encoding="utf-8")
    return p


@pytest.mark.parametrize("extra,msg", [
    ("[plan]\nstart = [0.7]\ngoal = [0.0, 0.5, -100.0]\n", "plan.start: 1 values; scara_rrp has 3 joints"),
    ("[plan]\nstart = [0.0, 0.5, -100.0]\ngoal = [0.0, 0.5, -100.0]\nplaner = 'RRT'\n", "plan.planer: unknown field"),
    ("[plan]\nstart = [0.0, 0.5, -100.0]\ngoal = [0.0, 0.5, -100.0]\ntime_limit = 1e308\n",
     "plan.time_limit: 1e+308 is outside the allowed range [0.001, 600]"),
    ("[plan]\nstart = [0.0, 0.5, -100.0]\ngoal = [0.0, 0.5, -100.0]\nseed = -1\n", "plan.seed: -1 is outside"),
    ("[plan]\nstart = [0.0, 0.5, -100.0]\ngoal = [0.0, 0.5, -100.0]\nobjective = 'fast'\n", "plan.objective"),
    ("[plan]\nstart = [0.0, 0.5, -100.0]\n", "plan.goal: missing"),
    ("[plan]\nstart = [0.0, 0.5, nan]\ngoal = [0.0, 0.5, -100.0]\n", "plan.start: must be a list of finite"),
    ("[workspace]\nsamples = 0\n", "workspace.samples: 0 is outside"),
    ("[workspace]\nsamples = 1.5\n", "workspace.samples: 1.5 is not an integer"),
    ("[windows]\nmargin = -1\n", "windows.margin: -1 is outside"),
    ("[windows]\nmargin = inf\n", "windows.margin: must be a finite number"),
    ("[windows]\n", "windows.margin: missing"),
    ("[singularities]\nfast = true\n", "singularities.fast: unknown field"),
    ("planer = 1\n", "planer: unknown field"),
])
def test_bad_study_files(tmp_path, extra, msg):
    text = BASE + extra if not extra.startswith("planer") else extra + BASE
    with pytest.raises(StudyFileError, match=msg.replace("[", r"\[").replace("+", r"\+")) as e:
        load_study(_study(tmp_path, text))
    assert "\n" not in str(e.value)


def test_configuration_length_and_name(tmp_path):
    with pytest.raises(StudyFileError, match=r"configurations\[0\].q: 2 values"):
        load_study(_study(tmp_path, BASE.replace("[0.0, 0.5, -100.0]", "[0.0, 0.5]")))
    with pytest.raises(StudyFileError, match="name: '../x' must match"):
        load_study(_study(tmp_path, BASE.replace('name = "s"', 'name = "../x"')))


def test_defaults_filled_in(tmp_path):
    s = load_study(_study(tmp_path, BASE + "[plan]\nstart = [0.0, 0.5, -100.0]\ngoal = [0.1, 0.5, -100.0]\n"
                                            "[workspace]\n"))
    assert s["plan"] == {"start": [0.0, 0.5, -100.0], "goal": [0.1, 0.5, -100.0], "planner": "RRTConnect",
                         "time_limit": 2.0, "seed": 0, "objective": "none"}
    assert s["workspace"] == {"samples": 100_000, "seed": 0}


def test_robot_path_is_relative_to_the_study_file(tmp_path, monkeypatch):
    from kin.robotfile import ROBOT_DIR
    sub = tmp_path / "project"
    sub.mkdir()
    (sub / "arm.toml").write_text((ROBOT_DIR / "planar_2r.toml").read_text())
    p = _study(sub, 'name = "s"\nrobot = "arm.toml"\n[[configurations]]\nq = [0.0, 0.5]\n')
    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    monkeypatch.chdir(elsewhere)
    s = load_study(p)
    assert s["robot"] == str(sub / "arm.toml")


def test_the_documented_study_example_loads(tmp_path):
    """The study-file example of docs/studies.md is a valid study with every key it documents."""
    import re
    from pathlib import Path

    from studies.study.kinematics import SECTIONS
    page = (Path(__file__).resolve().parents[3] / "docs" / "studies.md").read_text()
    text = re.search(r"## Study files.*?```toml\n(.*?)```", page, re.S).group(1)
    s = load_study(_study(tmp_path, text))
    assert s["robot"] == "fanuc_m16ib20" and s["configurations"][0][0] == "ready"
    for section, keys in SECTIONS.items():
        assert set(s[section]) == set(keys), section        # every documented key is in the example

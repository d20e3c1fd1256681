"""Fuzz: generated robot files, joint paths, tool paths and study files, each fed to the commands
that read it, run in-process against the contract of :mod:`tests.fuzz.contract`."""
from __future__ import annotations

import os
import tempfile
from pathlib import Path

import pytest
from hypothesis import given
from hypothesis import strategies as st

from tests.fuzz.contract import FUZZ, run_contract
from tests.fuzz.strategies import mostly, number_text, toml_number, toml_vector


@pytest.fixture(scope="module", autouse=True)
def no_compiler():
    """Generated robots run in CasADi's VM: the same numbers, without compiling a kernel for each."""
    old = os.environ.get("RMTKIT_CC")
    os.environ["RMTKIT_CC"] = "none"
    yield
    if old is None:
        os.environ.pop("RMTKIT_CC", None)
    else:
        os.environ["RMTKIT_CC"] = old


def _run(files: dict[str, str], argv: list[str], outputs: tuple[str, ...] = ()):
    with tempfile.TemporaryDirectory() as d:
        cwd = Path(d)
        for name, text in files.items():
            (cwd / name).write_text(text, encoding="utf-8")
        return run_contract(argv, cwd, outputs)


# ---- robot files ---------------------------------------------------------------------------------
TASKS = ['["x", "y"]', '["z"]', "[]", '["q"]', '["x", "x"]']
SAMPLES = ["200", "0", "-5", "1.5", "1e9", '"x"']
PLAN_VALUES = ["-1", "3", '"PRM*"', '"length"', "1e308"]
@st.composite
def robot_file(draw) -> tuple[str, int]:
    n = draw(st.integers(1, 3))
    pick = lambda good, bad: draw(mostly(st.sampled_from(good), st.sampled_from(bad), 20))
    lines = [f'name = "{pick(["fz", "fz_2"], ["Bad Name", ""])}"',
             f'convention = "{pick(["standard", "modified"], ["weird"])}"',
             f'length_unit = "{pick(["m", "mm", "in"], ["km"])}"',
             f'angle_unit = "{pick(["rad", "deg"], ["grad"])}"']
    if draw(st.integers(0, 5)) == 0:
        lines.append("task = " + draw(st.sampled_from(TASKS)))
    for _ in range(n):
        lines += ["[[joints]]", f'type = "{pick(["revolute", "revolute", "prismatic"], ["ball"])}"']
        for f in ("a", "alpha", "d", "theta"):
            if draw(st.booleans()):
                lines.append(f"{f} = {draw(toml_number(-2, 2))}")
        lo = draw(st.floats(-3, 0, allow_nan=False))
        lines.append(f"limits = {draw(mostly(st.just(f'[{lo!r}, {lo + 2.5!r}]'), toml_vector(2), 10))}")
        if draw(st.integers(0, 5)) == 0:
            lines.append(f"{draw(st.sampled_from(['max_velocity', 'speed', 'name']))} = {draw(toml_number(-1, 5))}")
    if draw(st.integers(0, 3)) == 0:
        lines += ["[tool]", f"xyz = {draw(toml_vector(3))}"]
    return "\n".join(lines) + "\n", n


@FUZZ
@given(robot_file(), st.sampled_from(["show", "fk", "jacobian", "singularities"]), st.booleans())
def test_robot_files(case, command, as_json):
    text, n = case
    argv = [command, "r.toml"] + (["0.1"] * n if command in ("fk", "jacobian") else [])
    if command == "singularities" and n > 2:
        argv[0] = "jacobian"                     # keep sympy's factoring small
        argv += ["0.1"] * n
    _run({"r.toml": text}, argv + (["--json"] if as_json else []))


# ---- joint paths -----------------------------------------------------------------------------------
@st.composite
def joint_path(draw) -> str:
    rows = []
    if draw(st.booleans()):
        rows.append(draw(st.sampled_from(["q1,q2", "q1", "a,b,c", "# comment"])))
    for _ in range(draw(st.integers(0, 6))):
        k = draw(mostly(st.just(2), st.sampled_from([1, 3]), 15))
        rows.append(",".join(draw(number_text(-3, 3)) for _ in range(k)))
    return "\n".join(rows) + "\n"


@FUZZ
@given(joint_path(), st.lists(st.tuples(st.sampled_from(["--margin", "--step", "--sigma-floor"]), number_text(0, 0.2)),
                              max_size=2, unique_by=lambda t: t[0]), st.booleans())
def test_joint_paths(text, options, as_json):
    extra = [x for pair in options for x in pair] + (["--json"] if as_json else [])
    _run({"p.csv": text}, ["check-path", "planar_2r", "p.csv"] + extra)


# ---- tool paths ------------------------------------------------------------------------------------
@st.composite
def toolpath_csv(draw) -> str:
    cols = draw(st.sampled_from([["x", "y", "z"], ["x", "y", "z", "feed"], ["x", "y", "z", "t"],
                                 ["x", "y", "z", "roll", "pitch", "yaw"], ["x", "y"], ["x", "y", "z", "qw"]]))
    rows = [",".join(cols)]
    for i in range(draw(st.integers(0, 6))):
        vals = []
        for c in cols:
            if c in ("x", "y"):
                vals.append(draw(st.one_of(st.floats(-1.5, 1.5, allow_nan=False).map(repr), number_text())))
            elif c == "t":
                vals.append(draw(st.one_of(st.just(str(i)), number_text())))
            elif c == "feed":
                vals.append(draw(mostly(st.just("0.1"), number_text(-1, 1), 6)))
            else:
                vals.append(draw(st.one_of(st.just("0"), number_text())))
        rows.append(",".join(vals))
    return "\n".join(rows) + "\n"


@st.composite
def toolpath_toml(draw) -> str:
    lines = [f"feed = {draw(mostly(st.just('0.1'), toml_number(-1, 1), 6))}", "[start]",
             f"xyz = {draw(mostly(st.just('[1.2, 0.3, 0.0]'), toml_vector(3), 6))}"]
    for _ in range(draw(st.integers(0, 3))):
        kind = draw(mostly(st.sampled_from(["line", "arc"]), st.just("spline"), 8))
        lines += ["[[segments]]", f'type = "{kind}"', f"to = {draw(toml_vector(3, -1.5, 1.5))}",
                  draw(mostly(st.sampled_from(["points = 3", "step = 0.5"]),
                              st.sampled_from(["points = 0", "points = -1", "step = 1e-300", "points = 1e9"]), 5))]
        if kind == "arc":
            lines += [f"center = {draw(toml_vector(3, -1, 1))}", f"normal = {draw(toml_vector(3, -1, 1))}"]
    return "\n".join(lines) + "\n"


@FUZZ
@given(st.one_of(toolpath_csv().map(lambda t: ("p.csv", t)), toolpath_toml().map(lambda t: ("p.toml", t))),
       st.booleans())
def test_tool_paths(case, as_json):
    name, text = case
    _run({name: text}, ["validate-toolpath", "planar_2r", name] + (["--json"] if as_json else []))


# ---- study files -----------------------------------------------------------------------------------
@st.composite
def study_file(draw) -> str:
    pick = lambda good, bad: draw(mostly(st.sampled_from(good), st.sampled_from(bad), 10))
    lines = [f'name = "{pick(["fz", "fz_study"], ["../up", "x y"])}"',
             f'robot = "{pick(["planar_2r", "r.toml"], ["nope"])}"']
    if draw(mostly(st.just(False), st.just(True), 8)):
        lines.append(f"{draw(st.sampled_from(['planer', 'title']))} = {draw(toml_number())}")
    for _ in range(draw(mostly(st.integers(1, 2), st.just(0), 10))):
        lines += ["[[configurations]]", f"q = {draw(toml_vector(2))}"]
    if draw(st.booleans()):
        lines += ["[windows]", f"margin = {draw(mostly(st.just('0.05'), toml_number(-1, 4), 5))}"]
    if draw(st.integers(0, 3)) == 0:
        lines += ["[workspace]", "samples = " + draw(st.sampled_from(SAMPLES))]
    if draw(st.booleans()):
        lines += ["[plan]", f"start = {draw(mostly(st.just('[0.1, 0.5]'), toml_vector(2), 5))}",
                  f"goal = {draw(mostly(st.just('[0.4, 0.9]'), toml_vector(2), 5))}",
                  f"time_limit = {pick(['0.05', '0.1'], ['0', '-1', 'nan', '1e308'])}"]
        if draw(st.booleans()):
            lines.append(draw(st.sampled_from(["seed", "planner", "objective", "planer"])) + " = "
                         + draw(st.sampled_from(PLAN_VALUES)))
    return "\n".join(lines) + "\n"


@FUZZ
@given(study_file(), st.booleans())
def test_study_files(text, as_json):
    robot = (Path(__file__).resolve().parents[2] / "kin" / "robots" / "planar_2r.toml").read_text()
    _run({"s.toml": text, "r.toml": robot}, ["study", "s.toml", "--out", "out", "--quiet"]
         + (["--json"] if as_json else []), outputs=("out",))


# ---- planning scenes (rmt import-scene) ------------------------------------------------------------
SHAPE_DIMS = {"box": 3, "sphere": 1, "cylinder": 2, "cone": 2, "1": 3, "3": 2}


@st.composite
def scene_yaml(draw) -> str:
    objects = []
    for k in range(draw(st.integers(0, 4))):
        kind = draw(mostly(st.sampled_from(sorted(SHAPE_DIMS)), st.sampled_from(["torus", "5", "true", "plane"]), 8))
        n = draw(mostly(st.just(SHAPE_DIMS.get(kind, 2)), st.integers(0, 4), 10))
        dims = ", ".join(draw(mostly(st.floats(0.01, 1).map(repr), number_text(-1, 1), 6)) for _ in range(n))
        pos = ", ".join(draw(number_text(-2, 2)) for _ in range(3))
        quat = draw(mostly(st.sampled_from(["[0, 0, 0, 1]", "[0, 0, 0.7071068, 0.7071068]", "[0, 0, 0, 0]"]),
                           st.sampled_from(["[0, 0, 0, 2]", "[1, 2]", "[.nan, 0, 0, 1]", "{x: 1}", "7"]), 6))
        name = draw(mostly(st.sampled_from(["base", "tool", "link 3", "table", f"o{k}"]),
                           st.sampled_from(['""', '"a\\x07"', "[1]", "o0", "true"]), 8))
        extra = draw(mostly(st.just(""), st.sampled_from([", operation: remove", ", header: {frame_id: tool0}",
                                                          ", planes: [{coef: [0, 0, 1, 0]}]", ", pose: 3"]), 8))
        objects.append(f"    - {{id: {name}, primitives: [{{type: {kind}, dimensions: [{dims}]}}], "
                       f"primitive_poses: [{{position: [{pos}], orientation: {quat}}}]{extra}}}")
    head = draw(mostly(st.just(""), st.sampled_from(["a: &a [1]\nb: *a\n", "robot_state: 3\n", "name: 3\n",
                                                     "start_state: {}\n", "{"]), 8))
    body = "world:\n  collision_objects:\n" + "\n".join(objects) + "\n" if objects else "world: {}\n"
    return head + body


@st.composite
def scene_text(draw) -> str:
    lines = [draw(st.sampled_from(["cell", "(noname)", ""]))]
    for k in range(draw(st.integers(0, 3))):
        kind, n = draw(mostly(st.sampled_from([("box", 3), ("sphere", 1), ("cylinder", 2), ("cone", 2)]),
                              st.sampled_from([("plane", 4), ("torus", 1), ("mesh", 2)]), 8))
        lines += [f"* {draw(st.sampled_from(['base', 'a b', f'o{k}', 'o0']))}", "0 0 0", "0 0 0 1",
                  draw(mostly(st.just("1"), st.sampled_from(["0", "-1", "x", "1001"]), 8)), kind,
                  " ".join(draw(mostly(st.floats(0.01, 1).map(repr), number_text(-1, 1), 6)) for _ in range(n)),
                  " ".join(draw(number_text(-2, 2)) for _ in range(3)),
                  draw(mostly(st.just("0 0 0 1"), st.sampled_from(["0 0 0 3", "0 0", "nan 0 0 1"]), 6))]
        if draw(st.booleans()):
            lines.append("0 0 0 0")
        lines.append(draw(mostly(st.just("0"), st.sampled_from(["2", "x"]), 8)))
    if draw(mostly(st.just(True), st.just(False), 8)):
        lines.append(".")
    return "\n".join(lines) + "\n"


@FUZZ
@given(st.one_of(scene_yaml().map(lambda t: ("s.yaml", t)), scene_text().map(lambda t: ("s.scene", t))),
       st.booleans())
def test_planning_scenes(case, as_json):
    name, text = case
    _run({name: text}, ["import-scene", name, "--out", "c.toml"] + (["--json"] if as_json else []), outputs=("c.toml",))

"""Task files: the bundled examples load; every bad field gives one TaskError line naming file and field;
the CLI prints that line and exits 2."""
from pathlib import Path

import numpy as np
import pytest

import kin
from design.task import TaskError, load_task, loads_task
from planning.toolpath import load_toolpath
from studies.cli.main import main

GOOD = '''
name = "t"
robot = "studies/tasks/robots/scara_design.toml"
length_unit = "mm"
angle_unit = "deg"
[target]
shape = "box"
min = [150, -150, -150]
max = [350, 150, -150]
count = [3, 2, 1]
[dexterity]
sigma_min = 0.05
'''


def test_good_file_in_si():
    t = loads_task(GOOD, "t.toml")
    assert t.targets.positions.shape == (6, 3)
    assert np.allclose(t.targets.positions[0], [0.15, -0.15, -0.15])
    assert t.dexterity.kind == "sigma_min" and t.dexterity.value == 0.05
    assert t.objective == "length" and t.min_coverage == 1.0


@pytest.mark.parametrize("name", ["planar_ring", "scara_box", "ring_codesign"])
def test_bundled_tasks_load(name):
    assert len(load_task(f"studies/tasks/{name}.toml").targets) > 0


@pytest.mark.parametrize("edit,field", [
    (("shape = \"box\"", "shape = \"cube\""), "target.shape"),
    (("count = [3, 2, 1]", "count = [3, 2]"), "target.count"),
    (("count = [3, 2, 1]", "count = [3, 0, 1]"), "target.count[1]"),
    (("max = [350, 150, -150]", "max = [100, 150, -150]"), "target.max"),
    (("sigma_min = 0.05", "sigma_min = -1"), "dexterity.sigma_min"),
    (("sigma_min = 0.05", "sigma_min = \"big\""), "dexterity.sigma_min"),
    (("length_unit = \"mm\"", "length_unit = \"km\""), "length_unit"),
    (("name = \"t\"", "name = \"t\"\nobjective = \"speed\""), "objective"),
    (("name = \"t\"", "name = \"t\"\nbogus = 1"), "bogus"),
    (("name = \"t\"", "name = \"t\"\narchitecture = [\"RRX\"]"), "architecture[0]"),
    (("sigma_min = 0.05", "sigma_min = 0.05\n[constraints]\nmin_coverage = 1.5"), "constraints.min_coverage"),
    (("robot = \"studies/tasks/robots/scara_design.toml\"", "robot = \"nope\""), "robot"),
    (("shape = \"box\"", "shape = \"box\"\norientation = \"axis\""), "target.axis"),
    (("shape = \"box\"", "shape = \"box\"\norientation = \"cone\"\naxis = [0, 0, 1]\nhalf_angle = 95"),
     "target.half_angle"),
])
def test_bad_fields_name_the_field(edit, field):
    with pytest.raises(TaskError) as e:
        loads_task(GOOD.replace(*edit), "t.toml")
    msg = str(e.value)
    assert msg.startswith(f"t.toml: {field}: ") and "\n" not in msg


def test_not_toml_and_missing_fields():
    with pytest.raises(TaskError, match="not valid TOML"):
        loads_task("name = ", "x.toml")
    with pytest.raises(TaskError, match="x.toml: target: missing"):
        loads_task('name = "a"\nrobot = "scara_rrp"\nlength_unit = "m"\nangle_unit = "rad"\n', "x.toml")


def test_cli_bad_task_one_line_exit_2(tmp_path, capsys):
    bad = tmp_path / "bad.toml"
    bad.write_text(GOOD.replace("sigma_min = 0.05", "sigma_min = -1"))
    assert main(["coverage", "scara_rrp", str(bad)]) == 2
    err = capsys.readouterr().err.strip()
    assert err.count("\n") == 0 and "dexterity.sigma_min" in err and str(bad) in err


def test_toolpath_and_points_targets(tmp_path):
    text = GOOD.replace('robot = "studies/tasks/robots/scara_design.toml"', 'robot = "scara_rrp"')
    tp = text.replace('shape = "box"\nmin = [150, -150, -150]\nmax = [350, 150, -150]\ncount = [3, 2, 1]',
                      f'shape = "toolpath"\nfile = "{Path("studies/toolpaths/scara_line.csv").resolve()}"')
    task = loads_task(tp, "t.toml")
    ref = load_toolpath("studies/toolpaths/scara_line.csv", kin.load_robot("scara_rrp"))
    assert np.allclose(task.targets.positions, ref.poses[:, :3, 3])
    (tmp_path / "p.csv").write_text("x,y,z,ax,ay,az\n100,0,-150,0,0,-1\n200,50,-150,0,0,-2\n")
    pts = text.replace('shape = "box"\nmin = [150, -150, -150]\nmax = [350, 150, -150]\ncount = [3, 2, 1]',
                       'shape = "points"\nfile = "p.csv"\norientation = "cone"\nhalf_angle = 10')
    task = loads_task(pts, str(tmp_path / "t.toml"), tmp_path)
    assert np.allclose(task.targets.positions, [[0.1, 0, -0.15], [0.2, 0.05, -0.15]])
    assert np.allclose(task.targets.axes, [[0, 0, -1], [0, 0, -1]])          # normalised
    assert task.targets.cone_half_angle == pytest.approx(np.radians(10))
    (tmp_path / "bad.csv").write_text("1,2\n")
    with pytest.raises(TaskError, match="bad.csv: line 1"):
        loads_task(pts.replace("p.csv", "bad.csv"), "t.toml", tmp_path)

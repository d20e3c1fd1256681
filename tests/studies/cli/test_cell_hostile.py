"""Hostile cell files through the command line: one line on stderr naming the file, the obstacle and
the field, exit code 2 — for every command that takes ``--cell``; nothing crashes or hangs."""
from __future__ import annotations

import pytest

from studies.cli import main

BAD = {
    "nan_size": ("[[obstacle]]\nname = 'b'\ntype = 'box'\nsize = [nan, 1, 1]\n", "size"),
    "negative_radius": ("[[obstacle]]\nname = 's'\ntype = 'sphere'\nradius = -0.1\n", "radius"),
    "unknown_shape": ("[[obstacle]]\nname = 'x'\ntype = 'torus'\n", "torus"),
    "missing_mesh": ("[[obstacle]]\nname = 'm'\ntype = 'mesh'\nfile = 'nowhere.stl'\n", "nowhere.stl"),
    "not_a_mesh": ("[[obstacle]]\nname = 'm'\ntype = 'mesh'\nfile = 'text.stl'\n", "text.stl"),
    "huge_cloud": ("[[obstacle]]\nname = 'scan'\ntype = 'point_cloud'\nfile = 'huge.csv'\npoint_radius = 0.01\n",
                   "huge.csv"),
    "not_toml": ("[[obstacle\nname = ", "TOML"),
    "unknown_body": ("[[obstacle]]\nname = 'b'\ntype = 'box'\nsize = [1, 1, 1]\nxyz = [3, 3, 3]\n"
                     "ignore = ['link 9']\n", "link 9"),
}
COMMANDS = {
    "plan": ["plan", "fanuc_lrmate200id", "--start", "0", "0", "0", "0", "-90", "0", "--goal", "10", "0", "0", "0",
             "-90", "0"],
    "check-path": ["check-path", "fanuc_lrmate200id", "PATH"],
    "clearance": ["clearance", "fanuc_lrmate200id", "0", "0", "0", "0", "-90", "0"],
    "validate-toolpath": ["validate-toolpath", "fanuc_lrmate200id", "fanuc_weld_seam"],
    "coverage": ["coverage", "fanuc_lrmate200id", "POINTS"],
    "place": ["place", "fanuc_lrmate200id", "TASK"],
    "reach": ["reach", "fanuc_lrmate200id", "TASK"],
}


@pytest.fixture(scope="module")
def files(tmp_path_factory):
    d = tmp_path_factory.mktemp("hostile")
    (d / "text.stl").write_text("this is not a mesh\n" * 20)
    with open(d / "huge.csv", "w") as f:
        f.write("0.1,0.2,0.3\n" * 1_000_000)
    (d / "path.csv").write_text("0,0,0,0,-90,0\n10,0,0,0,-90,0\n")
    (d / "points.csv").write_text("400,0,400\n")
    (d / "task.toml").write_text('name = "t"\nrobot = "fanuc_lrmate200id"\nlength_unit = "mm"\nangle_unit = "deg"\n'
                                 '[target]\nshape = "points"\nfile = "points.csv"\n')
    for name, (text, _) in BAD.items():
        (d / f"{name}.toml").write_text(text)
    return d


@pytest.mark.parametrize("command", COMMANDS)
@pytest.mark.parametrize("bad", BAD)
def test_hostile_cell_is_one_line_and_exit_2(files, command, bad, capsys):
    argv = [a.replace("PATH", str(files / "path.csv")).replace("POINTS", str(files / "points.csv"))
            .replace("TASK", str(files / "task.toml")) for a in COMMANDS[command]]
    rc = main([*argv, "--cell", str(files / f"{bad}.toml")])
    out, err = capsys.readouterr()
    assert rc == 2, (command, bad, out, err)
    lines = err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("rmt: error: "), err
    assert BAD[bad][1].lower() in lines[0].lower(), lines[0]
    assert "Traceback" not in err

"""Issue 30: every file a command reads goes through one bounded reader (:mod:`kin.files`) — a device,
a FIFO or a directory refused before reading, a size cap, decoding errors and over-deep or
over-large JSON reported in one line naming the file, a UTF-8 byte-order mark accepted."""
from __future__ import annotations

import json
import os
import warnings

import pytest

import kin
from kin.files import FileReadError, json_depth, read_bytes, read_json, read_text
from tests.fuzz.contract import run_contract

BINARY = bytes(range(256)) * 8         # not UTF-8 (0x80 cannot start a character)
BOM = b"\xef\xbb\xbf"


def refused(argv, cwd, *words):
    """Exit 2, one line on stderr naming every word (checked by :func:`run_contract` and here)."""
    code, _, err = run_contract(argv, cwd)
    assert code == 2, (argv, err)
    for w in words:
        assert w in err, (w, err)
    return err


# ---- the helper ------------------------------------------------------------------------------------
def test_devices_fifos_and_directories_are_refused_before_reading(tmp_path):
    fifo = tmp_path / "pipe.csv"
    os.mkfifo(fifo)                    # no writer: opening it for reading would block forever
    for p in ("/dev/zero", str(fifo), str(tmp_path)):
        with pytest.raises(FileReadError, match="not a regular file") as e:
            read_bytes(p, "joint-path file", 1000)
        assert str(e.value).startswith(f"{p}: ") and "\n" not in str(e.value)
    with pytest.raises(FileReadError, match="no such task file"):
        read_text(tmp_path / "gone.toml", "task file", 1000)


def test_size_cap_is_checked_first_and_exactly(tmp_path):
    p = tmp_path / "a.txt"
    p.write_bytes(b"x" * 100)
    assert read_bytes(p, "file", 100) == b"x" * 100
    with pytest.raises(FileReadError, match=r"100 bytes; a file may have at most 99 bytes"):
        read_bytes(p, "file", 99)


def test_text_decoding_error_names_file_and_offset_and_a_bom_is_dropped(tmp_path):
    p = tmp_path / "t.toml"
    p.write_bytes(b'a = 1\nb = "\xff"\n')
    with pytest.raises(FileReadError) as e:
        read_text(p, "task file", 1000)
    assert str(e.value) == f"{p}: not UTF-8 text (byte 0xff at offset 11, line 2); a task file must be UTF-8 text"
    p.write_bytes(BOM + 'a = "é"\n'.encode())
    assert read_text(p, "task file", 1000) == 'a = "é"\n'


def test_json_depth_counts_brackets_outside_strings():
    assert json_depth("") == 0 and json_depth("1") == 0
    assert json_depth('[1, {"a": [2]}, []]') == 3
    assert json_depth('{"s": "[[[{{{", "t": "\\"[["}') == 1
    assert json_depth("[" * 100_000) == 100_000
    assert json_depth("[]" * 5000) == 1


@pytest.mark.parametrize("text, words", [
    ("[" * 100_000, ["nested 100000 levels", "at most 64"]),
    ('{"support": ' + str(10 ** 30) + "}", ["31 digits", "at most 15"]),
    ('{"support": -' + "9" * 16 + "}", ["16 digits"]),
    ('{"x": NaN}', ["NaN is not a finite number"]),
    ('{"x": -Infinity}', ["-Infinity is not a finite number"]),
    ('{"x": 1e999}', ["1e999 overflows"]),
    ('{"x": 1', ["not JSON", "line 1"]),
])
def test_json_refusals(tmp_path, text, words):
    p = tmp_path / "s.json"
    p.write_text(text)
    with pytest.raises(FileReadError) as e:
        read_json(p, "reach study", 10 ** 7)
    msg = str(e.value)
    assert msg.startswith(f"{p}: ") and "\n" not in msg
    for w in words:
        assert w in msg, msg


def test_json_accepted(tmp_path):
    p = tmp_path / "s.json"
    doc = {"a": [1, -2.5, [[{"b": "[[["}]]], "n": 10 ** 14, "t": True, "z": None}
    p.write_bytes(BOM + json.dumps(doc).encode())
    assert read_json(p, "reach study", 1000) == doc


# ---- the commands (issue 30's cases) ---------------------------------------------------------------
def test_time_refuses_dev_zero_at_once(tmp_path):
    refused(["time", "planar_2r", "/dev/zero", "--v-max", "10", "--a-max", "1"], tmp_path,
            "/dev/zero", "not a regular file")


def _study(support=3) -> dict:
    """A minimal reach study as `rmt reach --json` writes it: two targets of the planar 2R."""
    rows = [{"x": 1.0, "y": 0.0, "z": 0.0, "reached": True, "score": 0.5, "reason": "reached", "support": support},
            {"x": 3.0, "y": 0.0, "z": 0.0, "reached": False, "score": 0.0, "reason": "out_of_reach", "support": 0}]
    return {"robot": "planar_2r", "length_unit": "m", "placement": {"xyz": [0, 0, 0], "rpy": [0, 0, 0]},
            "per_target": rows}


@pytest.fixture
def study_a(tmp_path):
    (tmp_path / "a.json").write_text(json.dumps(_study()))
    code, out, err = run_contract(["reach-compare", "a.json", "a.json", "--json"], tmp_path)
    assert code == 0 and json.loads(out)["reached_by_both"] == 1, err       # the study itself is valid
    return tmp_path


def test_reach_compare_dev_zero(study_a):
    refused(["reach-compare", "a.json", "/dev/zero"], study_a, "/dev/zero", "not a regular file")


def test_reach_compare_huge_support(study_a):
    (study_a / "b.json").write_text(json.dumps(_study(support=10 ** 30)))
    refused(["reach-compare", "a.json", "b.json"], study_a, "b.json", "31 digits", "at most 15")


def test_reach_compare_deep_nesting(study_a):
    (study_a / "b.json").write_text("[" * 100_000)
    refused(["reach-compare", "a.json", "b.json"], study_a, "b.json", "nested 100000 levels")


TASK = ('name = "ring"\nrobot = "planar_2r"\nlength_unit = "m"\nangle_unit = "deg"\n'
        '[target]\nshape = "points"\nfile = "pts.csv"\ntolerance = 0.001\n'
        '[placement]\nx = [-1, 2]\ny = [-1, 2]\nz = [0, 0]\nyaw = [0, 0]\n')
SWEEP = 'name = "s"\ntask = "task.toml"\n[sampling]\nmethod = "grid"\n[parameters.L1]\nrange = [0.3, 1.2]\ncount = 2\n'


@pytest.mark.parametrize("binary", ["task.toml", "pts.csv"])
@pytest.mark.parametrize("command", ["reach", "place", "sweep"])
def test_binary_task_or_points_file(tmp_path, command, binary):
    (tmp_path / "task.toml").write_text(TASK)
    (tmp_path / "pts.csv").write_text("x,y,z\n1,0,0\n0,1,0\n")
    (tmp_path / "sweep.toml").write_text(SWEEP)
    (tmp_path / binary).write_bytes(BINARY)
    argv = {"reach": ["reach", "planar_2r", "task.toml"], "place": ["place", "planar_2r", "task.toml"],
            "sweep": ["sweep", "sweep.toml"]}[command]
    refused(argv, tmp_path, binary, "not UTF-8 text", "byte 0x80 at offset 128")


CELL = '[[obstacle]]\nname = "post"\ntype = "sphere"\nxyz = [1.2, 0, 0]\nradius = 0.1\n'


def test_cell_file_with_a_byte_order_mark_is_read(tmp_path):
    (tmp_path / "plain.toml").write_text(CELL)
    (tmp_path / "bom.toml").write_bytes(BOM + CELL.encode())
    runs = [run_contract(["clearance", "planar_2r", "0", "0", "--cell", f"{n}.toml", "--json"], tmp_path)
            for n in ("plain", "bom")]
    assert runs[0][0] in (0, 1) and runs[1][0] == runs[0][0], runs[1][2]
    a, b = (json.loads(r[1]) for r in runs)
    assert b.pop("cell") == "bom" and a.pop("cell") == "plain"
    assert b == a and a["clear"] is False        # the arm at q = 0 runs through the post at x = 1.2 m


def test_point_cloud_with_a_header_only_one_line_no_warning(tmp_path):
    (tmp_path / "scan.csv").write_text("x,y,z\n")
    (tmp_path / "cell.toml").write_text('[[obstacle]]\nname = "scan"\ntype = "point_cloud"\nfile = "scan.csv"\n'
                                        'point_radius = 0.01\n')
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        refused(["clearance", "planar_2r", "0", "0", "--cell", "cell.toml"], tmp_path, "scan.csv", "no points")


@pytest.mark.parametrize("loader, word", [
    ("planning.cell.moveit:load_scene", "scene file"),
    ("planning.ompl.keep_out:load_keep_out", "keep-out file"),
    ("kin.urdf.srdf:read_root", "SRDF file"),
    ("planning.toolpath.model:read_toolpath_text", "tool-path file"),
])
def test_the_other_readers_refuse_a_fifo_at_once(tmp_path, loader, word):
    """Every file reader goes through kin.files: a FIFO (which would block a plain open) is refused
    before it is opened, in one line naming the file and the kind."""
    import importlib
    mod, fn = loader.split(":")
    fifo = tmp_path / ("pipe.yaml" if "moveit" in mod else "pipe.toml")
    os.mkfifo(fifo)
    f = getattr(importlib.import_module(mod), fn)
    args = (fifo, "m") if fn == "load_keep_out" else (fifo,)
    with pytest.raises(kin.RmtError, match=rf"pipe\.(yaml|toml): not a regular file; a {word} must be a regular file"):
        f(*args)

"""Every CSV rmt writes ends its lines with "\\n" alone (csv.writer's default is "\\r\\n"): read back
as bytes from `rmt plan --out`, `rmt time --csv` and the helper behind them."""
from __future__ import annotations

import numpy as np

import kin
from studies.cli import main
from studies.jointpath import path_csv_text


def _lines_ok(data: bytes, rows: int) -> None:
    assert b"\r" not in data
    assert data.endswith(b"\n") and data.count(b"\n") == rows


def test_path_csv_text_uses_lf():
    robot = kin.load_robot("planar_2r")
    _lines_ok(path_csv_text(robot, np.array([[0.0, 0.5], [1.0, 1.0]])).encode(), 3)


def test_plan_out_and_time_csv_use_lf(tmp_path, capsys):
    path = tmp_path / "p.csv"
    assert main(["plan", "planar_2r", "--start", "0", "0.5", "--goal", "1", "1", "--out", str(path)]) == 0
    data = path.read_bytes()
    _lines_ok(data, data.count(b"\n"))
    assert data.startswith(b"q1,q2\n")
    out = tmp_path / "t.csv"
    assert main(["time", "planar_2r", str(path), "--v-max", "1", "--a-max", "2", "--csv", str(out)]) == 0
    data = out.read_bytes()
    assert data.startswith(b"# rmtkit trajectory 1\n") and b"\nt,q1,q2,qd1,qd2,qdd1,qdd2\n" in data
    _lines_ok(data, data.count(b"\n"))
    capsys.readouterr()

"""Window values: reading a windows JSON file never runs code and refuses bad entries with one line;
membership refuses batches of the wrong shape instead of reshaping them."""
from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest

from kin.errors import ConfigurationError
from planning.errors import WindowError
from planning.windows import Window, WindowSet


def _entry(**kw):
    d = {"name": "elbow", "kind": "elbow", "expr": "0.1*sin(q3) - 0.74*cos(q3)", "joints": [3], "width": 0.05,
         "method": "margin", "epsilon": 0.037}
    d.update(kw)
    return d


def _file(tmp_path, windows, n=6) -> Path:
    p = tmp_path / "w.json"
    p.write_text(json.dumps({"robot": "r", "n": n, "windows": windows}), encoding="utf-8")
    return p


def test_round_trip_and_predicate_value(tmp_path):
    ws = WindowSet.load(_file(tmp_path, [_entry(), _entry(name="wrist", expr="sin(q5)", joints=[5],
                                                          intervals=[[-0.05, 0.05]], epsilon=None)]))
    q = np.zeros((3, 6))
    q[:, 2] = [math.atan2(0.74, 0.1), 0.0, 1.0]         # g = 0 at atan2(0.74, 0.1)
    q[2, 4] = 0.01                                      # inside the wrist interval
    g = 0.1 * np.sin(q[:, 2]) - 0.74 * np.cos(q[:, 2])  # the formula, in numpy
    assert np.allclose(ws.windows[0].g(q), g)
    assert ws.contains(q).tolist() == [True, True, True]
    assert ws.which(q).tolist() == [0, 1, 1]            # rows 1, 2: q5 inside the wrist interval only
    assert ws.windows[0].contains(q).tolist() == (np.abs(g) <= 0.037).tolist()
    ws.save(tmp_path / "again.json")
    again = WindowSet.load(tmp_path / "again.json")
    assert again.to_dict() == ws.to_dict()


def test_python_payload_is_refused_and_runs_nothing(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    p = _file(tmp_path, [_entry(expr="__import__('os').system('touch X')")])
    with pytest.raises(WindowError, match="unexpected character") as e:
        WindowSet.load(p)
    assert "\n" not in str(e.value) and "position" in str(e.value)
    assert not (tmp_path / "X").exists()


@pytest.mark.parametrize("change,msg", [
    ({"intervals": [[0.1, -0.1]], "joints": [5]}, "reversed"),
    ({"intervals": [[float("nan"), 0.1]], "joints": [5]}, "finite number"),
    ({"intervals": [[-float("inf"), 0.1]], "joints": [5]}, "finite number"),
    ({"epsilon": float("nan")}, "epsilon must be a finite number"),
    ({"epsilon": -1.0}, "epsilon -1.0 must be ≥ 0"),
    ({"width": float("inf")}, "width must be a finite number"),
    ({"width": "0.1"}, "width must be a finite number"),
    ({"joints": [7]}, "joints must be"),
    ({"joints": [1.5]}, "joints must be"),
    ({"joints": [True]}, "joints must be"),
    ({"expr": 3}, "expr must be a string"),
    ({"expr": "q1 +"}, "position 5"),
    ({"method": "magic"}, "method 'magic' unknown"),
    ({"intervals": [[0, 1]], "joints": [1, 2]}, "exactly one joint"),
])
def test_bad_entries_are_refused(tmp_path, change, msg):
    # json.dumps writes NaN / Infinity, which Python's json reads back: the check must catch them
    p = _file(tmp_path, [_entry(**change)])
    with pytest.raises(WindowError, match=msg) as e:
        WindowSet.load(p)
    assert "\n" not in str(e.value)


@pytest.mark.parametrize("doc,msg", [
    ("[]", "needs fields"), ('{"n": 6}', "needs fields"), ('{"n": 0, "windows": []}', "integer 1"),
    ('{"n": true, "windows": []}', "integer 1"), ('{"n": 6, "windows": [1]}', "JSON object"),
    ('{"n": 6, "windows": [{}]}', "lacks name"), ("{" * 100_000, "not a readable JSON"), ("\xff", "not a readable"),
])
def test_bad_documents(tmp_path, doc, msg):
    p = tmp_path / "w.json"
    p.write_text(doc, encoding="latin-1")
    with pytest.raises(WindowError, match=msg):
        WindowSet.load(p)


def test_wrong_shapes_and_types_raise():
    ws = WindowSet("r", 6, [Window.from_dict(_entry(), 6)])
    for bad in (np.zeros((4, 3)), np.zeros(5), np.zeros((2, 2, 6)), np.zeros(18)):
        with pytest.raises(ConfigurationError, match="shape"):
            ws.contains(bad)
        with pytest.raises(ConfigurationError, match="shape"):
            ws.windows[0].contains(bad)
    with pytest.raises(ConfigurationError, match="real numbers"):
        ws.contains(np.array(["0"] * 6))
    with pytest.raises(ConfigurationError, match="real numbers"):
        ws.contains(np.zeros(6, complex))
    assert ws.contains(np.zeros(6)) in (True, False)
    assert ws.contains(np.zeros((0, 6))).shape == (0,)


def test_every_window_is_a_window_base():
    import numpy as np

    from planning.windows import PointSetWindow, Window, WindowBase
    w = Window("wrist: sin(q5)", "wrist", "sin(q5)", (5,), 0.05, "margin", 6, intervals=[(-0.05, 0.05)])
    p = PointSetWindow("other: x", "other", "x", (2, 3), 0.05, "margin", 6, points=np.zeros((1, 2)))
    assert isinstance(w, WindowBase) and isinstance(p, WindowBase)
    assert (w.is_interval, w.is_point_set, p.is_interval, p.is_point_set) == (True, False, False, True)
    with pytest.raises(TypeError):
        WindowBase("x", "other", "x", (1,), 0.1, "margin", 6)       # abstract: only its kinds are windows

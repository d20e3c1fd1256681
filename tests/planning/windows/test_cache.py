"""Built windows on disk (planning.windows.cache): a hit returns exactly what a rebuild gives; a damaged,
foreign or hostile file is ignored and replaced; the key follows the robot's content and the width."""
from __future__ import annotations

import json

import pytest

import kin
from planning.windows import build_windows
from planning.windows.cache import cache_path, cached, window_key


@pytest.fixture()
def fresh_cache(tmp_path, monkeypatch):
    monkeypatch.setenv("RMTKIT_CACHE", str(tmp_path))
    return tmp_path


def _build(robot, calls):
    def build():
        calls.append(1)
        return build_windows(robot, margin=0.05)
    return build


def test_a_hit_is_what_a_rebuild_gives(fresh_cache):
    robot = kin.load_robot("fanuc_m16ib20")
    calls = []
    first = cached(robot, {"margin": 0.05}, _build(robot, calls))
    second = cached(robot, {"margin": 0.05}, _build(robot, calls))
    assert calls == [1]                                     # built once, then read back
    assert json.dumps(first.to_dict()) == json.dumps(second.to_dict())
    assert json.dumps(second.to_dict()) == json.dumps(build_windows(robot, margin=0.05).to_dict())


@pytest.mark.parametrize("content", ["not json {", json.dumps({"robot": "fanuc_m16ib20", "n": 6, "windows": [
    {"name": "x", "kind": "other", "expr": "__import__('os').system('true')", "joints": [1], "width": 0.05,
     "method": "margin", "epsilon": 1.0}]}), json.dumps({"robot": "puma560", "n": 6, "windows": []}),
    json.dumps({"robot": "fanuc_m16ib20", "n": 6, "windows": [{"name": "w", "kind": "wrist", "expr": "sin(q5)",
                                                               "joints": [5], "width": 0.05, "method": "margin",
                                                               "intervals": [[1.0, 0.0]]}]})])
def test_a_damaged_or_foreign_file_is_rebuilt(fresh_cache, content):
    robot = kin.load_robot("fanuc_m16ib20")
    path = cache_path(robot, window_key(robot, {"margin": 0.05}))
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(content)
    calls = []
    ws = cached(robot, {"margin": 0.05}, _build(robot, calls))
    assert calls == [1] and len(ws.windows) == 3
    d = json.loads(path.read_text())                                                  # repaired
    assert d.pop("cache_key") == window_key(robot, {"margin": 0.05})
    assert d == json.loads(json.dumps(ws.to_dict()))


def test_a_file_moved_under_another_key_is_not_used(fresh_cache):
    """A valid file of the 0.3 windows copied onto the 0.05 file's name: it records its own key."""
    robot = kin.load_robot("fanuc_m16ib20")
    wide = cached(robot, {"margin": 0.3}, lambda: build_windows(robot, margin=0.3))
    src = cache_path(robot, window_key(robot, {"margin": 0.3}))
    dst = cache_path(robot, window_key(robot, {"margin": 0.05}))
    dst.write_text(src.read_text())
    calls = []
    ws = cached(robot, {"margin": 0.05}, _build(robot, calls))
    assert calls == [1] and [w.width for w in ws.windows] == [0.05] * 3 and wide.windows[0].width == 0.3


def test_the_key_follows_content_and_width():
    fanuc, puma = kin.load_robot("fanuc_m16ib20"), kin.load_robot("puma560")
    assert window_key(fanuc, {"margin": 0.05}) == window_key(kin.load_robot("fanuc_m16ib20"), {"margin": 0.05})
    assert window_key(fanuc, {"margin": 0.05}) != window_key(fanuc, {"margin": 0.06})
    assert window_key(fanuc, {"margin": 0.05}) != window_key(fanuc, {"sigma_min": 0.05})
    assert window_key(fanuc, {"margin": 0.05}) != window_key(puma, {"margin": 0.05})
    text = kin.dumps_robot(fanuc.chain).replace("limits = [-2.44, 2.44]", "limits = [-2.4, 2.4]")
    assert "limits = [-2.4, 2.4]" in text
    moved = kin.Robot(kin.loads_robot(text))
    assert window_key(moved, {"margin": 0.05}) != window_key(fanuc, {"margin": 0.05})



def test_an_unwritable_cache_is_said_and_the_windows_still_right(tmp_path, monkeypatch):
    blocker = tmp_path / "a_file"
    blocker.write_text("not a directory")
    monkeypatch.setenv("RMTKIT_CACHE", str(blocker))
    robot = kin.load_robot("fanuc_m16ib20")
    said = []
    ws = cached(robot, {"margin": 0.05}, lambda: build_windows(robot, margin=0.05), unstored=said.append)
    assert len(ws.windows) == 3 and len(said) == 1 and "could not be stored" in said[0]
    assert blocker.read_text() == "not a directory"

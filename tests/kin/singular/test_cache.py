"""The disk cache of exact analyses (kin.singular.cache) and the structured form it stores
(kin.singular.exact): hit on the second call (counted, not timed), validated on load."""
from __future__ import annotations

import json

import numpy as np
import pytest

import kin
from kin.singular import analyse_singularities, cache
from kin.singular import analysis as analysis_module
from kin.singular.exact import StructureError, content_key, exact_structure, validate_structure


@pytest.fixture
def counted(tmp_path, monkeypatch):
    """The cache in a fresh directory, and a counter of budgeted exact runs."""
    monkeypatch.setattr(cache, "cache_dir", lambda: tmp_path)
    calls = []
    real = analysis_module.run_with_budget

    def counting(*args, **kwargs):
        calls.append(1)
        return real(*args, **kwargs)

    monkeypatch.setattr(analysis_module, "run_with_budget", counting)
    return tmp_path, calls


def _factors(a):
    return [(f.kind, f.expr, f.joints) for f in a.factors]


def test_second_analysis_hits_the_cache(counted):
    _, calls = counted
    robot = kin.load_robot("puma560")
    first = analyse_singularities(robot)
    assert first.method == "exact" and first.budget["exact_status"] == "done" and len(calls) == 1
    second = analyse_singularities(kin.load_robot("puma560"))
    assert len(calls) == 1 and second.budget["exact_status"] == "cached"
    assert _factors(second) == _factors(first)
    # the cached factors evaluate like the fresh ones
    Q = robot.random_configurations(50, seed=3)
    assert np.allclose(second.values(Q), first.values(Q), rtol=1e-12, atol=1e-15)


TWO_LINK = """
name = "two_link"
convention = "standard"
length_unit = "m"
angle_unit = "rad"
[[joints]]
type = "revolute"
a = {a1}
limits = [-3, 3]
[[joints]]
type = "revolute"
a = 0.5
limits = [-3, 3]
"""


def test_a_changed_chain_is_not_served_from_the_cache(counted):
    _, calls = counted
    first = kin.Robot(kin.loads_robot(TWO_LINK.format(a1=0.8)))
    other = kin.Robot(kin.loads_robot(TWO_LINK.format(a1=0.7)))
    assert content_key(first) != content_key(other)
    analyse_singularities(first)
    analyse_singularities(other)
    assert len(calls) == 2
    analyse_singularities(kin.Robot(kin.loads_robot(TWO_LINK.format(a1=0.8))))
    assert len(calls) == 2


@pytest.mark.parametrize("damage", ["garbage", "foreign_key", "bad_coefficient", "bad_generator", "bad_exponent",
                                    "extra_field", "truncated", "display_mismatch", "bad_node", "wrong_root",
                                    "label_text"])
def test_damaged_cache_file_is_ignored_and_recomputed(counted, damage):
    tmp_path, calls = counted
    robot = kin.load_robot("scara_rrp")
    good = analyse_singularities(robot)
    path = cache.cache_path(robot, content_key(robot))
    record = json.loads(path.read_text())
    s = record["structure"]
    if damage == "garbage":
        path.write_bytes(b"\x00\xff not json")
    elif damage == "foreign_key":
        record["key"] = "0" * 24
        path.write_text(json.dumps(record))
    elif damage == "bad_coefficient":
        s["factors"][0]["terms"][0][1] = "__import__('os').system('touch /tmp/pwned')"
        path.write_text(json.dumps(record))
    elif damage == "bad_generator":
        s["generators"][0] = "exec"
        path.write_text(json.dumps(record))
    elif damage == "bad_exponent":
        s["factors"][0]["terms"][0][0] = [[0, -3]]
        path.write_text(json.dumps(record))
    elif damage == "extra_field":
        s["factors"][0]["expr"] = "sin(q1)"
        path.write_text(json.dumps(record))
    elif damage == "display_mismatch":          # well-formed, but not the factor: caught by evaluating both
        s["factors"][0]["display"]["num"] = ["cos", ["sym", "q1"]]
        path.write_text(json.dumps(record))
    elif damage == "bad_node":
        s["factors"][0]["display"]["num"] = ["call", ["sym", "os.system"]]
        path.write_text(json.dumps(record))
    elif damage == "wrong_root":
        s["factors"][0]["roots"]["values"] = [0.123]
        s["factors"][0]["roots"]["labels"] = ["0.123"]
        path.write_text(json.dumps(record))
    elif damage == "label_text":
        s["factors"][0]["roots"]["labels"][0] = "__import__('os')"
        path.write_text(json.dumps(record))
    else:
        path.write_text(path.read_text()[:40])
    if damage not in ("display_mismatch", "wrong_root"):      # schema errors: refused on load
        assert cache.load_cached(robot, content_key(robot)) is None
    again = analyse_singularities(robot)
    assert len(calls) == 2 and again.budget["exact_status"] == "done"
    assert _factors(again) == _factors(good)
    assert cache.load_cached(robot, content_key(robot)) is not None      # replaced by a good file


def test_structure_validation_names_the_field():
    robot = kin.load_robot("planar_2r")
    s = exact_structure(robot)
    assert validate_structure(s, robot.n, tuple(robot.task_rows)) is s
    with pytest.raises(StructureError, match="rows"):
        validate_structure(s, robot.n, (0, 1, 2))
    with pytest.raises(StructureError, match="n must be"):
        validate_structure(s, robot.n + 1, tuple(robot.task_rows))
    bad = json.loads(json.dumps(s))
    bad["lengths"]["a1"] = float("nan")
    with pytest.raises(StructureError, match="lengths"):
        validate_structure(bad, robot.n, tuple(robot.task_rows))

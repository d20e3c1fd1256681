"""Issue 30: ``rmt reach --placement`` has the bounds of a task's ``[placement]`` (±10 km, angles
within a full turn), and ``rmt reach-compare --labels`` refuses control characters (a newline would
print a forged ``rmt: error:`` line into stdout) — one line, exit 2, naming the option and the range."""
from __future__ import annotations

import json

import pytest

from tests.studies.cli.test_place_cli import run, write_task

FAST = ["--starts", "2", "--samples", "256", "--spins", "1"]


@pytest.fixture(scope="module")
def ring(tmp_path_factory):
    return write_task(tmp_path_factory.mktemp("bounds"), "ring")


@pytest.mark.parametrize("placement, unit", [
    (["1e308", "0", "0", "0", "0", "0"], "m"), (["0", "-10001", "0", "0", "0", "0"], "m"),
    (["0", "0", "0", "0", "0", "361"], "deg"), (["0", "0", "0", "-1e300", "0", "0"], "deg"),
])
def test_reach_placement_beyond_the_task_placement_bounds_is_refused(ring, placement, unit):
    rc, out, err = run(["reach", "planar_2r", str(ring), "--placement", *placement, *FAST])
    lines = err.strip().splitlines()
    assert rc == 2 and out == "" and len(lines) == 1, err
    assert lines[0].startswith("rmt: error: --placement: x y z must lie within ±10000 m (10 km) and roll pitch yaw "
                               "within ±360 deg"), lines[0]


def test_reach_placement_at_the_bounds_is_accepted(ring):
    """10 km away the ring is out of reach (exit 1), but the placement is a valid one."""
    rc, out, err = run(["reach", "planar_2r", str(ring), "--placement", "10000", "0", "0", "0", "0", "-360",
                        "--json", *FAST])
    assert rc == 1 and err == ""
    assert json.loads(out)["placement"]["xyz"] == pytest.approx([10000.0, 0.0, 0.0])


@pytest.fixture(scope="module")
def studies(ring, tmp_path_factory):
    d = tmp_path_factory.mktemp("labels")
    for name, x in (("a", "0.5"), ("b", "0")):
        rc, out, _ = run(["reach", "planar_2r", str(ring), "--placement", x, "0.3", "0", "0", "0", "0", "--json",
                          *FAST])
        (d / f"{name}.json").write_text(out)
    return d / "a.json", d / "b.json"


@pytest.mark.parametrize("label", ["x\nrmt: error: forged", "x\rforged", "tab\there", "bell\x07", "rtl\u202eoverride",
                                   "line\u2028sep"])
def test_labels_with_control_characters_are_refused(studies, label):
    a, b = studies
    rc, out, err = run(["reach-compare", str(a), str(b), "--labels", label, "fine"])
    lines = err.strip().splitlines()
    assert rc == 2 and out == "" and len(lines) == 1, (out, err)
    assert lines[0].startswith(f"rmt: error: --labels: {label!r} holds the control character U+") and \
        lines[0].endswith("allowed: 1–80 printable characters"), lines[0]


def test_printable_labels_are_kept(studies):
    a, b = studies
    rc, out, err = run(["reach-compare", str(a), str(b), "--labels", "centre é", "origin", "--json"])
    assert rc == 0 and err == "" and json.loads(out)["labels"] == ["centre é", "origin"]

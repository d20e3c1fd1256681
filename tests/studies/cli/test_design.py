"""``rmt coverage`` and ``rmt optimise`` on the bundled examples: exit codes, strict JSON, the files
written, and one-line errors for bad input."""
import json
import math

import pytest

import kin
from studies.cli.main import main


def test_coverage_json_matches_the_annulus(capsys):
    # nominal L1 = 0.7, L2 = 0.3: reach annulus [0.4, 1.0] of the 1.98 m disc target
    rc = main(["coverage", "studies/tasks/robots/planar_2r_design.toml", "planar_ring", "--json",
               "--seeds", "2", "--samples", "2000"])
    out = json.loads(capsys.readouterr().out)
    assert rc == 1                                   # not every target covered
    r = [math.hypot(x, y) for x, y, _ in out["positions"]]
    expect = sum(0.4 <= v <= 1.0 for v in r) / len(r)
    assert out["coverage_percent"] == pytest.approx(100 * expect)
    assert len(out["best"]) == out["targets"] == 240


def test_optimise_writes_design_json_and_robot(tmp_path, capsys):
    rc = main(["optimise", "scara_box", "--out", str(tmp_path), "--starts", "1", "--seeds", "2",
               "--samples", "1000", "--json"])
    out = json.loads(capsys.readouterr().out)
    assert rc == 0 and out["feasible"] and out["verified"]["coverage_percent"] == 100.0
    d = tmp_path / "scara_box"
    saved = json.loads((d / "design.json").read_text())
    assert saved["parameters"] == out["parameters"]
    chain = kin.load_chain(d / "scara_design_optimised.toml")
    assert chain.parameters["A1"].value == pytest.approx(out["parameters"]["A1"] * 1e-3)
    assert (d / "coverage.png").stat().st_size > 0 and (d / "history.png").stat().st_size > 0


@pytest.mark.parametrize("argv,needle", [
    (["optimise", "no_such_task"], "no such task file"),
    (["optimise", "scara_box", "--starts", "0"], "--starts"),
    (["coverage", "scara_rrp", "scara_box", "--seeds", "0"], "--seeds"),
    (["coverage", "scara_rrp", "scara_box", "--param", "A1=3"], "unknown design parameter"),
])
def test_bad_input_one_line_exit_2(argv, needle, capsys):
    assert main(argv) == 2
    err = capsys.readouterr().err.strip()
    assert "\n" not in err and needle in err

"""One-line CLI messages a new user met: no doubled "rmt: " prefix, the --tcp values printed plainly."""
from __future__ import annotations

from studies.cli import main


def _err(capsys, *argv) -> tuple[int, str]:
    code = main(list(argv))
    out, err = capsys.readouterr()
    return code, err.strip()


def test_unrecognized_arguments_name_the_command_once(capsys):
    code, err = _err(capsys, "fk", "puma560", "0", "0", "0", "0", "0", "0", "--bogus", "-93.49")
    assert code == 2
    assert err == "rmt: error: rmt fk: unrecognized arguments: --bogus -93.49"
    code, err = _err(capsys, "--bogus")
    assert code == 2 and err.startswith("rmt: error: ") and "rmt: error: rmt:" not in err


def _puma_wrist_limited(tmp_path):
    """The PUMA 560 with joint 5 limited to [70°, 80°] (every other field as bundled)."""
    from pathlib import Path

    import kin
    src = Path(kin.__file__).parent / "robots" / "puma560.toml"
    text = src.read_text(encoding="utf-8").replace("limits = [-100.0, 100.0]", "limits = [70.0, 80.0]", 1)
    p = tmp_path / "puma_wrist.toml"
    p.write_text(text.replace('name = "puma560"', 'name = "puma_wrist"', 1), encoding="utf-8")
    return p


def test_ik_no_solution_says_out_of_reach(capsys):
    code = main(["ik", "puma560", "--xyz", "5000", "0", "0", "--rpy", "0", "0", "0"])
    out = capsys.readouterr().out
    assert code == 1 and out.startswith("NO solution (base frame): out of reach: no branch of the closed form")


def test_ik_no_solution_says_every_branch_is_outside_the_limits(capsys, tmp_path):
    import numpy as np

    import kin
    from tests.dh_numpy import fk_numpy
    robot = kin.load_robot(str(_puma_wrist_limited(tmp_path)))
    c = robot.chain
    q = np.radians([10.0, -40.0, 30.0, 20.0, 60.0, 10.0])   # |q5| is 60°, 31.6°, 17.7° or 62.7° on its 8 branches
    T = fk_numpy(c, q)
    xyz = T[:3, 3] / c.length_scale
    from scipy.spatial.transform import Rotation
    rpy = np.degrees(Rotation.from_matrix(T[:3, :3]).as_euler("xyz"))
    code = main(["ik", str(tmp_path / "puma_wrist.toml"), "--xyz", *map(str, xyz), "--rpy", *map(str, rpy)])
    out = capsys.readouterr().out
    assert code == 1, out
    assert "branch(es) of the closed form reach the pose, each with a joint outside its limits" in out
    assert "joint 5 = " in out and "outside [70, 80] deg" in out


def test_bad_tcp_values_are_printed_plainly(capsys):
    code = main(["fk", "puma560", "0", "0", "0", "0", "0", "0", "--tcp", "a", "b", "c"])
    err = capsys.readouterr().err.strip()
    assert code == 2
    assert err == "rmt: error: --tcp: expected 3 or 6 numbers (x y z [roll pitch yaw]), got a b c"

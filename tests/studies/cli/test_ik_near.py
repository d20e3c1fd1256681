"""``rmt ik`` position-only (numeric) honours --near: every revolute angle is the whole-turn copy
nearest --near inside the limits (checked against the pose by the numpy FK); --near/--q0 far outside
the limits is one line, exit 2."""
from __future__ import annotations

import json
import math

import numpy as np
import pytest

import kin
from studies.cli import main
from tests.dh_numpy import fk_numpy


def _run(capsys, *argv):
    code = main([str(a) for a in argv])
    out, err = capsys.readouterr()
    return code, out, err


def test_position_ik_wrapped_towards_near(capsys):
    robot = kin.load_robot("ur5e")
    c = robot.chain
    near = np.array([10.0, -80.0, 60.0, 0.0, 0.0, 0.0])            # deg (the file's unit)
    code, out, err = _run(capsys, "ik", "ur5e", "--xyz", 0.3, 0.2, 0.4, "--near", *near, "--json")
    assert code == 0, err
    q = np.radians(json.loads(out)["q"])
    assert np.allclose(fk_numpy(c, q)[:3, 3], [0.3, 0.2, 0.4], atol=1e-9)     # still the target
    assert np.all(q >= c.lower - 1e-12) and np.all(q <= c.upper + 1e-12)
    for j in range(6):          # no other whole-turn copy inside the limits is nearer --near
        for k in (-1, 1):
            other = q[j] + 2 * math.pi * k
            if c.lower[j] <= other <= c.upper[j]:
                assert abs(q[j] - math.radians(near[j])) <= abs(other - math.radians(near[j])) + 1e-12, (j, q)


@pytest.mark.parametrize("opt", ["--near", "--q0"])
def test_near_far_outside_the_limits_is_refused(capsys, opt):
    code, out, err = _run(capsys, "ik", "ur5e", "--xyz", 0.3, 0.2, 0.4, opt, "1e9", 0, 0, 0, 0, 0)
    assert code == 2 and out == ""
    assert err.strip() == f"rmt: error: {opt}: joint 1 = 1e+09 deg is outside [-720, 720] deg (its limits ± a turn)"
    code, _, err = _run(capsys, "ik", "ur5e", "--xyz", 0.3, 0.2, 0.4, opt, 0, 0, 0, 0, 0, 719)
    assert code == 0, err


def test_huge_q0_is_refused(capsys):
    code, out, err = _run(capsys, "ik", "scara_rrp", "--xyz", 100, 100, 0, "--q0", "1e308", "-1e308", "-1e9")
    assert code == 2 and out == "" and len(err.strip().splitlines()) == 1
    assert err.startswith("rmt: error: --q0: joint 1 = 1e+308 rad is outside [")

"""Issue 32: the inverse dynamics of an assembled robot equal pinocchio's on the URDF that
``rmt export-urdf`` writes of the robot file ``rmt assemble`` wrote — to 1e-10 at random q, q̇, q̈,
gravity included (a tilted base puts it across frame 0), the tool as the payload.  The URDF's bodies
hold every moving part of the modules (their masses summed from the catalogue by hand)."""
from __future__ import annotations

import numpy as np
import pytest

import kin
from studies.cli import main
from tests.kin.modules.plain import FIXTURE, Plain

pin = pytest.importorskip("pinocchio")

ASSEMBLIES = [
    "stand R80 L200@90 E80 L300b@180 P80 A80_63 R63@180 grip63",
    "wall R80@270 E80@90 L300b R80 grip",
    "wall P80@180 E80@90 L200 R80@90 grip",
]


def _moving_mass(plain: Plain, items: list[str]) -> float:
    """kg of every part that moves: the distal parts, and every part after the first joint module."""
    names = plain.parse(items)[0]
    first = next(i for i, n in enumerate(names) if plain.mod[n]["kind"] == "joint")
    total = 0.0
    for i, n in enumerate(names):
        m = plain.mod[n]
        total += m.get("distal_inertial", {}).get("mass", 0.0)
        if i > first:
            total += m.get("inertial", {}).get("mass", 0.0)
    return total


@pytest.mark.parametrize("text", ASSEMBLIES)
def test_inverse_dynamics_equal_pinocchio_on_the_exported_urdf(text, tmp_path, capsys):
    robot_file, urdf = tmp_path / "arm.toml", tmp_path / "arm.urdf"
    assert main(["assemble", str(FIXTURE), "--modules", *text.split(), "--out", str(robot_file)]) == 0
    assert main(["export-urdf", str(robot_file), "--out", str(urdf)]) == 0
    capsys.readouterr()
    robot = kin.Robot(kin.load_chain(robot_file), backend="vm")
    model = pin.buildModelFromUrdf(str(urdf))
    data = model.createData()
    assert model.nq == robot.n
    plain = Plain(FIXTURE)
    assert sum(i.mass for i in model.inertias) == pytest.approx(_moving_mass(plain, text.split()), rel=1e-12)
    rng = np.random.default_rng(11)
    lo, hi = robot.chain.lower, robot.chain.upper
    for _ in range(15):
        q = rng.uniform(lo, hi)
        qd, qdd = rng.normal(size=robot.n), rng.normal(size=robot.n)
        tau = pin.rnea(model, data, q, qd, qdd)
        assert np.abs(tau).max() > 0.1
        np.testing.assert_allclose(robot.inverse_dynamics(q, qd, qdd), tau, rtol=1e-10,
                                   atol=1e-10 * np.abs(tau).max())

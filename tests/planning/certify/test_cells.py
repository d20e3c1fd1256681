"""planning.certify.cells: impossibility verdicts checked against an independent labelling of the
free space sampled on a fine grid, the slab case against the window's intervals."""
import numpy as np
import pytest
from scipy import ndimage

import kin
from planning.certify.cells import FreeCells
from planning.windows import build_windows


@pytest.fixture(scope="module")
def fanuc():
    robot = kin.load_robot("fanuc_m16ib20")
    ws = build_windows(robot, margin=0.05)
    return robot, ws, FreeCells(robot.chain.lower, robot.chain.upper, ws)


def test_groups_follow_the_windows_joints(fanuc):
    _, _, fc = fanuc
    assert sorted(js for js, _ in fc.groups) == [(1, 2), (4,)]        # (q2, q3) and q5, 0-based


def test_a_slab_separates_with_an_exact_reason(fanuc):
    robot, ws, fc = fanuc
    a = np.array([0.0, 0.3, 0.2, 0.0, -0.6, 0.0])
    b = a.copy()
    b[4] = 0.8
    sep = fc.separation(a, b)
    assert sep is not None and sep.kind == "slab" and sep.joints == (5,)
    assert "q5 ∈ [-0.05, 0.05]" in sep.reason and "q5 = -0.6" in sep.reason and "q5 = 0.8" in sep.reason
    b[4] = -0.2                                          # same side: no verdict
    assert fc.separation(a, b) is None


def test_cell_verdicts_agree_with_a_fine_sampled_labelling(fanuc):
    robot, ws, fc = fanuc
    c = robot.chain
    R = 1200
    g2 = np.linspace(c.lower[1], c.upper[1], R)
    g3 = np.linspace(c.lower[2], c.upper[2], R)
    G2, G3 = np.meshgrid(g2, g3, indexing="ij")
    Q = np.zeros((R * R, 6))
    Q[:, 1], Q[:, 2], Q[:, 4] = G2.ravel(), G3.ravel(), 1.0          # q5 = 1: outside the wrist window
    free = (ws.which(Q) < 0).reshape(R, R)
    labels, _ = ndimage.label(free)                                  # 4-connected free samples
    Qs = robot.random_configurations(3000, seed=4)
    Qs[:, 4] = np.abs(Qs[:, 4]) + 0.1                                # one side of the wrist slab
    Qs = Qs[ws.which(Qs) < 0][:600].reshape(-1, 2, 6)

    def lab(q):
        return labels[np.abs(g2 - q[1]).argmin(), np.abs(g3 - q[2]).argmin()]
    separated = together = 0
    for a, b in Qs:
        sep = fc.separation(a, b)
        la, lb = lab(a), lab(b)
        if sep is not None:
            # a slab of q2 or q3 within the (q2, q3) group is decided exactly first
            assert (sep.kind, sep.joints) in (("cells", (2, 3)), ("slab", (2,)), ("slab", (3,)))
            separated += 1
            assert la != lb or la == 0                               # never a verdict on a connected pair
        elif la and la == lb:
            together += 1
    assert separated >= 50 and together >= 5


def test_no_windows_no_verdict():
    robot = kin.load_robot("scara_rrp")
    fc = FreeCells(robot.chain.lower, robot.chain.upper, None)
    assert fc.separation(robot.chain.lower, robot.chain.upper) is None

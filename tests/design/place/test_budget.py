"""Issue 30: ``place``'s ``max_time`` covers all of its work — the screening, the IPOPT set-up and the
verification reach studies (which stop after their first start past it) — and the result says what
was cut."""
from __future__ import annotations

import numpy as np
import pytest

import kin
from design.place import PlacementRegion, place
from design.task.model import Targets


@pytest.mark.slow
def test_the_budget_covers_screening_nlp_and_verification():
    robot = kin.load_robot("ur5e")
    P = np.random.default_rng(0).uniform([-0.6, -0.6, 0.1], [0.6, 0.6, 0.8], (6000, 3))
    region = PlacementRegion(x=(-0.5, 0.5), y=(-0.5, 0.5), yaw=(0.0, 0.0))
    res = place(robot, Targets(P, tolerance=1e-4), region=region, max_time=1.0)
    assert res.time_s < 6.0          # generous: one IK start per verification study past the budget
    note = next(n for n in res.notes if n.startswith("the time budget of 1 s ran out"))
    assert "screening: " in note and "ipopt: not run" in note and "verification: IK from 1 of the 8 starts" in note
    assert any(n.startswith("the time budget ran out: IK from 1 of the 8 starts") for n in res.study.notes)

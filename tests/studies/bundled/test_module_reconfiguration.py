"""The module reconfiguration study in quick mode, checked independently of design.compose: the plan's
costs recomputed from the catalogue file read with tomllib (each module type's largest count in any
configuration times its price, plus the swaps), each configuration's robot file against a plain numpy
product of the modules' transforms, and every target of every part reached by that robot file —
an IK solution within the joint limits whose tool point, by a numpy DH product, is within the part's
0.1 mm; then strict JSON and the report in headless Chromium."""
from __future__ import annotations

import json
import tomllib
from collections import Counter

import numpy as np
import pytest

import kin
from kin.modules import catalogue_path
from tests.dh_numpy import fk_numpy
from tests.kin.modules.plain import Plain
from tests.studies.bundled.common import ROOT, assert_report_renders, quick_run

PARTS = ("panel_dispense", "tray_pick", "fixture_probe")


@pytest.fixture(scope="module")
def run(tmp_path_factory):
    return quick_run("module_reconfiguration", tmp_path_factory)


@pytest.fixture(scope="module")
def plan(run):
    return json.loads((run.report.parent / "plan.json").read_text())


def _targets(name: str) -> np.ndarray:
    """The part's box of targets (m), from its file by hand: count points per axis, evenly from min to max."""
    doc = tomllib.loads((ROOT / "studies" / "tasks" / "parts" / f"{name}.toml").read_text())
    t = doc["target"]
    assert doc["length_unit"] == "mm" and t["shape"] == "box"
    axes = [np.linspace(lo, hi, n) if n > 1 else np.array([lo]) for lo, hi, n in zip(t["min"], t["max"], t["count"])]
    return np.array(np.meshgrid(*axes, indexing="ij")).reshape(3, -1).T / 1000


def test_the_plan_costs_what_its_modules_and_swaps_cost(plan):
    doc = tomllib.loads(catalogue_path("dynamixel_y").read_text())
    price = {m["name"]: m["cost"] for m in doc["modules"]}
    assert plan["found"] and [c["part"] for c in plan["configurations"]] == list(PARTS)
    owned: Counter = Counter()
    for c in plan["configurations"] + [{"assembly": plan["base"]}]:
        for name, n in Counter(it.partition("@")[0] for it in c["assembly"].split()).items():
            owned[name] = max(owned[name], n)
    assert dict(owned) == plan["inventory"]
    inventory = sum(price[n] * c for n, c in owned.items())
    assert plan["inventory_cost"] == pytest.approx(inventory, abs=1e-9)
    swaps = sum(c["swaps"] for c in plan["configurations"])
    assert plan["swaps"] == swaps
    assert plan["total"] == pytest.approx(inventory + 150.0 * swaps, abs=1e-9)
    for c in plan["configurations"]:      # a part served by the base needs no swap, any other at least one
        assert (c["swaps"] == 0) == (c["assembly"] == plan["base"])


@pytest.mark.parametrize("part", PARTS)
def test_each_configuration_reaches_its_part(run, plan, part):
    text = next(c["assembly"] for c in plan["configurations"] if c["part"] == part)
    chain = kin.load_robot(str(run.report.parent / f"{part}_robot.toml")).chain
    robot = kin.Robot(chain)
    plain = Plain(catalogue_path("dynamixel_y"))
    rng = np.random.default_rng(7)
    for q in rng.uniform(chain.lower, chain.upper, (5, robot.n)):      # the robot file is the assembly
        assert np.abs(fk_numpy(chain, q) - plain.tip(text.split(), np.degrees(q))).max() < 1e-9   # deg: the file's
    P = _targets(part)
    for p in P:
        G = np.eye(4)
        G[:3, 3] = p
        best = np.inf
        for seed in range(12):
            r = robot.ik(G, mode="position", seed=seed, restarts=8)
            if bool(np.asarray(r.success).ravel()[0]):
                q = np.asarray(r.q).ravel()
                if np.all(q >= chain.lower - 1e-9) and np.all(q <= chain.upper + 1e-9):
                    best = min(best, float(np.linalg.norm(fk_numpy(chain, q)[:3, 3] - p)))
            if best <= 1e-4:
                break
        assert best <= 1e-4, (part, p, best)


def test_report_renders_in_a_browser(run, report_browser):
    assert_report_renders(report_browser, run.report, run.results)

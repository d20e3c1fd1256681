"""design.cycle against independent values: a one-joint rest-to-rest cycle has the closed-form
bang-bang / trapezoid duration; the link mass model's torques on a planar 2R equal the textbook 2R
dynamics of rods with point masses; the [cycle] table's fields are validated; sweeps store the
cycle columns."""
from __future__ import annotations

import dataclasses
import math
import sqlite3

import numpy as np
import pytest

import kin
from design.cycle import CycleSpec, LinkMasses, chain_with_masses, evaluate_cycle, rest_to_rest_time
from design.task import TaskError, loads_task
from design.task.model import Targets

ONE = """name = "one"
robot = "one.toml"
length_unit = "m"
angle_unit = "rad"
"""


def _one_joint(tmp_path):
    """A single revolute joint of length 0.5 m in the plane (gravity along its axis)."""
    (tmp_path / "one.toml").write_text('name = "one_r"\nconvention = "standard"\nlength_unit = "m"\n'
                                       'angle_unit = "rad"\ntask = ["x", "y"]\n\n[[joints]]\ntype = "revolute"\n'
                                       'a = 0.5\nlimits = [-3.0, 3.0]\n')
    return kin.load_robot(tmp_path / "one.toml")


@pytest.mark.parametrize("travel, v, a", [(1.0, 2.0, 4.0), (1.0, 1.0, 4.0), (0.3, 5.0, 2.0)])
def test_one_joint_cycle_is_twice_the_closed_form_rest_to_rest_time(tmp_path, travel, v, a):
    robot = _one_joint(tmp_path)
    th = np.array([-travel / 2, travel / 2])
    T = Targets(np.column_stack([0.5 * np.cos(th), 0.5 * np.sin(th), np.zeros(2)]), tolerance=1e-9)
    spec = CycleSpec((0, 1), v, a, 10.0, LinkMasses.make(1, mass_per_length=2.0, payload=1.0), blend=0.0)
    res = evaluate_cycle(robot, spec, T)
    # bang-bang when the travel is short (triangle: 2√(d/a)), else the trapezoid d/v + v/a; the timing is
    # minimum-time on its grid (300 intervals), so a corner of the profile between grid points costs < 1e-4
    t1 = 2 * math.sqrt(travel / a) if travel <= v * v / a else travel / v + v / a
    assert res.ok and 2 * t1 * (1 - 1e-9) <= res.cycle_time <= 2 * t1 * (1 + 1e-4)
    assert rest_to_rest_time([travel], [v], [a]) == pytest.approx(t1)
    # torque: rod m l²/3 plus the payload's m l², times the peak acceleration (no gravity about z)
    inertia = 2.0 * 0.5 * 0.25 / 3 + 1.0 * 0.25
    assert res.peak_torque[0] == pytest.approx(inertia * a, rel=1e-6)
    assert res.torque_ratio == pytest.approx(inertia * a / 10.0, rel=1e-6)


def test_dwell_adds_per_stop(tmp_path):
    robot = _one_joint(tmp_path)
    T = Targets(np.array([[0.5, 0, 0], [0, 0.5, 0], [0, -0.5, 0]]), tolerance=1e-9)     # q = 0, π/2, −π/2
    spec = CycleSpec((0, 1, 2), 1.0, 2.0, 10.0, LinkMasses.make(1, mass_per_length=1.0), dwell=0.25, blend=0.0)
    res = evaluate_cycle(robot, spec, T)
    legs = [math.pi / 2, math.pi / 2, math.pi]
    want = sum(d / 1.0 + 1.0 / 2.0 for d in legs) + 3 * 0.25
    assert want * (1 - 1e-9) <= res.cycle_time <= want * (1 + 1e-4)


def test_link_mass_model_matches_the_closed_form_2r():
    chain = kin.load_chain("planar_2r")                 # l1 = 1.0, l2 = 0.8 m
    chain = dataclasses.replace(chain, gravity=(0.0, -9.81, 0.0))
    rho, motor2, pay = (3.0, 2.0), 1.5, 0.7
    dyn = kin.Robot(chain_with_masses(chain, None, LinkMasses.make(2, rho, (0.0, motor2), 0.0, pay)))
    l1, l2 = 1.0, 0.8
    m1, m2 = rho[0] * l1, rho[1] * l2
    rng = np.random.default_rng(0)
    for _ in range(5):
        q, qd, qdd = rng.uniform(-2, 2, (3, 2))
        c2, s2 = np.cos(q[1]), np.sin(q[1])
        # body 1: rod + J2's motor at the elbow; body 2: rod + payload at the tip (about J2)
        A1 = m1 * l1 ** 2 / 3 + motor2 * l1 ** 2
        M2, S2, A2 = m2 + pay, m2 * l2 / 2 + pay * l2, m2 * l2 ** 2 / 3 + pay * l2 ** 2
        M = np.array([[A1 + A2 + M2 * l1 ** 2 + 2 * S2 * l1 * c2, A2 + S2 * l1 * c2], [A2 + S2 * l1 * c2, A2]])
        h = S2 * l1 * s2
        cor = np.array([-h * (2 * qd[0] * qd[1] + qd[1] ** 2), h * qd[0] ** 2])
        g = 9.81 * np.array([(m1 / 2 + motor2 + M2) * l1 * np.cos(q[0]) + S2 * np.cos(q.sum()), S2 * np.cos(q.sum())])
        assert np.allclose(dyn.inverse_dynamics(q, qd, qdd), M @ qdd + cor + g, atol=1e-10)


def test_masses_follow_the_design_lengths():
    chain = kin.load_chain("studies/tasks/robots/scara_design.toml")
    ms = LinkMasses.make(3, (6.0, 4.0, 2.0), (0.0, 2.5, 1.2), 0.0, 1.0)
    for p in ([0.1, 0.3], [0.35, 0.2]):
        ch = chain_with_masses(chain, np.array(p), ms)
        assert ch.joints[0].inertia.mass == pytest.approx(6.0 * (p[0] + 0.001) + 2.5)
        assert ch.joints[1].inertia.mass == pytest.approx(4.0 * (p[1] + 0.001) + 1.2)
        assert ch.joints[2].inertia.mass == pytest.approx(2.0 * 0.2) and ch.payload.mass == 1.0
        # body 1's centre of mass (frame 1, at the elbow): the a rod's middle, the d rod on J1's axis
        # (x = −a), J2's motor at the origin
        m1 = 6.0 * (p[0] + 0.001) + 2.5
        assert ch.joints[0].inertia.com[0] == pytest.approx(-(6.0 * p[0] * p[0] / 2 + 6.0 * 0.001 * p[0]) / m1)


@pytest.mark.parametrize("bad", [dict(mass_per_length=-1.0), dict(motor_mass=(1.0, 2.0)), dict(payload=float("nan")),
                                 dict()])
def test_bad_mass_models_are_refused(bad):
    with pytest.raises(TaskError):
        LinkMasses.make(3, **bad)


TASK = """name = "c"
robot = "studies/tasks/robots/scara_design.toml"
length_unit = "mm"
angle_unit = "deg"
objective = "cycle_time"

[target]
shape = "box"
min = [180, -160, -150]
max = [380, 70, -150]
count = [2, 2, 1]

[cycle]
sequence = [0, 3]
v_max = [300, 500, 1000]
a_max = [1500, 3000, 10000]
tau_max = [32, 15, 100]
lift = 25

[cycle.masses]
mass_per_length = [6.0, 4.0, 2.0]
motor_mass = [0.0, 2.5, 1.2]
payload = 1.0
"""


def test_cycle_table_in_file_units():
    t = loads_task(TASK, "c.toml")
    c = t.cycle
    assert c.sequence == (0, 3) and c.lift == pytest.approx(0.025)
    assert np.allclose(c.v_max, [math.radians(300), math.radians(500), 1.0])
    assert np.allclose(c.a_max, [math.radians(1500), math.radians(3000), 10.0])
    assert np.allclose(c.tau_max, [32, 15, 100])


@pytest.mark.parametrize("old, new, field", [
    ("sequence = [0, 3]", "sequence = [0, 4]", "cycle.sequence[1]"),
    ("sequence = [0, 3]", "sequence = [0]", "cycle.sequence"),
    ("v_max = [300, 500, 1000]", "v_max = [300, 0, 1000]", "cycle.v_max[1]"),
    ("a_max = [1500, 3000, 10000]", "a_max = [1500, 3000]", "cycle.a_max"),
    ("tau_max = [32, 15, 100]", "tau_max = -1", "cycle.tau_max"),
    ("lift = 25", "lift = -5", "cycle.lift"),
    ("lift = 25", "lift = 25\ntorque = \"fast\"", "cycle.torque"),
    ("lift = 25", "lift = 25\nspeed = 3", "cycle.speed"),
    ("payload = 1.0", "payload = 1e9", "cycle.masses.payload"),
    ("mass_per_length = [6.0, 4.0, 2.0]", "mass_per_length = [6.0, -4.0, 2.0]", "cycle.masses.mass_per_length[1]"),
    ("objective = \"cycle_time\"", "objective = \"torque_ratio\"\n[x]", "x"),
])
def test_bad_cycle_fields_name_file_and_field(old, new, field):
    with pytest.raises(TaskError) as e:
        loads_task(TASK.replace(old, new), "c.toml")
    msg = str(e.value)
    assert msg.startswith(f"c.toml: {field}") and "\n" not in msg, msg


def test_cycle_objective_needs_a_cycle():
    text = TASK[:TASK.index("[cycle]")]
    with pytest.raises(TaskError, match="objective.*cycle"):
        loads_task(text, "c.toml")


def test_sweep_stores_the_cycle_columns(tmp_path):
    from design.sweep import LocalExecutor, loads_sweep, run_sweep, sweep_table
    (tmp_path / "c.toml").write_text(TASK.replace("studies/", f"{kin.__file__.rsplit('/kin/', 1)[0]}/studies/"))
    sweep = loads_sweep('name = "s"\ntask = "c.toml"\nmetrics = ["coverage", "cycle_time", "peak_torque", '
                        '"torque_ratio"]\n[evaluation]\nseeds = 1\nsamples = 200\n'
                        '[parameters.A1]\nvalues = [200, 300]\n[parameters.A2]\nvalues = [250]\n', "s.toml", tmp_path)
    db = tmp_path / "s.sqlite"
    rep = run_sweep(sweep, db, LocalExecutor(workers=1))
    assert rep.counts["done"] == 2
    con = sqlite3.connect(db)
    import json
    rows = [json.loads(m) for (m,) in con.execute("SELECT metrics FROM designs ORDER BY id")]
    con.close()
    for r in rows:
        assert r["cycle_time"] > 0 and r["peak_torque"] == max(r["peak_torque_J1"], r["peak_torque_J2"])
        assert r["torque_ratio"] == pytest.approx(max(r["peak_torque_J1"] / 32, r["peak_torque_J2"] / 15,
                                                      r["peak_torque_J3"] / 100))
        assert r["feasible"] == (r["torque_ratio"] <= 1 + 1e-6)
        assert r["objective"] == r["cycle_time"]
    cols = list(sweep_table(db).columns) if hasattr(sweep_table(db), "columns") else sweep_table(db).dtype.names
    assert {"cycle_time", "peak_torque", "peak_torque_J1", "peak_torque_J3", "torque_ratio"} <= set(cols)


def test_sweep_refuses_cycle_metrics_without_a_cycle(tmp_path):
    from design.sweep import SweepError, loads_sweep
    task = loads_task(TASK[:TASK.index("[cycle]")].replace("cycle_time", "length"), "c.toml")
    with pytest.raises(SweepError, match=r"metrics\[1\]"):
        loads_sweep('name = "s"\ntask = "x"\nmetrics = ["coverage", "cycle_time"]\n[parameters.A1]\nvalues = [200]\n',
                    "s.toml", tmp_path, task=task)


def test_torque_limited_cycle_is_the_torque_bang_bang(tmp_path):
    """torque = "limit" with a motor limit below the acceleration limit's need: the one-joint move is
    then bang-bang at the torque's acceleration τmax/I (no gravity about z): 2·2√(d·I/τmax), and the
    peak torque meets the limit."""
    robot = _one_joint(tmp_path)
    travel, v, a = 1.0, 5.0, 20.0
    th = np.array([-travel / 2, travel / 2])
    T = Targets(np.column_stack([0.5 * np.cos(th), 0.5 * np.sin(th), np.zeros(2)]), tolerance=1e-9)
    inertia = 2.0 * 0.5 * 0.25 / 3 + 1.0 * 0.25
    tau = 2.0                                         # < I·a = 8.33 N·m: the motor binds
    masses = LinkMasses.make(1, mass_per_length=2.0, payload=1.0)
    check = evaluate_cycle(robot, CycleSpec((0, 1), v, a, tau, masses, blend=0.0), T)
    limit = evaluate_cycle(robot, CycleSpec((0, 1), v, a, tau, masses, blend=0.0, torque="limit"), T)
    assert check.peak_torque[0] == pytest.approx(inertia * a, rel=1e-6) and not check.within_torque
    want = 2 * 2 * math.sqrt(travel * inertia / tau)
    assert limit.ok and want * (1 - 1e-9) <= limit.cycle_time <= want * (1 + 1e-3)
    assert limit.peak_torque[0] <= tau * (1 + 1e-6) and limit.within_torque

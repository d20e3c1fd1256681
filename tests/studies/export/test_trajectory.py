"""The trajectory file: written by trajectory_csv_text and read back to the bit (in the robot file's
units or in SI), and every malformed file refused in one line naming the file and the line."""
from __future__ import annotations

import math

import numpy as np
import pytest

import kin
from studies.export.trajectory import TrajectoryFileError, read_trajectory, trajectory_csv_text


def _samples(n=6, K=5, seed=0):
    rng = np.random.default_rng(seed)
    t = np.r_[0.0, np.cumsum(rng.uniform(0.01, 0.1, K - 1))]
    return t, rng.uniform(-1, 1, (K, n)), rng.uniform(-1, 1, (K, n)), rng.uniform(-3, 3, (K, n))


@pytest.mark.parametrize("si", [False, True])
def test_written_file_reads_back_exactly(tmp_path, si):
    robot = kin.load_robot("ur5e")                      # a file in degrees
    t, q, qd, qdd = _samples()
    tau = np.arange(30.0).reshape(5, 6)
    f = tmp_path / "t.csv"
    f.write_text(trajectory_csv_text(robot, t, q, qd, qdd, tau, si=si))
    tr = read_trajectory(robot, f)
    assert np.array_equal(tr.t, t) and np.array_equal(tr.tau, tau)
    for a, b in ((tr.q, q), (tr.qd, qd), (tr.qdd, qdd)):     # deg → rad → deg costs an ulp or two
        assert np.allclose(a, b, rtol=1e-15, atol=1e-15)
    assert tr.names == ["base", "shoulder", "elbow", "wrist1", "wrist2", "wrist3"]
    text = f.read_text()
    assert ("# angle_unit: rad" in text) == si and ("# angle_unit: deg" in text) != si


def test_a_file_without_notes_is_in_the_robot_files_units(tmp_path):
    robot = kin.load_robot("scara_rrp")                 # revolute and prismatic joints
    c = robot.chain
    f = tmp_path / "old.csv"
    f.write_text("t,q1,q2,q3,qd1,qd2,qd3,qdd1,qdd2,qdd3\n0,10,20,30,0,0,0,1,2,3\n0.5,11,21,31,1,1,1,0,0,0\n")
    tr = read_trajectory(robot, f)
    scale = np.where(c.revolute_mask, {"deg": math.pi / 180, "rad": 1.0}[c.angle_unit],
                     {"m": 1.0, "mm": 1e-3}[c.length_unit])
    assert np.allclose(tr.q[0], np.array([10, 20, 30]) * scale, rtol=1e-15)
    assert np.allclose(tr.qdd[0], np.array([1, 2, 3]) * scale, rtol=1e-15) and tr.tau is None


HEADER = "t," + ",".join(f"{k}{j}" for k in ("q", "qd", "qdd") for j in range(1, 7))
ROW0 = "0," + ",".join(["0"] * 18)
ROW1 = "0.5," + ",".join(["1"] * 18)


@pytest.mark.parametrize("text, what", [
    (f"{HEADER}\n{ROW0}\n0.5,nan" + ",1" * 17 + "\n", "line 3: column q1 is nan"),
    (f"{HEADER}\n{ROW0}\n0.5,1,1,1,1,1,1,1,inf" + ",1" * 10 + "\n", "column qd2 is inf"),
    (f"{HEADER}\n{ROW0}\n", "1 sample(s); a trajectory needs at least two"),
    (f"{HEADER}\n", "0 sample(s)"),
    ("t," + ",".join(f"{k}{j}" for k in ("q", "qd", "qdd") for j in range(1, 6)) + "\n", "the header has 5 joint "
                                                                                      "position columns"),
    (f'# joints: ["a", "b"]\n{HEADER}\n{ROW0}\n{ROW1}\n', "names 2 joints; ur5e has 6"),
    (f"{HEADER}\n{ROW0}\n{ROW1}\n0.5," + ",".join(["1"] * 18) + "\n", "line 4: t = 0.5 s is not after the previous"),
    (f"{HEADER}\n{ROW1}\n{ROW0}\n", "the first sample is at t = 0.5 s"),
    (f"{HEADER}\n{ROW0}\n0.5,1,2\n", "line 3: 3 values; the header has 19 columns"),
    (f"{HEADER}\n{ROW0}\n0.5,x" + ",1" * 17 + "\n", "'x' is not a number"),
    (f"{ROW0}\n{ROW1}\n", "the header must be t,q1..q6"),
    ("# only notes\n", "no header row"),
    (f"# robot: franka_panda\n{HEADER}\n{ROW0}\n{ROW1}\n", "is a trajectory of 'franka_panda', not of ur5e"),
    (f"# angle_unit: grad\n{HEADER}\n{ROW0}\n{ROW1}\n", "angle_unit 'grad' is not one of rad, deg"),
    (f"# joints: nope\n{HEADER}\n{ROW0}\n{ROW1}\n", "joints must be a JSON list"),
    (f"{HEADER}\n{ROW0}\n0.5," + ",".join(["1e308"] * 18) + "\n", None),     # finite in deg, finite in rad
])
def test_malformed_files_are_one_line(tmp_path, text, what):
    robot = kin.load_robot("ur5e")
    f = tmp_path / "bad.csv"
    f.write_text(text)
    if what is None:
        assert np.isfinite(read_trajectory(robot, f).q).all()
        return
    with pytest.raises(TrajectoryFileError) as e:
        read_trajectory(robot, f)
    msg = str(e.value)
    assert msg.startswith(f"{f}: ") and "\n" not in msg and what in msg, msg


def test_huge_and_odd_files_are_refused_before_reading(tmp_path):
    robot = kin.load_robot("ur5e")
    big = tmp_path / "big.csv"
    with open(big, "wb") as fh:                         # sparse: no disk used, stat says 101 MB
        fh.truncate(101_000_000)
    for path, what in ((big, "a trajectory file may have at most"), (tmp_path, "not a regular file"),
                       (tmp_path / "missing.csv", "no such trajectory file")):
        with pytest.raises(TrajectoryFileError, match=what):
            read_trajectory(robot, path)
    bad = tmp_path / "latin1.csv"
    bad.write_bytes(b"t\xe9\n")
    with pytest.raises(TrajectoryFileError, match="not UTF-8"):
        read_trajectory(robot, bad)

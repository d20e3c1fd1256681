"""Fuzz: generated trajectory files (a header that may be wrong, rows of numbers, NaN, text, times out
of order, notes that may lie) fed to ``rmt export-trajectory`` in every format, run in-process against
the contract of :mod:`tests.fuzz.contract` (exit 0, 1 or 2, one line for bad input, no traceback)."""
from __future__ import annotations

import tempfile
from pathlib import Path

from hypothesis import given
from hypothesis import strategies as st

from tests.fuzz.contract import FUZZ, run_contract
from tests.fuzz.strategies import mostly, number_text

GOOD_HEADER = "t,q1,q2,qd1,qd2,qdd1,qdd2"
NOTES = ["# rmtkit trajectory 1", "# robot: planar_2r", "# robot: ur5e", '# joints: ["a", "b"]', '# joints: ["a"]',
         "# joints: [1, 2]", "# angle_unit: deg", "# angle_unit: rad", "# angle_unit: grad", "# length_unit: mm",
         "# anything: at all"]


@st.composite
def trajectory_csv(draw) -> str:
    lines = draw(st.lists(st.sampled_from(NOTES), max_size=3))
    header = draw(mostly(st.just(GOOD_HEADER), st.sampled_from(["t,q1,qd1,qdd1", GOOD_HEADER + ",tau1,tau2",
                                                                 "q1,q2", ""]), 6))
    lines.append(header)
    width = len(header.split(","))
    t = 0.0
    for _ in range(draw(st.integers(0, 6))):
        t += draw(mostly(st.floats(0.001, 0.5), st.floats(-0.5, 0.0), 6))
        vals = [repr(t)] + [draw(mostly(st.floats(-0.5, 0.5).map(repr), number_text(), 8))
                            for _ in range(width - 1 + draw(mostly(st.just(0), st.integers(-1, 1), 10)))]
        lines.append(",".join(vals))
    return "\n".join(lines) + "\n"


@FUZZ
@given(trajectory_csv(), st.sampled_from(["ros", "ros-json", "csv", "urscript"]),
       st.sampled_from([[], ["--rate", "200"], ["--rate", "1e-3"]]), st.booleans())
def test_trajectory_files_keep_the_contract(text, fmt, extra, to_file):
    with tempfile.TemporaryDirectory() as d:
        cwd = Path(d)
        (cwd / "traj.csv").write_text(text, encoding="utf-8")
        out = ["--out", "x.out"] if to_file else []
        run_contract(["export-trajectory", "planar_2r", "traj.csv", "--format", fmt, *extra, *out], cwd, ("x.out",))

"""Fuzz: argument vectors for every cheap command on bundled robots, hostile values included, run
in-process against the contract of :mod:`tests.fuzz.contract`."""
from __future__ import annotations

import tempfile
from pathlib import Path

from hypothesis import given
from hypothesis import strategies as st

from tests.fuzz.contract import FUZZ, run_contract
from tests.fuzz.strategies import NASTY_TEXT, number_text

ROBOTS = {"planar_2r": 2, "scara_rrp": 3}
PATH_CSV = "q1,q2\n0.1,0.5\n0.3,0.7\n"
OUTPUTS = ["o.json", "sub/dir/o.csv", ".", "missing/", "o.png"]


@st.composite
def argv(draw):
    robot = draw(st.sampled_from(sorted(ROBOTS) + ["no_such_robot", "r.toml"]))
    n = ROBOTS.get(robot, 2)
    q = lambda: draw(st.lists(number_text(-2, 2), min_size=n - 1, max_size=n + 1))
    opt = lambda name, values: ([name, draw(values)] if draw(st.booleans()) else [])
    seed = st.one_of(st.integers(-5, 2**33).map(str), st.sampled_from(NASTY_TEXT))
    command = draw(st.sampled_from(["fk", "jacobian", "ik", "singularities", "windows", "workspace", "plan",
                                    "check-path", "show", "robots", "junk"]))
    out: list[str] = []
    outputs: tuple[str, ...] = ()
    if command in ("fk", "jacobian"):
        out = [command, robot, *q()]
    elif command == "ik":
        out = ["ik", robot, "--xyz", *[draw(number_text(-500, 500)) for _ in range(3)]] + opt("--seed", seed)
    elif command == "singularities":
        out = ["singularities", robot] + opt("--seed", seed)
    elif command == "windows":
        out = ["windows", robot, draw(st.sampled_from(["--margin", "--sigma-min"])), draw(number_text(-1, 4))]
        out += opt("--out", st.sampled_from(OUTPUTS))
    elif command == "workspace":
        out = ["workspace", robot, "--samples", draw(st.sampled_from(["-1", "0", "1", "50", "300", "nan", "1e9", "x"]))]
        out += opt("--seed", seed) + opt("--sigma-min", number_text(-1, 1))
        out += opt("--plot", st.sampled_from(["w.png", "sub/w.png", ".", "/dev/null"]))
    elif command == "plan":
        out = ["plan", robot, "--start", *q(), "--goal", *q(), "--time-limit",
               draw(st.sampled_from(["0.05", "0.1", "0", "-1", "nan", "1e308", "x"]))]
        out += opt("--planner", st.sampled_from(["RRTConnect", "PRM*", "BIT*", "nonsense", ""]))
        out += opt("--objective", st.sampled_from(["none", "length", "singularity", "fast"]))
        out += opt("--margin", number_text(-1, 1)) + opt("--out", st.sampled_from(OUTPUTS)) + opt("--seed", seed)
    elif command == "check-path":
        out = ["check-path", robot, draw(st.sampled_from(["p.csv", "missing.csv", "."]))]
        out += opt("--step", number_text(-1, 1)) + opt("--sigma-floor", number_text(-1, 1))
        out += opt("--margin", number_text(-1, 1))
    elif command in ("show", "robots"):
        out = [command] + ([robot] if command == "show" else [])
    else:
        out = draw(st.lists(st.sampled_from(NASTY_TEXT + ["--json", "-h", "fk", "--out"]), max_size=5))
        return out, outputs
    if draw(st.booleans()):
        out.append("--json")
    for flag in ("--out", "--plot"):
        if flag in out:
            outputs = (out[out.index(flag) + 1],)
    return out, outputs


@FUZZ
@given(argv())
def test_argument_vectors_keep_the_contract(case):
    args, outputs = case
    with tempfile.TemporaryDirectory() as d:
        cwd = Path(d)
        (cwd / "p.csv").write_text(PATH_CSV)
        (cwd / "r.toml").write_text("name = 'x'\n")            # an invalid robot file
        run_contract(args, cwd, outputs)

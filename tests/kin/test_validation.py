"""kin.validation: one set of checks for numbers handed to the API, the CLI and files."""
from __future__ import annotations

import math

import numpy as np
import pytest

from kin.errors import ArgumentError, RobotFileError
from kin.validation import Fields, count, is_count, is_real, real


@pytest.mark.parametrize("x, r, c", [(1, True, True), (1.5, True, False), (np.float32(2), True, False),
                                      (np.int64(3), True, True), (True, False, False), (np.bool_(True), False, False),
                                      ("1", False, False), (1 + 0j, False, False), (None, False, False),
                                      (math.nan, True, False)])
def test_is_real_and_is_count(x, r, c):
    assert is_real(x) is r and is_count(x) is c


def test_real_names_the_argument_and_the_range():
    assert real(-0.0, "margin", 0) == 0.0 and math.copysign(1, real(-0.0, "margin", 0)) == 1.0
    assert real(np.float64(0.5), "t", 0, 1) == 0.5
    for x, match in [(True, "margin must be a finite number ≥ 0, got boolean True"),
                     ("0.1", "margin must be a finite number ≥ 0, got string '0.1'"),
                     (math.inf, "margin = inf must be a finite number ≥ 0"),
                     (-1, "margin = -1.0 must be a finite number ≥ 0")]:
        with pytest.raises(ArgumentError, match=match):
            real(x, "margin", 0)
    with pytest.raises(ArgumentError, match=r"t = 1.0 must be a number in \[0, 1\)"):
        real(1.0, "t", 0, 1, high_open=True)
    with pytest.raises(RobotFileError):
        real(math.nan, "x", error=RobotFileError)


def test_count():
    assert count(np.int32(4), "n", 1, 8) == 4
    with pytest.raises(ArgumentError, match=r"n = 9 must be an integer in \[1, 8\]"):
        count(9, "n", 1, 8)
    with pytest.raises(ArgumentError, match="n must be an integer ≥ 1, got number 2.0"):
        count(2.0, "n", 1)


def test_fields_name_the_file_and_the_field():
    f = Fields("cell.toml", fail=lambda field, msg: RobotFileError(msg, "cell.toml", field))
    assert f.table({"a": 1}, "box", ("a", "b")) == {"a": 1}
    assert f.vector([1, 2.5, 3], "box.lower", 3) == [1.0, 2.5, 3.0]
    for call, match in [(lambda: f.table({"c": 1}, "box", ("a", "b")),
                         "cell.toml: box.c: unknown field; allowed: a, b"),
                        (lambda: f.number(True, "box.a"), "cell.toml: box.a: must be a number, got boolean"),
                        (lambda: f.number(-1, "box.a", positive=True), "must be > 0, got -1"),
                        (lambda: f.vector([1, 2], "box.lower", 3),
                         "must be a list of 3 numbers, got array of length 2"),
                        (lambda: f.integer(0, "n", 1, 5), r"n: must be an integer in \[1, 5\], got 0"),
                        (lambda: f.string(3, "kind", ("a",)), "kind: must be a string, got integer 3")]:
        with pytest.raises(RobotFileError, match=match):
            call()

"""studies.drawing: solver output (C printf on file descriptor 1, as OSQP's error messages) never
reaches the command's standard output."""
from __future__ import annotations

import ctypes

from studies.drawing import solver_output_silenced


def test_c_level_printf_is_silenced(capfd):
    libc = ctypes.CDLL(None)
    print("before", flush=True)
    with solver_output_silenced():
        libc.printf(b"ERROR in osqp_setup: P must be a valid upper triangular matrix\n")
    print("after", flush=True)
    out, err = capfd.readouterr()
    assert out == "before\nafter\n" and err == ""


"""What the importer writes is what a robot file holds (kin/urdf/writable.py): rounding noise of the
URDF's numbers written as 0 (the closed form of the noise checked), and a length no rounding explains
but a robot file refuses is one line naming the joint."""
from __future__ import annotations

import math
import re

import numpy as np
import pytest

import kin
from kin.urdf import UrdfError, import_urdf
from tests.kin.urdf.reference import YourdfpyFk
from tests.kin.urdf.synthetic import serial, write_urdf


def rounded(tmp_path):
    """π/2 written to 11 digits, as robowflex's Panda writes it."""
    q = 1.57079632679
    return write_urdf(tmp_path, serial([("revolute", (0, 0, 0.333), (0, 0, 0), (0, 0, 1)),
                                        ("revolute", (0, 0, 0), (-q, 0, 0), (0, 0, 1)),
                                        ("revolute", (0, -0.316, 0), (q, 0, 0), (0, 0, 1)),
                                        ("revolute", (0.0825, 0, 0), (q, 0, 0), (0, 0, 1)),
                                        ("fixed", (0, 0, 0.1), (0, 0, 0), (0, 0, 1))]), "rounded")


def test_rounding_noise_is_written_as_zero_and_said(tmp_path):
    """The 11-digit π/2 (off by δ = π/2 − 1.57079632679 rad) tilts joint 3's axis, 0.316 m along joint 2's
    link, so their common normal misses by δ·0.316 m ≈ 1.5e-12 m: a DH length a robot file cannot hold,
    written as 0 (within 1e-9 of the chain's size, at least the tip's distance) and said in the source;
    the file loads and its FK is yourdfpy's within that."""
    path = rounded(tmp_path)
    chain = import_urdf(str(path), collision=False)
    table = chain.dh_table()
    assert all(v == 0.0 or abs(v) >= 1e-9 for v in table[:, [0, 2]].ravel())
    noise = (math.pi / 2 - 1.57079632679) * 0.316
    m = re.search(r"1 length within ([0-9.e+-]+) m of 0 \(up to ([0-9.e+-]+) m: rounding of the URDF's numbers\) "
                  "written as 0", chain.source)
    assert m and m.group(2) == f"{noise:.2g}", chain.source
    tip = YourdfpyFk(path, "l0", "l5")([], [])[:3, 3]
    assert 1e-9 * np.linalg.norm(tip) * 0.999 <= float(m.group(1)) <= 1e-9 * (0.333 + 0.316 + 0.0825 + 0.1)
    back = kin.load_chain(kin.save_robot(chain, tmp_path / "rounded.toml"))
    assert back == chain


def test_a_length_below_a_nanometre_that_is_not_rounding_is_refused(tmp_path):
    """Two parallel axes 0.5 nm apart in a 0.15 m chain: DH a = 5e-10 m is no rounding of its numbers
    (that would be within 1.5e-10 m) and a robot file holds 0 or at least 1 nm — one line naming the joint."""
    path = write_urdf(tmp_path, serial([("revolute", (0, 0, 0.05), (0, 0, 0), (0, 0, 1)),
                                        ("revolute", (5e-10, 0, 0.05), (0, 0, 0), (0, 0, 1)),
                                        ("fixed", (0, 0, 0.05), (0, 0, 0), (0, 0, 1))]), "tiny")
    with pytest.raises(UrdfError) as e:
        import_urdf(str(path), collision=False)
    msg = str(e.value)
    assert "\n" not in msg and msg.startswith(f"{path}: joint 'j1': its DH a = 5e-10 m, made from the URDF's joint "
                                              "origins and axes; allowed: 0 or 1e-09 to 10000 m in magnitude"), msg

"""Tool-path readers (csv_reader.py, segments.py) at the edges of their ranges: huge or vanishing
values are refused with one line naming the field — never an OverflowError, never inf times."""
from __future__ import annotations

import math

import numpy as np
import pytest

from planning.toolpath import ToolPathError, parse_toolpath_csv, parse_toolpath_toml


class _Units:            # a robot stand-in: only the units are read
    class chain:  # noqa: N801 - stands in for Robot.chain, the attribute the readers read
        length_unit, angle_unit = "mm", "deg"


@pytest.mark.parametrize("text,where,words", [
    ("x,y,z\n0,0,0\n1e308,0,0\n", "line 3, column 'x'", "outside the allowed range ±1e+07"),
    ("x,y,z,roll,pitch,yaw\n0,0,0,0,0,1e308\n", "line 2, column 'yaw'", "outside the allowed range ±1440"),
    ("x,y,z,feed\n0,0,0,1\n1,0,0,1e-300\n", "line 3, column 'feed'", "outside the allowed range [0.001, 1e+06]"),
    ("x,y,z,feed\n0,0,0,1\n1,0,0,1e308\n", "line 3, column 'feed'", "outside the allowed range"),
])
def test_csv_ranges(text, where, words):
    with pytest.raises(ToolPathError) as e:
        parse_toolpath_csv(text, 1e-3, math.pi / 180, "p.csv", ("mm", "deg"))
    s = str(e.value)
    assert where in s and words in s and "\n" not in s


HEAD = 'feed = 10.0\n[start]\nxyz = [0.0, 0.0, 0.0]\n'


@pytest.mark.parametrize("body,field,words", [
    ('[[segments]]\ntype = "line"\nto = [100.0, 0.0, 0.0]\nstep = 1e-300\n', "segments[0]",
     "more than 5000000 waypoints"),
    ('[[segments]]\ntype = "line"\nto = [1e308, 0.0, 0.0]\npoints = 2\n', "segments[0].to", "within ±1e+07"),
    ('[[segments]]\ntype = "line"\nto = [100.0, 0.0, 0.0]\npoints = 2\nfeed = 1e-300\n', "segments[0].feed",
     "outside the allowed range"),
    ('[[segments]]\ntype = "line"\nto = [100.0, 0.0, 0.0]\npoints = 2\nduration = 1e300\n', "segments[0].duration",
     "outside the allowed range"),
    ('[[segments]]\ntype = "arc"\ncenter = [50.0, 0.0, 0.0]\nnormal = [0.0, 0.0, 1e308]\nto = [100.0, 0.0, 0.0]\n'
     'points = 4\n', None, None),                       # a huge normal is only a direction
])
def test_toml_ranges(body, field, words):
    if field is None:
        tp = parse_toolpath_toml(HEAD + body, _Units, "p.toml")
        # a half circle of radius 50 mm about +z from (0, 0) to (100, 0): through (50, -50)
        assert np.allclose(tp.poses[-1][:3, 3], [0.1, 0.0, 0.0], atol=1e-12)
        assert tp.s[-1] == pytest.approx(math.pi * 0.05, rel=1e-12)
        return
    with pytest.raises(ToolPathError) as e:
        parse_toolpath_toml(HEAD + body, _Units, "p.toml")
    s = str(e.value)
    assert field in s and words in s and "\n" not in s


def test_toml_feed_default_and_rpy_range():
    with pytest.raises(ToolPathError, match="feed: feed 1e-300 is outside"):
        parse_toolpath_toml('feed = 1e-300\n[start]\nxyz = [0.0, 0.0, 0.0]\n[[segments]]\ntype = "line"\n'
                            'to = [1.0, 0.0, 0.0]\npoints = 2\n', _Units, "p.toml")
    with pytest.raises(ToolPathError, match=r"start.rpy: angles must lie within ±1440"):
        parse_toolpath_toml('feed = 1.0\n[start]\nxyz = [0.0, 0.0, 0.0]\nrpy = [0.0, 0.0, 1e308]\n[[segments]]\n'
                            'type = "line"\nto = [1.0, 0.0, 0.0]\npoints = 2\n', _Units, "p.toml")

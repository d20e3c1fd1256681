"""planning.ompl.keep_out: boxes read in file units → SI; every malformed file refused naming the field."""
import pytest

from planning.ompl.keep_out import KeepOutError, load_keep_out, parse_keep_out

GOOD = """
length_unit = "mm"
[[box]]
name = "fixture"
lower = [400, -200, 0]
upper = [700, 200, 300]
[[box]]
lower = [-1, -1, -1]
upper = [1, 1, 1]
frames = "all"
"""


def test_boxes_in_si():
    a, b = parse_keep_out(GOOD, "m")
    assert a.lower == pytest.approx((0.4, -0.2, 0.0)) and a.upper == pytest.approx((0.7, 0.2, 0.3))
    assert not a.all_frames and b.all_frames
    assert b.lower == pytest.approx((-0.001, -0.001, -0.001))
    c, = parse_keep_out("[[box]]\nlower = [0, 0, 0]\nupper = [1, 2, 3]\n", "in")   # the robot's unit by default
    assert c.upper == pytest.approx((0.0254, 0.0508, 0.0762))


@pytest.mark.parametrize("text, words", [
    ("[[box]]\nlower = [0, 0]\nupper = [1, 1, 1]\n", "lower must be three numbers"),
    ("[[box]]\nlower = [0, 0, 0]\nupper = [1, 1, nan]\n", "finite"),
    ("[[box]]\nlower = [0, 0, 2]\nupper = [1, 1, 1]\n", "lower must be below upper"),
    ("[[box]]\nlower = [0, 0, 0]\nupper = [1, 1, 1]\nframes = 'some'\n", "frames 'some' unknown"),
    ("[[box]]\nlower = [0, 0, 0]\nupper = [1, 1, 1]\ncolour = 'red'\n", "unknown key(s) colour"),
    ("length_unit = 'furlong'\n[[box]]\nlower = [0, 0, 0]\nupper = [1, 1, 1]\n", "length_unit 'furlong' unknown"),
    ("boxes = 1\n", "unknown key(s) boxes"),
    ("", "no [[box]]"),
    ("[[box]\n", "not valid TOML"),
    ("[[box]]\nlower = [true, 0, 0]\nupper = [1, 1, 1]\n", "lower must be three numbers"),
])
def test_bad_files_are_refused(text, words):
    with pytest.raises(KeepOutError) as e:
        parse_keep_out(text, "m", "cell.toml")
    assert words in str(e.value) and str(e.value).startswith("cell.toml") and "\n" not in str(e.value)


def test_missing_file(tmp_path):
    with pytest.raises(KeepOutError, match="no such keep-out file"):
        load_keep_out(tmp_path / "nope.toml", "m")

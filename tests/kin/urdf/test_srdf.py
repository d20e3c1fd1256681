"""MoveIt SRDFs (kin.urdf.srdf): disabled link pairs read, hostile files refused in one line, a body pair
left unchecked only when every link pair between the two bodies is disabled, and robowflex's Panda
imported with its SRDF (when MotionBenchMaker's files are at hand)."""
from __future__ import annotations

import pytest

from kin.geometry import LinkCapsule, RobotGeometry
from kin.urdf import UrdfError
from kin.urdf.srdf import allowed_body_pairs, disabled_link_pairs

SRDF = """<?xml version="1.0"?>
<robot name="r">
  <disable_collisions link1="a" link2="b" reason="Adjacent"/>
  <disable_collisions link1="a" link2="c" reason="Never"/>
  <disable_collisions link1="b2" link2="c" reason="Never"/>
  <disable_collisions link1="a" link2="a" reason="Default"/>
</robot>
"""


def test_disabled_pairs_are_read(tmp_path):
    p = tmp_path / "r.srdf"
    p.write_text(SRDF)
    assert disabled_link_pairs(p) == {frozenset("ab"), frozenset("ac"), frozenset(("b2", "c"))}


@pytest.mark.parametrize("text, words", [
    ('<?xml version="1.0"?><!DOCTYPE r [<!ENTITY x "y">]><robot/>', "document type declaration"),
    ("<robot><disable_collisions link1='a'/></robot>", "needs link1 and link2"),
    ("<robot><unclosed></robot>", "not well-formed XML"),
    ("<urdf/>", "not <robot>"),
])
def test_hostile_files_are_refused_in_one_line(tmp_path, text, words):
    p = tmp_path / "bad.srdf"
    p.write_text(text)
    with pytest.raises(UrdfError, match=words) as e:
        disabled_link_pairs(p)
    assert "\n" not in str(e.value) and str(p) in str(e.value)


def test_missing_and_binary_files(tmp_path):
    with pytest.raises(UrdfError, match="no such SRDF file"):
        disabled_link_pairs(tmp_path / "none.srdf")
    p = tmp_path / "bin.srdf"
    p.write_bytes(b"\xff\xfe\x00")
    with pytest.raises(UrdfError, match="UTF-8"):
        disabled_link_pairs(p)


def test_a_body_pair_is_allowed_only_when_every_link_pair_is_disabled():
    cap = lambda body, name: LinkCapsule(body, (0, 0, 0), (0, 0, 0.1), 0.01, name)  # noqa: E731
    # body 1 holds links a; body 2 holds b and b2; body 3 holds c
    geo = RobotGeometry((cap(1, "a"), cap(2, "b"), cap(2, "b2"), cap(3, "c")))
    disabled = {frozenset("ab"), frozenset("ac"), frozenset(("b2", "c")), frozenset(("zz", "a"))}
    pairs, unknown = allowed_body_pairs(geo, disabled)
    # (1, 2): a–b disabled but a–b2 not: checked; (1, 3): a–c: allowed; (2, 3): b–c enabled: checked
    assert pairs == {(1, 3)}
    assert unknown == ["zz"]


def test_robowflex_panda_imports_with_its_srdf():
    from studies.benchmarks.mbm import MbmDataError, robot_files
    try:
        urdf, srdf = robot_files("panda")
    except MbmDataError as e:
        pytest.skip(f"MotionBenchMaker's files are not available here: {e}")
    import warnings

    from kin.urdf import UrdfWarning, import_urdf
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", UrdfWarning)
        plain = import_urdf(str(urdf))
        chain = import_urdf(str(urdf), srdf=srdf)
    g = chain.geometry
    assert plain.geometry.allowed == frozenset() and len(g.allowed) > 10
    disabled = disabled_link_pairs(srdf)
    links = {}
    for c in g.capsules:
        links.setdefault(c.body, set()).add(c.name)
    for i, j in g.allowed:                               # every allowed body pair: all its link pairs disabled
        assert all(frozenset((a, b)) in disabled for a in links[i] for b in links[j])
    # the SRDF leaves link 5 against the hand checked: so is the body pair
    b5 = next(c.body for c in g.capsules if c.name == "panda_link5")
    bh = next(c.body for c in g.capsules if c.name == "panda_hand")
    assert (min(b5, bh), max(b5, bh)) not in g.allowed
    assert "SRDF" in chain.source

"""MoveIt SRDFs (kin.urdf.srdf): disabled link pairs read, hostile files refused in one line, a body pair
left unchecked only when every link pair between the two bodies is disabled, and robowflex's Panda
imported with its SRDF (when MotionBenchMaker's files are at hand); group states read as named states
(matched by joint name, the rest said), hostile ones refused in one line, and example-robot-data's Panda
state checked against yourdfpy's FK of its URDF."""
from __future__ import annotations

import numpy as np
import pytest

import kin
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


# ---- group states ---------------------------------------------------------------------------------
def _two_joint_urdf(tmp_path):
    from tests.kin.urdf.synthetic import joint, write_urdf
    return write_urdf(tmp_path, [joint("j1", "revolute", "base", "l1", limits=(-2.0, 2.0)),
                                 joint("j2", "revolute", "l1", "l2", xyz=(0.3, 0, 0), axis=(0, 1, 0),
                                       limits=(-1.0, 1.0)),
                                 joint("j3", "continuous", "l2", "tip", xyz=(0.2, 0, 0), axis=(1, 0, 0))])


def _srdf(tmp_path, body: str):
    p = tmp_path / "r.srdf"
    p.write_text(f'<?xml version="1.0"?>\n<robot name="r">\n{body}\n</robot>\n')
    return p


def _state(name, **values):
    return (f'<group_state name="{name}" group="arm">'
            + "".join(f'<joint name="{k}" value="{v}"/>' for k, v in values.items()) + "</group_state>")


def test_group_states_become_named_states_and_the_rest_is_said(tmp_path):
    import warnings

    from kin.urdf import UrdfWarning, import_urdf
    urdf = _two_joint_urdf(tmp_path)
    srdf = _srdf(tmp_path, "\n".join([
        _state("ready", j1=0.5, j2=-0.25, j3=4.0, finger=0.01),     # a joint off the chain; j3 continuous: 4 - 2π
        _state("open", finger=0.04),                                # another group's state: none of the chain's
        _state("half", j1=0.1),                                     # only some of the chain's joints
        _state("my home", j1=0, j2=0, j3=0)]))                      # a name a robot file cannot hold
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", UrdfWarning)
        chain = import_urdf(str(urdf), collision=False, srdf=srdf)
    assert list(chain.states) == ["ready"]
    assert np.allclose(chain.states["ready"], (0.5, -0.25, 4.0 - 2 * np.pi), rtol=0, atol=1e-15)
    said = " | ".join(str(w.message) for w in caught)
    assert "'ready': values of joints off the chain left out (finger)" in said
    assert "'open' (group 'arm') sets 0 of the chain's 3 joints" in said
    assert "'half' (group 'arm') sets 1 of the chain's 3 joints" in said
    assert "'my home': left out" in said
    assert "named states from the SRDF r.srdf" in chain.source


@pytest.mark.parametrize("body, words", [
    (_state("a", j1=0, j2="", j3=0), "group_state 'a': joint 'j2': value '' must be one finite number"),
    ('<group_state name="a" group="arm"><joint name="j1"/></group_state>', "group_state 'a': joint 'j1' has no value"),
    (_state("a", j1="nan", j2=0, j3=0), "joint 'j1': value 'nan' must be one finite number"),
    (_state("a", j1="inf", j2=0, j3=0), "joint 'j1': value 'inf' must be one finite number"),
    (_state("a", j1="abc", j2=0, j3=0), "joint 'j1': value 'abc' is not a number"),
    (_state("a", j1="1 2", j2=0, j3=0), "value '1 2' must be one finite number"),
    (_state("a", j1=0, j2=1.5, j3=0), "group_state 'a': joint 'j2' = 1.5 rad lies outside its limits \\[-1, 1\\]"),
    ('<group_state group="arm"><joint name="j1" value="0"/></group_state>', "group_state 1: needs a name"),
    ('<group_state name="a"><joint value="0"/></group_state>', "its joint 1 needs a name"),
    ('<group_state name="a"><joint name="j1" value="0"/><joint name="j1" value="1"/></group_state>',
     "joint 'j1' is set twice"),
    (_state("a", j1=0, j2=0, j3=0) + _state("a", j1=0.1, j2=0, j3=0), "group_state 'a': is given twice"),
])
def test_hostile_group_states_are_refused_in_one_line(tmp_path, body, words):
    from kin.urdf import import_urdf
    urdf = _two_joint_urdf(tmp_path)
    srdf = _srdf(tmp_path, body)
    with pytest.raises(UrdfError, match=words) as e:
        import_urdf(str(urdf), collision=False, srdf=srdf)
    assert "\n" not in str(e.value) and str(srdf) in str(e.value)


def test_an_entity_attack_is_refused_before_any_group_state_is_read(tmp_path):
    from kin.urdf.srdf import group_states
    p = tmp_path / "lol.srdf"
    p.write_text('<?xml version="1.0"?><!DOCTYPE r [<!ENTITY a "aaaaaaaaaa"><!ENTITY b "&a;&a;&a;&a;">]>'
                 '<robot><group_state name="&b;"><joint name="j1" value="0"/></group_state></robot>')
    with pytest.raises(UrdfError, match="document type declaration"):
        group_states(p)


def test_example_robot_datas_panda_state_is_the_urdfs_configuration(tmp_path):
    """The real SRDF of example-robot-data's Panda: its "default" group state (arm and hand) becomes the
    arm's state (the finger's value left out), and the imported chain's FK there is yourdfpy's FK of the
    URDF at the SRDF's own joint values."""
    import warnings

    from kin.urdf import UrdfWarning, import_urdf
    from kin.urdf.srdf import group_states
    from tests.kin.urdf.reference import YourdfpyFk, erd_urdf
    urdf = erd_urdf("panda_description/urdf/panda.urdf")
    srdf = erd_urdf("panda_description/srdf/panda.srdf")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", UrdfWarning)
        chain = import_urdf(str(urdf), tip="panda_link8", collision=False, srdf=srdf)
    (default,) = [g for g in group_states(srdf) if g.name == "default"]
    names = [f"panda_joint{k}" for k in range(1, 8)]
    assert list(chain.states) == ["default"]
    assert chain.states["default"] == tuple(default.values[n] for n in names)
    ref = YourdfpyFk(urdf, "panda_link0", "panda_link8")
    q = np.array(chain.states["default"])
    assert np.allclose(kin.Robot(chain).fk(q), ref(names, q), atol=1e-9)
    # written to a robot file and read back: the same state, in the file's units
    path = tmp_path / "panda.toml"
    kin.save_robot(chain, path)
    assert kin.load_chain(path).states == chain.states

"""Import → save → load for every URDF the tests have: example-robot-data's nine serial arms and its
other test URDFs, robowflex's spherized Panda and UR5 (MotionBenchMaker's robots), and synthetic
chains.  The robot file the importer writes loads back (kin.robotfile's reader accepts every number)
to the same chain, whose FK (tests/dh_numpy.py, plain numpy) is yourdfpy's FK of the URDF; with
collision meshes, the capsules loaded back hold every vertex of every collision mesh placed by
yourdfpy's FK (gripper joints off the chain at the values the importer holds them at), and robowflex's
spheres come back as themselves."""
from __future__ import annotations

import warnings
import zlib

import numpy as np
import pytest

import kin
from kin.geometry import body_frames
from kin.urdf import UrdfWarning, import_urdf, read_serial_chain
from tests.dh_numpy import fk_numpy
from tests.kin.urdf.reference import YourdfpyFk, erd_urdf, mbm_urdf
from tests.kin.urdf.synthetic import random_urdf, write_urdf
from tests.kin.urdf.test_collision import outside, place, urdf_solids
from tests.kin.urdf.test_writable import rounded

#: example-robot-data's serial arms (file, tip: None = the default), the issue's nine first
ARMS = [("panda_description/urdf/panda.urdf", "panda_hand_tcp"), ("so_arm_description/urdf/so100.urdf", None),
        ("so_arm_description/urdf/so101.urdf", "gripper_frame_link"), ("z1_description/urdf/z1.urdf", None),
        ("ur_description/urdf/ur3_robot.urdf", "tool0"), ("ur_description/urdf/ur5_gripper.urdf", "tool0"),
        ("ur_description/urdf/ur10_robot.urdf", "tool0"),
        ("kinova_description/robots/kinova.urdf", "j2s6s200_end_effector"), ("xarm_description/urdf/xarm7.urdf", None)]
OTHERS = [("panda_description/urdf/panda.urdf", "panda_link8"), ("ur_description/urdf/ur5_robot.urdf", "tool0"),
          ("double_pendulum_description/urdf/double_pendulum_continuous.urdf", "link2")]
#: FK of the file against the URDF's: the importer writes lengths within 1e-9 of the chain's size as 0
FK_TOL = 2e-9


def _erd(relative, tip):
    return lambda tmp_path: (erd_urdf(relative), tip)


def _mbm(robot, tip):
    return lambda tmp_path: (mbm_urdf(robot), tip)


def _synthetic(seed):
    def make(tmp_path):
        joints = random_urdf(seed)
        return write_urdf(tmp_path, joints, f"random_{seed}"), None
    return make


CASES = ([(f"erd-{r.rsplit('/', 1)[-1][:-5]}-{t or 'default'}", _erd(r, t)) for r, t in ARMS + OTHERS]
         + [("mbm-panda-default", _mbm("panda", None)), ("mbm-panda-grasptarget", _mbm("panda", "panda_grasptarget")),
            ("mbm-ur5-default", _mbm("ur5", None)), ("mbm-ur5-tool0", _mbm("ur5", "tool0")),
            ("rounded", lambda tmp_path: (rounded(tmp_path), None))]
         + [(f"random-{seed}", _synthetic(seed)) for seed in range(8)])


def _import(path, tip, **kw):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", UrdfWarning)       # robowflex's placeholder inertials
        return import_urdf(str(path), tip=tip, **kw)


@pytest.mark.parametrize("convention", ["standard", "modified"])
@pytest.mark.parametrize("case", [c for _, c in CASES], ids=[i for i, _ in CASES])
def test_import_save_load_gives_the_urdf_fk(tmp_path, case, convention):
    path, tip = case(tmp_path)
    chain = _import(path, tip, convention=convention, collision=False)
    out = kin.save_robot(chain, tmp_path / "robot.toml")
    back = kin.load_chain(out)
    assert back == chain
    sc = read_serial_chain(str(path), tip=tip)
    ref = YourdfpyFk(path, sc.base, sc.tip)
    rng = np.random.default_rng(zlib.crc32(str(path.name).encode()))
    worst = max(float(np.abs(fk_numpy(back, q) - ref(back.joint_names(), q)).max())
                for q in rng.uniform(back.lower, back.upper, size=(20, back.n)))
    assert worst < FK_TOL, f"FK differs from yourdfpy's by {worst:.3g} m"


# ---- collision geometry -------------------------------------------------------------------------------
#: the arms whose meshes take seconds to enclose are the slow test's (tests/conftest.py)
MESH_FAST = [("panda_description/urdf/panda.urdf", "panda_hand_tcp"), ("ur_description/urdf/ur5_gripper.urdf", "tool0")]


def _holds_the_meshes(path, chain, sc):
    """Every vertex of every collision mesh and box of the URDF's links on the chain's bodies lies inside
    the capsules of its body, placed by yourdfpy's FK at random configurations."""
    body_of = {lk.name: lk.body for lk in sc.links}
    model, solids = urdf_solids(path)
    carried = [s for s in solids if s[0] in body_of]
    assert carried
    held = {name: q for name, q, _ in sc.held}
    rng = np.random.default_rng(zlib.crc32(path.name.encode()))
    for q in rng.uniform(chain.lower, chain.upper, size=(3, chain.n)):
        model.update_cfg({**held, **dict(zip(chain.joint_names(), q))})
        F = body_frames(chain, q)[0]
        for link, origin, V in carried:
            world = place(np.asarray(model.get_transform(link, sc.base)) @ origin, V)
            assert outside(world, [c for c in chain.geometry.capsules if c.body == body_of[link]], F) <= 1e-9, link


def _mesh_round_trip(tmp_path, relative, tip):
    path = erd_urdf(relative)
    chain = import_urdf(str(path), tip=tip)
    back = kin.load_chain(kin.save_robot(chain, tmp_path / "robot.toml"))
    assert back == chain and back.geometry.capsules
    _holds_the_meshes(path, back, read_serial_chain(str(path), tip=tip))


@pytest.mark.parametrize("relative, tip", MESH_FAST, ids=["panda", "ur5_gripper"])
def test_meshes_round_trip_and_are_held(tmp_path, relative, tip):
    _mesh_round_trip(tmp_path, relative, tip)


def test_meshes_of_every_arm_round_trip_and_are_held(tmp_path):
    for relative, tip in ARMS:
        if (relative, tip) not in MESH_FAST:
            _mesh_round_trip(tmp_path, relative, tip)


@pytest.mark.parametrize("robot", ["panda", "ur5"])
def test_robowflex_spheres_round_trip(tmp_path, robot):
    """robowflex's collision spheres come back as balls of the same centres (in yourdfpy's FK) and radii."""
    path = mbm_urdf(robot)
    chain = _import(path, None)
    back = kin.load_chain(kin.save_robot(chain, tmp_path / "robot.toml"))
    assert back == chain
    sc = read_serial_chain(str(path))
    import yourdfpy
    model = yourdfpy.URDF.load(str(path), build_scene_graph=True, load_meshes=False)
    q = np.random.default_rng(2).uniform(back.lower, back.upper)
    model.update_cfg(dict(zip(back.joint_names(), q)))
    F = body_frames(back, q)[0]
    ours = sorted((round(r, 12), *np.round(place(F[c.body], [c.a])[0], 9)) for c in back.geometry.capsules
                  for r in [c.radius])
    theirs = []
    for link in model.robot.links:
        for c in link.collisions:
            if c.geometry.sphere is not None and link.name in {lk.name for lk in sc.links}:
                T = np.asarray(model.get_transform(link.name, sc.base)) @ (np.eye(4) if c.origin is None else c.origin)
                theirs.append((round(float(c.geometry.sphere.radius), 12), *np.round(T[:3, 3], 9)))
    assert ours == sorted(theirs) and len(ours) > 30

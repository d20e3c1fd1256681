"""Windows know which robot they belong to (WindowSet.check_robot, robot_key): windows or an analysis of
another robot — another name, or the same name with other DH values — are refused by every user."""
from __future__ import annotations

import pytest

import kin
from kin.singular import analyse_singularities
from planning.errors import WindowError
from planning.ompl import plan
from planning.validate import check_path
from planning.windows import WindowSet, build_windows


def test_windows_of_another_robot_with_the_same_name_are_refused():
    fanuc = kin.load_robot("fanuc_m16ib20")
    text = kin.dumps_robot(fanuc.chain)
    assert "a = 0.77" in text
    other = kin.Robot(kin.loads_robot(text.replace("a = 0.77", "a = 0.95")))
    assert other.name == fanuc.name
    ws = build_windows(fanuc, margin=0.05)
    for use in (lambda: check_path(other, [[0, 0, 0, 0, 0.5, 0]], ws),
                lambda: plan(other, [0, 0, 0, 0, 0.5, 0], [0.1, 0, 0, 0, 0.5, 0], ws),
                lambda: ws.check_robot(other)):
        with pytest.raises(WindowError, match="built for another robot"):
            use()
    with pytest.raises(WindowError, match="analysis is of another robot named 'fanuc_m16ib20'"):
        build_windows(other, margin=0.05, analysis=analyse_singularities(fanuc))
    puma = kin.load_robot("puma560")
    with pytest.raises(WindowError, match="built for another robot"):
        check_path(puma, [[0, 0, 0, 0, 0.5, 0]], ws)
    # a windows file without the key (written by hand or an older rmtkit) is matched by name
    bare = WindowSet.from_dict({k: v for k, v in ws.to_dict().items() if k != "robot_key"})
    bare.check_robot(other)
    with pytest.raises(WindowError, match="are of 'fanuc_m16ib20', not of 'puma560'"):
        bare.check_robot(puma)

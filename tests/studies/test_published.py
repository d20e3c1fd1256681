"""studies.published: the published values (with their source) and the comparison of a learned-IK
window with the published one — made in the studies, never in the core (design.learned reports the
method alone)."""
from __future__ import annotations

import pytest

import design.learned
from studies.published import PUBLISHED_LEARNED_WINDOWS, compare_learned_window


def _report(joints, width=0.37, status="ok"):
    """The fields of a design.learned.learned_window report the comparison reads."""
    return {"status": status, "factor": {"kind": "boundary", "expr": "sin(q2)", "joints": joints},
            "width": width, "intervals": [[-width, width]]}


def test_the_scara_window_as_published():
    # docs/machines.md §2: the learned-IK error window of the SCARA, θ2 ∈ [−0.01, 0.01] rad
    p = PUBLISHED_LEARNED_WINDOWS["scara_rrp"]
    assert p["joint"] == 2 and p["interval"] == (-0.01, 0.01)
    assert "thesis" in p["source"] and "docs/machines.md §2" in p["source"]


def test_comparison_beside_a_report():
    out = compare_learned_window(_report([2], width=0.25), "scara_rrp")
    assert out == {"joint": "q2", "interval": [-0.01, 0.01], "width": pytest.approx(0.01),
                   "source": PUBLISHED_LEARNED_WINDOWS["scara_rrp"]["source"], "ours_intervals": [[-0.25, 0.25]],
                   "ours_width": 0.25, "ours_over_published": pytest.approx(25.0)}


@pytest.mark.parametrize("report, robot", [
    (_report([2]), "fanuc_m16ib20"),                 # nothing published for this robot
    (_report([1]), "scara_rrp"),                     # another joint than the published one
    (_report([2, 3]), "scara_rrp"),                  # a factor of several joints
    (_report([2], status="skipped"), "scara_rrp"),   # no window computed
])
def test_no_comparison_where_nothing_matches(report, robot):
    assert compare_learned_window(report, robot) is None


def test_the_core_holds_no_published_values():
    assert not [name for name in dir(design.learned) if "THESIS" in name.upper() or "PUBLISHED" in name.upper()]

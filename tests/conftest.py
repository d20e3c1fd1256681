"""Which tests are slow: the end-to-end runs (whole bundled studies and their reports in a browser,
sweeps with worker processes and Dask clusters, the numeric analysis of a 12-joint chain, the long
command-line examples of the docs) are marked ``slow`` here, in one list, so that ``make test``
(``pytest -m "not slow"``, on every core by pytest-xdist) stays under five minutes on two cores and
``make test-slow`` runs them; CI runs both.  Nothing is skipped: a slow test only runs in the second step."""
from __future__ import annotations

import pytest

#: test files that are end-to-end as a whole
SLOW_FILES = (
    "tests/studies/bundled/",
    "tests/studies/report/test_browser_harness.py",
    "tests/design/sweep/test_kill.py",
    "tests/design/sweep/test_cluster.py",
    "tests/design/sweep/test_refine.py",
    "tests/design/sweep/test_run.py",
    "tests/kin/modules/test_timor.py",        # needs .venv-timor, which `make test-slow` makes
)

#: single tests (node id prefixes) of several seconds each
SLOW_TESTS = (
    "tests/kin/singular/test_numeric.py::test_12_joint_chain_answers_within_2_gb",
    "tests/kin/singular/test_numeric.py::test_general_chains_answer_numerically",
    "tests/studies/cli/test_one_window.py::test_sampled_windows_are_said_and_a_sigma_floor_catches_what_they_miss",
    "tests/studies/cli/test_one_window.py::test_other_planners_paths_pass_check_path",
    "tests/studies/cli/test_one_window.py::test_windows_of_a_numeric_analysis_do_not_follow_the_seed",
    "tests/studies/cli/test_singular.py::test_seven_joint_arms_get_their_singular_set_and_windows",
    "tests/studies/cli/test_singular.py::test_singularities_of_a_general_chain_say_numeric",
    "tests/design/optimise/test_run.py::test_scara_ipopt_matches_the_grid",
    "tests/design/test_architecture.py::test_all_eight_evaluated_and_the_gantry_covers_the_box",
    "tests/planning/windows/test_sampled.py::test_sigma_min_windows_of_a_general_chain",
    "tests/planning/timing/test_torque.py::test_reach_and_qp_agree_with_torque_limits",
    "tests/kin/urdf/test_round_trip.py::test_meshes_of_every_arm_round_trip_and_are_held",
    "tests/kin/geometry/test_bundled_geometry.py::test_panda_capsules_are_those_of_the_meshes",
    "tests/planning/certify/test_points.py::test_proven_segments_are_clear_and_violations_are_inside",
    "tests/studies/benchmarks/test_bench_mbm.py::test_one_problem_per_scene_reports_every_figure",
    "tests/studies/benchmarks/test_bench_startup.py::test_the_report_holds_every_command",
    "tests/planning/timing/test_reachability.py::test_same_duration_as_the_osqp_method",
    "tests/planning/certify/test_points.py::test_segments_through_a_point_are_never_proven",
    "tests/design/compose/test_compose_acceptance.py::test_least_cost_equals_the_exhaustive_enumeration_with_links",
)

#: `rmt` commands of the docs' examples that run a study, a sweep, an optimisation, a composition
#: search or a follower over thousands of waypoints (a page's commands that read their output are among them)
SLOW_COMMANDS = {"study", "sweep", "sweep-export", "sweep-plot", "optimise", "follow", "compose"}


def _slow(item) -> bool:
    nodeid = item.nodeid
    if nodeid.startswith(SLOW_FILES) or nodeid.startswith(SLOW_TESTS):
        return True
    if nodeid.startswith("tests/test_doc_examples.py::test_cli_example"):
        argv = getattr(item, "callspec", None) and item.callspec.params.get("argv")
        return bool(argv) and argv[0] in SLOW_COMMANDS
    return False


def pytest_collection_modifyitems(config, items):
    for item in items:
        if _slow(item):
            item.add_marker(pytest.mark.slow)

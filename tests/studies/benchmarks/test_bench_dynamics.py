"""bench_dynamics at its smallest: the report's structure and the agreement with pinocchio (no timing
asserted)."""
import pytest

pytest.importorskip("pinocchio")


def test_quick_report(monkeypatch):
    from studies.benchmarks import bench_dynamics
    try:
        bench_dynamics._urdf_path()
    except RuntimeError:
        pytest.skip("example-robot-data is not installed")
    monkeypatch.setattr(bench_dynamics, "_per_call_us", lambda fn, repeat, number: (fn(), 1.0)[1])
    R = bench_dynamics.run(None, quick=True)
    assert R["joints"] == 6 and R["agreement"]["tau_max_rel"] <= 1e-10
    assert R["agreement"]["mass_matrix_max_rel"] <= 1e-10
    assert {t["name"] for t in R["targets"]} >= {"agreement with pinocchio (relative)"}
    assert "bench_dynamics" in bench_dynamics.format_report(R)

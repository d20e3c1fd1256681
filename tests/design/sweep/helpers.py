"""Small SCARA sweeps for the sweep tests: a 3 × 3 box of targets, 2 IK seeds, 300 samples, so a
design takes a few milliseconds; and a per-design function that fails for some designs."""
from __future__ import annotations

from pathlib import Path

from design.sweep.evaluate import evaluate_design
from studies.benchmarks.bench_sweep import task_text

ROOT = Path(__file__).resolve().parents[3]
TASK = task_text("scara_small", (3, 3), 0.8)


def write_sweep(folder: Path, counts=(6, 6), sampling: str = "", extra: str = "", name: str = "small") -> Path:
    """A sweep file over A1, A2 ∈ [100, 400] mm (grid ``counts`` unless ``sampling`` is given)."""
    folder.mkdir(parents=True, exist_ok=True)
    (folder / "task.toml").write_text(TASK)
    c1 = f"count = {counts[0]}" if not sampling else ""
    c2 = f"count = {counts[1]}" if not sampling else ""
    text = f'''
name = "{name}"
task = "task.toml"
{extra}
[evaluation]
seeds = 2
samples = 300
{sampling}
[parameters.A1]
range = [100, 400]
{c1}
[parameters.A2]
range = [100, 400]
{c2}
'''
    p = folder / f"{name}.toml"
    p.write_text(text)
    return p


def evaluate_failing(job, robot, design):
    """The ordinary evaluation, except that designs with A1 > 0.35 m raise."""
    if design.values["A1"] > 0.35:
        raise ValueError(f"test failure for A1 = {design.values['A1']}")
    return evaluate_design(job, robot, design)


def evaluate_dying_once(job, robot, design):
    """The ordinary evaluation, except that the first design with A1 > 0.3 m kills its worker
    process (once per task folder: a marker file ``died`` beside the task file records it)."""
    import os
    marker = Path(job.task.source).parent / "died"
    if design.values["A1"] > 0.3 and not marker.exists():
        marker.touch()
        os._exit(1)
    return evaluate_design(job, robot, design)


def evaluate_slow(job, robot, design):
    """The ordinary evaluation after a 20 ms pause (so a test can kill a sweep part-way on any machine)."""
    import time
    time.sleep(0.02)
    return evaluate_design(job, robot, design)

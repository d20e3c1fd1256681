"""Parameter sweeps: sweep files (:mod:`~design.sweep.file`), the design space and its sampling
(:mod:`~design.sweep.space`), the SQLite store (:mod:`~design.sweep.store`), the per-design
evaluation (:mod:`~design.sweep.evaluate`), local and Dask executors (:mod:`~design.sweep.local`,
:mod:`~design.sweep.cluster`), the driver (:mod:`~design.sweep.run`), Gaussian-process refinement
(:mod:`~design.sweep.refine`) and export (:mod:`~design.sweep.export`)."""
from design.sweep.cluster import DaskExecutor
from design.sweep.evaluate import Outcome, SweepJob, evaluate_chunk, evaluate_design, make_job
from design.sweep.export import best_row, read_sweep, sweep_table, write_csv, write_parquet
from design.sweep.file import METRICS, SAMPLINGS, ParameterSpace, Sweep, SweepError, load_sweep, loads_sweep
from design.sweep.local import LocalExecutor
from design.sweep.run import SweepReport, run_sweep
from design.sweep.space import Design, design_key, sample_designs
from design.sweep.store import Store, StoreError

__all__ = ["Sweep", "ParameterSpace", "SweepError", "load_sweep", "loads_sweep", "SAMPLINGS", "METRICS",
           "Design", "design_key", "sample_designs", "Store", "StoreError", "SweepJob", "Outcome", "make_job",
           "evaluate_design", "evaluate_chunk", "LocalExecutor", "DaskExecutor", "SweepReport", "run_sweep",
           "read_sweep", "sweep_table", "write_csv", "write_parquet", "best_row"]

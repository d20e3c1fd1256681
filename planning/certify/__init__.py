"""Proofs about joint paths: interval arithmetic over singular factors
(:mod:`~planning.certify.intervals`), segments proven clear of every window or the first state
inside one (:mod:`~planning.certify.segments`), and start/goal pairs that no joint path can join
(:mod:`~planning.certify.cells`)."""
from planning.certify.cells import FreeCells, Separation, free_cells
from planning.certify.intervals import IntervalError, compile_interval
from planning.certify.segments import PathProof, SegmentViolation, certify_path

__all__ = ["certify_path", "PathProof", "SegmentViolation", "FreeCells", "Separation", "free_cells", "compile_interval",
           "IntervalError"]

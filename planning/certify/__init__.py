"""Proofs about joint paths: interval arithmetic over singular factors
(:mod:`~planning.certify.intervals`) and segments proven clear of every window, or the first state
inside one (:mod:`~planning.certify.segments`)."""
from planning.certify.intervals import IntervalError, compile_interval
from planning.certify.segments import PathProof, SegmentViolation, certify_path

__all__ = ["certify_path", "PathProof", "SegmentViolation", "compile_interval", "IntervalError"]

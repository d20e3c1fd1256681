"""Proofs about joint paths: interval arithmetic over singular factors
(:mod:`~planning.certify.intervals`), segments proven clear of every window or the first state
inside one (:mod:`~planning.certify.segments`), σ_min floors proven along segments
(:mod:`~planning.certify.sigma`), and start/goal pairs that no joint path can join
(:mod:`~planning.certify.cells`)."""
from planning.certify.cells import FreeCells, Separation, free_cells
from planning.certify.intervals import IntervalError, compile_interval
from planning.certify.segments import PathProof, SegmentViolation, certify_path
from planning.certify.sigma import SigmaProof, certify_sigma, jacobian_lipschitz

__all__ = ["certify_path", "PathProof", "SegmentViolation", "certify_sigma", "SigmaProof", "jacobian_lipschitz",
           "FreeCells", "Separation", "free_cells", "compile_interval", "IntervalError"]

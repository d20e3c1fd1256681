"""Reach studies: which targets a robot placed in a work cell reaches, how well, and why not."""
from design.reach.compare import ReachComparison, compare_studies
from design.reach.score import MEASURES, ScoreWeights, limit_margin
from design.reach.study import (
                                REASONS,
                                ReachProblem,
                                ReachSettings,
                                ReachStudy,
                                halton_configurations,
                                placement_matrix,
                                reach_study,
)

__all__ = ["ReachComparison", "compare_studies", "ScoreWeights", "MEASURES", "limit_margin", "REASONS",
           "ReachSettings", "ReachStudy", "ReachProblem", "reach_study", "halton_configurations", "placement_matrix"]

"""Robot placement: the base pose in a work cell that reaches most targets, best (IPOPT, with
differential evolution and a grid as cross-checks, every answer verified by the reach study)."""
from design.place.codesign import evaluate_placed_design, pareto_front
from design.place.nlp import NlpRun, PlacementNlp
from design.place.pair import PairResult, place_pair, robot_robot_clearance
from design.place.region import COORDINATES, PlacementRegion, placement_transform
from design.place.run import MAX_GRID, SCREEN, PlacementResult, place
from design.place.search import de_search, evaluate_placements, grid_placements, halton_placements

__all__ = ["place", "place_pair", "PairResult", "robot_robot_clearance", "pareto_front", "evaluate_placed_design",
           "PlacementResult", "PlacementRegion", "PlacementNlp", "NlpRun", "COORDINATES", "SCREEN", "MAX_GRID",
           "placement_transform", "de_search", "evaluate_placements", "grid_placements", "halton_placements"]

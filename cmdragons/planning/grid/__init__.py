"""Grid navigation: cost grids, NF1, 8-connected shortest paths and E* (Philippsen 2004)."""

from cmdragons.planning.grid.movingai import MapError, Scenario, read_map, read_scenarios
from cmdragons.planning.grid.planners import EStar, GridPath, descend_nf1, nf1, octile_path

__all__ = ["EStar", "GridPath", "MapError", "Scenario", "descend_nf1", "nf1", "octile_path", "read_map",
           "read_scenarios"]

"""EasyNav planners: SimplePlanner (A* on the simple grid)."""

"""Planners of the GridMap stack: grid A* and RRT* on an elevation map with a slope limit."""

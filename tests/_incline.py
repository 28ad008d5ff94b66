"""A cell's floor tilted into an incline, for the DEM's analytic stick/slide/roll tests."""

from __future__ import annotations

import math

import numpy as np

from pidcore.dem.geometry import CellGeometry


class Incline:
    """A plane through the origin tilted by ``theta`` about y (the other walls 1 m away).

    Down-slope direction t = (cos th, 0, -sin th); inward normal n = (sin th, 0, cos th).
    """

    def __init__(self, theta: float):
        normals = CellGeometry().wall_normals.copy()
        normals[6] = [math.sin(theta), 0.0, math.cos(theta)]
        self.wall_normals = np.ascontiguousarray(normals)
        self.wall_offsets = np.array([1.0] * 6 + [0.0, 1.0])
        self.normal = normals[6]
        self.down = np.array([math.cos(theta), 0.0, -math.sin(theta)])

    def signed_distances(self, points):
        return np.asarray(points) @ self.wall_normals.T + self.wall_offsets

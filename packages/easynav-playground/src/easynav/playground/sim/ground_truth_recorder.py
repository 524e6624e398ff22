"""GroundTruthRecorder: what really happened in a run, for evaluating the navigation."""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np


class GroundTruthRecorder:
    """Keeps the true trajectory, an estimated one when given, clearances and collisions.

    Trajectories are lists of ``(stamp, x, y, yaw)``. The localisation error pairs each
    estimate with the true pose interpolated at the estimate's stamp. On a world with terrain,
    :attr:`terrain` lists ``(stamp, z, slope)`` with each true pose: the ground height (m) and
    slope (rad) under the robot (empty on flat worlds, and then absent from the saved file). On a
    multi-level world, :attr:`levels` lists ``(stamp, level, z, pitch)`` with each true pose: the
    level the robot is on (a floor's or a ramp's name), its height (m) and pitch (rad, REP-103:
    negative nose up), so the true pose is ``(x, y, z, yaw)`` and the level (empty elsewhere, and
    then absent from the saved file).

    Thread contract: not thread-safe. In the playground the simulation loop records; in the
    demo the executor thread records. Read results from the same thread or after the run.
    """

    def __init__(self) -> None:
        self.true_poses: list[tuple[float, float, float, float]] = []
        self.estimated_poses: list[tuple[float, float, float, float]] = []
        self.clearances: list[tuple[float, float]] = []
        self.collisions: list[dict] = []
        self.terrain: list[tuple[float, float, float]] = []
        self.levels: list[tuple[float, str, float, float]] = []
        self.min_clearance = math.inf
        self.min_clearance_at: tuple[float, float, float] | None = None

    def record_true(self, stamp: float, x: float, y: float, yaw: float) -> None:
        """Add a true pose sample (stamps must not go backwards)."""
        if self.true_poses and stamp < self.true_poses[-1][0]:
            raise ValueError(
                f"GroundTruthRecorder: true pose stamp {stamp} is older than the last one "
                f"{self.true_poses[-1][0]}"
            )
        self.true_poses.append((float(stamp), float(x), float(y), float(yaw)))

    def record_terrain(self, stamp: float, z: float, slope: float) -> None:
        """Add the ground height ``z`` (m) and slope (rad) under the robot at ``stamp``."""
        self.terrain.append((float(stamp), float(z), float(slope)))

    def record_level(self, stamp: float, level: str, z: float, pitch: float) -> None:
        """Add the level, height ``z`` (m) and pitch (rad) of the robot at ``stamp``."""
        self.levels.append((float(stamp), str(level), float(z), float(pitch)))

    def level_at(self, stamp: float) -> str | None:
        """The level of the latest sample at or before ``stamp`` (the first one before them
        all); None without level samples (a world without levels)."""
        if not self.levels:
            return None
        found = self.levels[0][1]
        for t, level, _, _ in self.levels:
            if t > stamp:
                break
            found = level
        return found

    def max_slope(self, start: float = -math.inf, end: float = math.inf) -> float:
        """The steepest slope (rad) under the robot between two stamps; NaN without terrain
        samples there (a flat world)."""
        slopes = [s for t, _, s in self.terrain if start <= t <= end]
        return max(slopes) if slopes else math.nan

    def record_estimate(self, stamp: float, x: float, y: float, yaw: float) -> None:
        """Add an estimated pose sample (from a localizer), in the same frame as the truth."""
        self.estimated_poses.append((float(stamp), float(x), float(y), float(yaw)))

    def record_clearance(self, stamp: float, x: float, y: float, clearance: float) -> None:
        """Add the robot's clearance (m) to the nearest obstacle at ``(x, y)``."""
        self.clearances.append((float(stamp), float(clearance)))
        if clearance < self.min_clearance:
            self.min_clearance = float(clearance)
            self.min_clearance_at = (float(stamp), float(x), float(y))

    def record_collision(self, collision: dict) -> None:
        """Add a collision (``{"stamp", "x", "y", "with"}``)."""
        self.collisions.append(dict(collision))

    # ------------------------------------------------------------------ results
    def distance_driven(self, start: float = -math.inf, end: float = math.inf) -> float:
        """Length (m) of the true trajectory between two stamps."""
        pts = np.array([p[1:3] for p in self.true_poses if start <= p[0] <= end])
        if len(pts) < 2:
            return 0.0
        return float(np.hypot(*np.diff(pts, axis=0).T).sum())

    def localisation_errors(self, start: float = -math.inf, end: float = math.inf) -> np.ndarray:
        """Position errors (m) of the estimates stamped in ``[start, end]`` against the
        interpolated truth.

        Estimates outside the span of the true trajectory are not paired (no extrapolation).
        """
        if len(self.true_poses) < 2 or not self.estimated_poses:
            return np.zeros(0)
        truth = np.array(self.true_poses)
        est = np.array(self.estimated_poses)
        inside = (est[:, 0] >= max(truth[0, 0], start)) & (est[:, 0] <= min(truth[-1, 0], end))
        est = est[inside]
        tx = np.interp(est[:, 0], truth[:, 0], truth[:, 1])
        ty = np.interp(est[:, 0], truth[:, 0], truth[:, 2])
        return np.hypot(est[:, 1] - tx, est[:, 2] - ty)

    def true_pose_at(self, stamp: float) -> tuple[float, float] | None:
        """The true position interpolated at ``stamp``, None outside the recorded span."""
        if not self.true_poses or not self.true_poses[0][0] <= stamp <= self.true_poses[-1][0]:
            return None
        truth = np.array(self.true_poses)
        return (
            float(np.interp(stamp, truth[:, 0], truth[:, 1])),
            float(np.interp(stamp, truth[:, 0], truth[:, 2])),
        )

    # ------------------------------------------------------------------ persistence
    def to_dict(self) -> dict:
        """A JSON-ready snapshot."""
        data = {
            "true_poses": self.true_poses,
            "estimated_poses": self.estimated_poses,
            "clearances": self.clearances,
            "collisions": self.collisions,
            "min_clearance": None if math.isinf(self.min_clearance) else self.min_clearance,
            "min_clearance_at": self.min_clearance_at,
        }
        if self.terrain:
            data["terrain"] = self.terrain
        if self.levels:
            data["levels"] = self.levels
        return data

    def save(self, path: str | Path) -> None:
        """Write :meth:`to_dict` as JSON (atomically: a reader never sees half a file)."""
        path = Path(path)
        tmp = path.with_name(path.name + ".tmp")
        tmp.write_text(json.dumps(self.to_dict()))
        tmp.replace(path)

    @classmethod
    def load(cls, path: str | Path) -> GroundTruthRecorder:
        """Read a file written by :meth:`save`.

        Raises:
            FileNotFoundError: no such file.
            ValueError: not a recorder file (names the missing key).
        """
        data = json.loads(Path(path).read_text())
        rec = cls()
        for key in ("true_poses", "estimated_poses", "clearances", "collisions"):
            if key not in data:
                raise ValueError(f"{path}: not a ground-truth record (missing '{key}')")
        rec.true_poses = [tuple(p) for p in data["true_poses"]]
        rec.estimated_poses = [tuple(p) for p in data["estimated_poses"]]
        rec.clearances = [tuple(c) for c in data["clearances"]]
        rec.collisions = list(data["collisions"])
        rec.terrain = [tuple(t) for t in data.get("terrain", ())]
        rec.levels = [tuple(t) for t in data.get("levels", ())]
        if data.get("min_clearance") is not None:
            rec.min_clearance = float(data["min_clearance"])
            at = data.get("min_clearance_at")
            rec.min_clearance_at = tuple(at) if at else None
        return rec

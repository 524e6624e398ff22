"""RunSummary: the figures of a demo run and its table."""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from easynav.playground.demo.waypoint_result import WaypointResult
from easynav.playground.sim.ground_truth_recorder import GroundTruthRecorder


@dataclass
class RunSummary:
    """What the demo reports: per-waypoint results and whole-run figures.

    Built by :meth:`compute` from the playground's ground truth (with EasyNav's estimates
    added) and the waypoint events seen during the run.

    Thread contract: plain data, built after the run.
    """

    waypoints: list[WaypointResult]
    final_state: str
    status_message: str = ""
    nav_start: float = 0.0
    nav_end: float = 0.0
    distance_driven: float = 0.0
    min_clearance: float = math.nan
    collisions: list[dict] = field(default_factory=list)
    localisation_mean: float = math.nan
    localisation_max: float = math.nan
    localisation_samples: int = 0
    command_rate: float = 0.0
    real_time_factor: float = math.nan
    late_rt_cycles: int | None = None
    #: The controller's update_rt cost as EasyNav logged it when it stopped: ``{"alias",
    #: "plugin", "runs", "median_ms", "p99_ms", "max_ms"}``; None when not found.
    controller_cycle: dict | None = None
    #: How old the ``odom → robot`` transforms were when EasyNav's TF listener served them
    #: (its executor's backlog, which every pose lookup lags by): ``{"transforms",
    #: "median_ms", "p99_ms", "max_ms"}`` as EasyNav logged it when it stopped; None when not
    #: found.
    odometry_age: dict | None = None
    #: The steepest ground (rad) under the robot during the navigation; NaN on flat worlds.
    max_slope: float = math.nan

    @property
    def all_reached(self) -> bool:
        """Every waypoint reached (on its own level, on a multi-level world)."""
        return all(w.achieved for w in self.waypoints)

    @property
    def success(self) -> bool:
        """Every waypoint reached and no collision: the demo's exit code 0."""
        return self.all_reached and not self.collisions

    @classmethod
    def compute(
        cls,
        waypoints: list[WaypointResult],
        truth: GroundTruthRecorder,
        final_state: str,
        status_message: str,
        nav_start: float,
        nav_end: float,
        command_rate: float,
        real_time_factor: float = math.nan,
    ) -> RunSummary:
        """Fill the legs of the reached waypoints and the whole-run figures.

        ``truth`` holds the true trajectory, clearances and collisions (the playground's
        record) and EasyNav's estimated poses.
        """
        previous = nav_start
        for w in waypoints:
            if w.reached_at is None:
                continue
            w.leg_time = w.reached_at - previous
            w.leg_distance = truth.distance_driven(previous, w.reached_at)
            at = truth.true_pose_at(w.reached_at)
            if at is not None:
                w.arrival_error = math.hypot(at[0] - w.x, at[1] - w.y)
            w.arrival_level = truth.level_at(w.reached_at)
            previous = w.reached_at
        in_run = [c for c in truth.clearances if nav_start <= c[0] <= nav_end]
        errors = truth.localisation_errors()
        return cls(
            waypoints=waypoints,
            final_state=final_state,
            status_message=status_message,
            nav_start=nav_start,
            nav_end=nav_end,
            distance_driven=truth.distance_driven(nav_start, nav_end),
            min_clearance=min((c[1] for c in in_run), default=math.nan),
            collisions=list(truth.collisions),
            localisation_mean=float(np.mean(errors)) if errors.size else math.nan,
            localisation_max=float(np.max(errors)) if errors.size else math.nan,
            localisation_samples=int(errors.size),
            command_rate=command_rate,
            real_time_factor=real_time_factor,
            max_slope=truth.max_slope(nav_start, nav_end),
        )

    def to_dict(self) -> dict:
        """The whole-run figures as JSON-ready values (NaN as None), for tools such as the
        integration matrix."""

        def clean(value):
            return None if isinstance(value, float) and math.isnan(value) else value

        return {
            "waypoints": len(self.waypoints),
            "reached": sum(w.achieved for w in self.waypoints),
            "reached_on_wrong_level": sum(w.reached and not w.on_level for w in self.waypoints),
            "final_state": self.final_state,
            "status_message": self.status_message,
            "navigation_time": clean(self.nav_end - self.nav_start),
            "distance_driven": clean(self.distance_driven),
            "min_clearance": clean(self.min_clearance),
            "collisions": len(self.collisions),
            "localisation_mean": clean(self.localisation_mean),
            "localisation_max": clean(self.localisation_max),
            "command_rate": clean(self.command_rate),
            "real_time_factor": clean(self.real_time_factor),
            "late_rt_cycles": self.late_rt_cycles,
            "controller_cycle": self.controller_cycle,
            "odometry_age": self.odometry_age,
            "max_slope_deg": clean(math.degrees(self.max_slope)),
            "success": self.success,
        }

    def format_table(self) -> str:
        """The summary as plain text: a waypoint table, then the run figures."""

        def num(value: float, fmt: str) -> str:
            return "-" if value is None or math.isnan(value) else format(value, fmt)

        lines = [
            " #      x      y    yaw  reached   time(s)  driven(m)  off(m)",
            "-- ------ ------ ------  -------  --------  ---------  ------",
        ]
        for w in self.waypoints:
            lines.append(
                f"{w.index:2d} {w.x:6.2f} {w.y:6.2f} {w.yaw:6.2f}  "
                f"{_reached_cell(w):>7}  {num(w.leg_time, '8.1f'):>8}  "
                f"{num(w.leg_distance, '9.2f'):>9}  {num(w.arrival_error, '6.3f'):>6}"
            )
        reached = sum(w.achieved for w in self.waypoints)
        lines += [
            f"  waypoint {w.index} reached on level {w.arrival_level}, not on its level {w.level}"
            for w in self.waypoints if w.reached and not w.on_level
        ]
        lines += [
            "",
            f"result:               {self.final_state}"
            + (f" ({self.status_message})" if self.status_message else ""),
            f"waypoints reached:    {reached} of {len(self.waypoints)}",
            f"navigation time:      {self.nav_end - self.nav_start:.1f} s (simulated)",
            f"distance driven:      {self.distance_driven:.2f} m",
            f"min clearance:        {num(self.min_clearance, '.3f')} m (robot edge to obstacles)",
            f"collisions:           {len(self.collisions)}",
            f"localisation error:   mean {num(self.localisation_mean, '.3f')} m, "
            f"max {num(self.localisation_max, '.3f')} m ({self.localisation_samples} samples)",
            f"velocity commands:    {self.command_rate:.1f} Hz (simulated time)",
        ]
        if not math.isnan(self.max_slope):
            lines.append(
                f"max slope driven:     {math.degrees(self.max_slope):.1f} deg (ground under the "
                "robot)"
            )
        if not math.isnan(self.real_time_factor):
            lines.append(f"simulation speed:     x{self.real_time_factor:.2f} real time")
        if self.late_rt_cycles is not None:
            lines.append(f"late RT cycles:       {self.late_rt_cycles} (EasyNav's heartbeat)")
        if self.controller_cycle is not None:
            c = self.controller_cycle
            lines.append(
                f"controller cycle:     median {c['median_ms']:.2f} ms, p99 {c['p99_ms']:.2f} ms, "
                f"max {c['max_ms']:.2f} ms ({c['alias']}: {c['plugin']}, {c['runs']} runs)"
            )
        if self.odometry_age is not None:
            a = self.odometry_age
            lines.append(
                f"odom TF age served:   median {a['median_ms']:.1f} ms, p99 {a['p99_ms']:.1f} ms, "
                f"max {a['max_ms']:.1f} ms ({a['transforms']} transforms)"
            )
        for c in self.collisions:
            lines.append(
                f"  collision with {c.get('with')} at ({c.get('x', 0):.2f}, {c.get('y', 0):.2f}), "
                f"t={c.get('stamp', 0):.1f} s"
            )
        lines.append(f"verdict:              {'SUCCESS' if self.success else 'FAILURE'}")
        return "\n".join(lines)


def _reached_cell(w: WaypointResult) -> str:
    """The table's ``reached`` cell: yes, NO, or LEVEL (reached on another level)."""
    if not w.reached:
        return "NO"
    return "yes" if w.on_level else "LEVEL"

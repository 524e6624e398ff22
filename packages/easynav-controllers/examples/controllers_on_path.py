"""Follow the same path with SimpleController, RegulatedPurePursuit and MPPI, without ROS.

    python packages/easynav-controllers/examples/controllers_on_path.py [--plot out.png]

Each plugin is configured from a dict of parameters (as ``controller_node`` would from a params
file) and driven at 20 Hz as the RT loop drives it: NavState ``path`` and ``robot_pose`` in,
``cmd_vel`` out. A kinematic unicycle executes the command (no smoothing, no noise) and
becomes the next ``robot_pose``. The path is an S-curve 6 m long that ends facing +y; the robot
starts 0.3 m off it. Printed: the time to arrive, the final distance to the end of the path
and the yaw error, the largest distance from the path, the top and mean speeds.
"""

from __future__ import annotations

import argparse
import math

import numpy as np

from easynav.controllers.mppi.mppi_controller import MPPIController
from easynav.controllers.regulated_pp.regulated_pp_controller import (
    RegulatedPurePursuitController,
)
from easynav.controllers.simple_controller import SimpleController
from easynav.core.nav_state import NavState
from easynav.core.plugins import DictParameters, PluginContext
from easynav.core.robot import RobotLimits
from easynav.core.types import Header, Odometry, Path, Pose, TwistStamped

LIMITS = RobotLimits(max_linear_vel=0.5, min_linear_vel=-0.2, max_angular_vel=1.0,
                     max_linear_acc=0.5, max_linear_decel=1.0, max_angular_acc=1.5,
                     max_angular_decel=2.0)
DT = 0.05  # 20 Hz

#: (plugin, alias as in a params file, its parameters)
CONTROLLERS = (
    (SimpleController, "simple", {"look_ahead_dist": 0.4}),
    (RegulatedPurePursuitController, "rpp", {}),
    (MPPIController, "mppi", {"num_samples": 400, "horizon_steps": 30, "seed": 7}),
)


class Clock:
    """The node clock, moved by the simulation."""

    def __init__(self) -> None:
        self.t = 0.0

    def __call__(self) -> float:
        return self.t


def s_curve() -> np.ndarray:
    xs = np.arange(0.0, 6.001, 0.05)
    ys = np.sin(xs)
    yaws = np.arctan2(np.gradient(ys), np.gradient(xs))
    yaws[-1] = math.pi / 2  # finish facing +y
    return np.column_stack((xs, ys, yaws))


def distance_to(path: np.ndarray, x: float, y: float) -> float:
    a, b = path[:-1, :2], path[1:, :2]
    ab = b - a
    t = np.clip(np.einsum("ij,ij->i", (x, y) - a, ab) / np.einsum("ij,ij->i", ab, ab), 0, 1)
    q = a + ab * t[:, None]
    return float(np.min(np.hypot(q[:, 0] - x, q[:, 1] - y)))


def drive(cls, alias: str, params: dict, path: np.ndarray, t_max: float = 60.0):
    clock = Clock()
    values = {f"{alias}.rt_freq": 1.0 / DT}
    values.update({f"{alias}.{k}": v for k, v in params.items()})
    context = PluginContext(parameters=DictParameters(values), namespace=f"example_{alias}",
                            now=clock, robot_limits=lambda: LIMITS)
    controller = cls()
    controller.initialize(context, alias)

    nav_state = NavState()
    nav_state.set("path", Path.from_xy_yaw(path, Header(0.0, "map")))
    nav_state.set("goal_tolerance.position", 0.1)
    nav_state.set("goal_tolerance.yaw", 0.1)
    x, y, yaw = 0.0, -0.3, 0.5
    trace = []
    while clock.t < t_max:
        nav_state.set("robot_pose", Odometry(Header(clock.t, "map"), "base_footprint",
                                             Pose.from_xy_yaw(x, y, yaw)))
        controller.update_rt(nav_state)
        twist = nav_state.get("cmd_vel", TwistStamped).twist
        trace.append((x, y, twist.vx))
        if controller.state == "arrived":
            break
        x += twist.vx * math.cos(yaw + 0.5 * twist.wz * DT) * DT
        y += twist.vx * math.sin(yaw + 0.5 * twist.wz * DT) * DT
        yaw += twist.wz * DT
        clock.t += DT
    return controller.state, clock.t, (x, y, yaw), np.array(trace)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--plot", metavar="PNG", help="draw the path and the runs (matplotlib)")
    args = parser.parse_args()

    path = s_curve()
    end = path[-1]
    print(f"S-curve of {len(path)} poses to ({end[0]:.2f}, {end[1]:.2f}, yaw {end[2]:.2f}); "
          f"start (0.00, -0.30, yaw 0.50)")
    runs = []
    for cls, alias, params in CONTROLLERS:
        state, t, (x, y, yaw), trace = drive(cls, alias, params, path)
        final = math.hypot(x - end[0], y - end[1])
        yaw_error = abs(math.remainder(yaw - end[2], 2 * math.pi))
        worst = max(distance_to(path, px, py) for px, py, _ in trace[len(trace) // 10:])
        print(f"{cls.__name__:31s} {state} after {t:4.1f} s: final distance {final:.3f} m, "
              f"yaw error {yaw_error:.3f} rad, off the path at most {worst:.2f} m, "
              f"speed top {trace[:, 2].max():.2f} mean {trace[:, 2].mean():.2f} m/s")
        runs.append((cls.__name__, trace))

    if args.plot:
        try:
            import matplotlib
        except ImportError:
            print("--plot: matplotlib is not installed")
            return
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt

        fig, ax = plt.subplots(figsize=(9, 4))
        ax.plot(path[:, 0], path[:, 1], "o", color="grey", markersize=2, label="path")
        for name, trace in runs:
            ax.plot(trace[:, 0], trace[:, 1], "-", label=name)
        ax.set_aspect("equal")
        ax.legend()
        fig.savefig(args.plot, dpi=80)
        print("picture:", args.plot)


if __name__ == "__main__":
    main()

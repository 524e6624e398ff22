"""SimplePathFollower drives a simulated unicycle along an S-shaped path.

    python packages/easynav-controllers/examples/follow_path.py [--plot output.png]

SimplePathFollower is the algorithm inside the SimpleController plugin, called directly
(``controllers_on_path.py`` drives the plugins). Prints the final error and the speeds;
``--plot`` (with matplotlib) draws the trajectory.
"""

from __future__ import annotations

import argparse
import math

import numpy as np

from easynav.controllers import ARRIVED, SimplePathFollower
from easynav.core.robot import RobotLimits


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--plot", metavar="PNG", help="draw the trajectory (matplotlib)")
    args = parser.parse_args()
    xs = np.arange(0.0, 6.01, 0.2)
    path = np.column_stack((xs, np.sin(xs), np.zeros_like(xs)))
    path[-1, 2] = math.pi / 2  # finish facing +y
    follower = SimplePathFollower(look_ahead_dist=0.4)
    limits = RobotLimits(max_linear_vel=0.6, max_angular_vel=1.0)
    x, y, yaw, dt, t = 0.0, -0.3, 0.5, 1 / 30, 0.0
    trace = []
    state = ""
    while t < 60.0 and state != ARRIVED:
        v, w, state = follower.compute((x, y, yaw), path, dt, limits)
        trace.append((x, y, v, w))
        x += v * math.cos(yaw) * dt
        y += v * math.sin(yaw) * dt
        yaw += w * dt
        t += dt
    trace = np.array(trace)
    error = math.hypot(x - path[-1, 0], y - path[-1, 1])
    print(f"{state} after {t:.1f} s: {error:.3f} m from the end, yaw {yaw:.3f} rad")
    print(f"top speed {trace[:, 2].max():.2f} m/s, mean {trace[:, 2].mean():.2f} m/s")

    if not args.plot:
        return
    try:
        import matplotlib
    except ImportError:
        print("--plot: matplotlib is not installed")
        return
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(9, 4))
    ax.plot(path[:, 0], path[:, 1], "o-", color="grey", markersize=3, label="path")
    ax.plot(trace[:, 0], trace[:, 1], "-", label="robot")
    ax.set_aspect("equal")
    ax.legend()
    fig.savefig(args.plot, dpi=80)
    print("picture:", args.plot)


if __name__ == "__main__":
    main()

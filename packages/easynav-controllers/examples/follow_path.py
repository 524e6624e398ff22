"""SimplePathFollower drives a simulated unicycle along an S-shaped path.

python packages/easynav-controllers/examples/follow_path.py [output.png]
"""

from __future__ import annotations

import math
import sys
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from easynav.controllers import ARRIVED, SimplePathFollower  # noqa: E402
from easynav.core.robot import RobotLimits  # noqa: E402


def main() -> None:
    output = Path(sys.argv[1]) if len(sys.argv) > 1 else Path("follow_path.png")
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

    fig, ax = plt.subplots(figsize=(9, 4))
    ax.plot(path[:, 0], path[:, 1], "o-", color="grey", markersize=3, label="path")
    ax.plot(trace[:, 0], trace[:, 1], "-", label="robot")
    ax.set_aspect("equal")
    ax.legend()
    fig.savefig(output, dpi=80)
    print("picture:", output)


if __name__ == "__main__":
    main()

"""SimplePlanner's algorithm on the shipped house: danger levels, raw and smoothed paths.

python packages/easynav-planners/examples/plan_in_house.py [output.png]
"""

from __future__ import annotations

import sys
import time
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
from matplotlib.colors import ListedColormap  # noqa: E402

from easynav.maps import SimpleMap, resolve_map_file  # noqa: E402
from easynav.planners import SimpleGridPlanner  # noqa: E402


def main() -> None:
    output = Path(sys.argv[1]) if len(sys.argv) > 1 else Path("plan_in_house.png")
    home = SimpleMap.load(resolve_map_file("easynav_maps", "worlds/home.map"))
    start = (0.0, 0.0)
    goals = [(10.0, 2.0, 0.0), (1.0, 6.5, 1.57), (8.5, 6.0, 3.14), (11.0, 7.0, 0.0)]

    raw = SimpleGridPlanner(smooth=False)
    smooth = SimpleGridPlanner(smooth=True)
    coarse = smooth.coarse_map(home)
    levels = smooth.danger_levels(coarse)

    fig, ax = plt.subplots(figsize=(10, 7))
    x0, y0, x1, y1 = coarse.extent
    colours = ListedColormap(["white", "#cfe3ff", "#ffd0a0", "#404040"])
    ax.imshow(levels, origin="lower", extent=(x0, x1, y0, y1), cmap=colours, vmin=0, vmax=3)
    ax.plot(*start, "bs", label="start")
    for goal in goals:
        t = time.perf_counter()
        result = smooth.plan(home, start, goal)
        ms = (time.perf_counter() - t) * 1e3
        if not result.ok:
            print(f"goal {goal[:2]}: no path: {result.reason}")
            ax.plot(goal[0], goal[1], "rx", markersize=12)
            continue
        straight = raw.plan(home, start, goal)
        print(
            f"goal {goal[:2]}: {result.length:.2f} m smoothed, {straight.length:.2f} m raw "
            f"8-connected, {len(result.poses)} poses, {ms:.1f} ms"
        )
        ax.plot(straight.poses[:, 0], straight.poses[:, 1], ":", color="grey")
        ax.plot(result.poses[:, 0], result.poses[:, 1], "-", linewidth=2)
        ax.plot(goal[0], goal[1], "go")
    ax.set_title("danger levels: free / clearance / collision / obstacle")
    ax.legend(loc="upper right")
    fig.savefig(output, dpi=80)
    print("picture:", output)


if __name__ == "__main__":
    main()

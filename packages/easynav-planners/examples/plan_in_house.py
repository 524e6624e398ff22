"""SimplePlanner's algorithm on the shipped house: danger levels, raw and smoothed paths.

    python packages/easynav-planners/examples/plan_in_house.py [--plot output.png]

SimpleGridPlanner (the search inside the SimplePlanner plugin) plans from (0, 0) to four goals
of the house shipped with easynav-maps and prints the smoothed and raw lengths; ``--plot``
(with matplotlib) draws the danger levels and the paths.
"""

from __future__ import annotations

import argparse
import time

from easynav.maps import SimpleMap, resolve_map_file
from easynav.planners import SimpleGridPlanner


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--plot", metavar="PNG", help="draw levels and paths (matplotlib)")
    args = parser.parse_args()
    home = SimpleMap.load(resolve_map_file("easynav_maps", "worlds/home.map"))
    start = (0.0, 0.0)
    goals = [(10.0, 2.0, 0.0), (1.0, 6.5, 1.57), (8.5, 6.0, 3.14), (11.0, 7.0, 0.0)]

    raw = SimpleGridPlanner(smooth=False)
    smooth = SimpleGridPlanner(smooth=True)
    drawn = []  # (goal, smoothed path or None, raw path)
    for goal in goals:
        t = time.perf_counter()
        result = smooth.plan(home, start, goal)
        ms = (time.perf_counter() - t) * 1e3
        if not result.ok:
            print(f"goal {goal[:2]}: no path: {result.reason}")
            drawn.append((goal, None, None))
            continue
        straight = raw.plan(home, start, goal)
        print(
            f"goal {goal[:2]}: {result.length:.2f} m smoothed, {straight.length:.2f} m raw "
            f"8-connected, {len(result.poses)} poses, {ms:.1f} ms"
        )
        drawn.append((goal, result.poses, straight.poses))

    if not args.plot:
        return
    try:
        import matplotlib
    except ImportError:
        print("--plot: matplotlib is not installed")
        return
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.colors import ListedColormap

    coarse = smooth.coarse_map(home)
    levels = smooth.danger_levels(coarse)
    fig, ax = plt.subplots(figsize=(10, 7))
    x0, y0, x1, y1 = coarse.extent
    colours = ListedColormap(["white", "#cfe3ff", "#ffd0a0", "#404040"])
    ax.imshow(levels, origin="lower", extent=(x0, x1, y0, y1), cmap=colours, vmin=0, vmax=3)
    ax.plot(*start, "bs", label="start")
    for goal, poses, straight in drawn:
        if poses is None:
            ax.plot(goal[0], goal[1], "rx", markersize=12)
            continue
        ax.plot(straight[:, 0], straight[:, 1], ":", color="grey")
        ax.plot(poses[:, 0], poses[:, 1], "-", linewidth=2)
        ax.plot(goal[0], goal[1], "go")
    ax.set_title("danger levels: free / clearance / collision / obstacle")
    ax.legend(loc="upper right")
    fig.savefig(args.plot, dpi=80)
    print("picture:", args.plot)


if __name__ == "__main__":
    main()

"""SimpleMap in a few lines: load, query, downsample, convert, save, and draw.

    python packages/easynav-maps/examples/simple_map_example.py [--plot output.png]

Loads the house shipped with easynav-maps, marks a few "live" obstacles, downsamples to the
planner's 0.2 m, converts and saves; ``--plot`` (with matplotlib) draws them (and a Nav2 map
when /work/shared/maps is there).
"""

from __future__ import annotations

import argparse
import tempfile
from pathlib import Path

import numpy as np

from easynav.maps import SimpleMap, resolve_map_file


def draw(ax, world: SimpleMap, title: str) -> None:
    x0, y0, x1, y1 = world.extent
    ax.imshow(world.cells, origin="lower", extent=(x0, x1, y0, y1), cmap="Greys")
    ax.set_title(title)
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--plot", metavar="PNG", help="draw the maps (matplotlib)")
    args = parser.parse_args()
    home = SimpleMap.load(resolve_map_file("easynav_maps", "worlds/home.map"))
    print("loaded", home)
    print("is (0, 0) free?", not home.occupied_at(0.0, 0.0))

    live = home.copy()
    xs, ys = np.array([1.0, 1.05, 1.1]), np.array([1.5, 1.5, 1.5])
    print("marked", live.mark_occupied(xs, ys), "points as obstacles")

    coarse = live.downsample(0.2)
    print("downsampled", coarse)

    grid = coarse.to_occupancy_grid("map", 0.0)
    print("occupancy grid", grid.width, "x", grid.height, "values", np.unique(grid.data))

    with tempfile.TemporaryDirectory() as tmp:
        coarse.save(Path(tmp) / "coarse.map")
        assert SimpleMap.load(Path(tmp) / "coarse.map") == coarse
        print("saved and reloaded", Path(tmp) / "coarse.map")

    if not args.plot:
        return
    try:
        import matplotlib
    except ImportError:
        print("--plot: matplotlib is not installed")
        return
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    panels = [(live, "home.map + live obstacles"), (coarse, "downsampled to 0.2 m")]
    nav2 = Path("/work/shared/maps/tb3_sandbox.yaml")
    if nav2.is_file():
        panels.append((SimpleMap.load(nav2), "tb3_sandbox.yaml (unknown = occupied)"))
    fig, axes = plt.subplots(1, len(panels), figsize=(6 * len(panels), 5))
    for ax, (world, title) in zip(axes, panels, strict=True):
        draw(ax, world, title)
    fig.tight_layout()
    fig.savefig(args.plot, dpi=80)
    print("picture:", args.plot)


if __name__ == "__main__":
    main()

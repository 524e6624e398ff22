"""SimpleMap in a few lines: load, query, downsample, convert, save, and draw.

    python packages/easynav-maps/examples/simple_map_example.py [output.png]

Loads the house shipped with easynav-maps (and a Nav2 map when /work/shared/maps is there),
marks a few "live" obstacles, downsamples to the planner's 0.2 m and writes a picture.
"""

from __future__ import annotations

import sys
import tempfile
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from easynav.maps import SimpleMap, resolve_map_file  # noqa: E402


def draw(ax, world: SimpleMap, title: str) -> None:
    x0, y0, x1, y1 = world.extent
    ax.imshow(world.cells, origin="lower", extent=(x0, x1, y0, y1), cmap="Greys")
    ax.set_title(title)
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")


def main() -> None:
    output = Path(sys.argv[1]) if len(sys.argv) > 1 else Path("simple_map_example.png")
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

    panels = [(live, "home.map + live obstacles"), (coarse, "downsampled to 0.2 m")]
    nav2 = Path("/work/shared/maps/tb3_sandbox.yaml")
    if nav2.is_file():
        panels.append((SimpleMap.load(nav2), "tb3_sandbox.yaml (unknown = occupied)"))
    fig, axes = plt.subplots(1, len(panels), figsize=(6 * len(panels), 5))
    for ax, (world, title) in zip(axes, panels, strict=True):
        draw(ax, world, title)
    fig.tight_layout()
    fig.savefig(output, dpi=80)
    print("picture:", output)


if __name__ == "__main__":
    main()

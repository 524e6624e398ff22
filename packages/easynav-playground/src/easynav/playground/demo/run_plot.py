"""The picture of a demo run (matplotlib, Agg backend: no display needed)."""

from __future__ import annotations

import math
from collections.abc import Sequence
from pathlib import Path

import numpy as np

from easynav.playground.demo.waypoint_result import WaypointResult
from easynav.playground.sim.moving_obstacle import MovingObstacle
from easynav.playground.sim.multilevel import MultiLevelWorld
from easynav.playground.sim.terrain import Terrain
from easynav.playground.sim.world import World


def plot_run(
    path: str | Path,
    world: World,
    waypoints: Sequence[WaypointResult] = (),
    start_pose: tuple[float, float, float] | None = None,
    true_poses: Sequence[Sequence[float]] = (),
    estimated_poses: Sequence[Sequence[float]] = (),
    planned_paths: Sequence[np.ndarray] = (),
    collisions: Sequence[dict] = (),
    obstacles: Sequence[MovingObstacle] = (),
    title: str = "",
    progress_legend: bool = True,
    terrain: Terrain | None = None,
    levels: MultiLevelWorld | None = None,
) -> None:
    """Draw the world, moving-obstacle tracks, planned paths, the true and estimated
    trajectories, the waypoints (green reached, red not) and collisions; save as PNG. A world's
    ``terrain`` is drawn under them: heights in colour, contours every 0.2 m, and the ground
    steeper than the robot climbs hatched. A multi-level world's ``levels`` (``world`` is then
    its ground floor's map) are outlined over it: each higher floor's area and its height, each
    ramp hatched with an arrow up it.

    Any thread (matplotlib's object API with the Agg canvas, no global pyplot state).
    """
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    min_x, min_y, max_x, max_y = world.bounds
    aspect = (max_y - min_y) / (max_x - min_x)
    fig = Figure(figsize=(9, max(3.5, min(9 * aspect, 14)) + 0.6), dpi=100)
    FigureCanvasAgg(fig)
    ax = fig.add_subplot(1, 1, 1)
    ax.imshow(
        world.occupied,
        origin="lower",
        cmap="Greys",
        vmin=0,
        vmax=1.4,
        extent=(min_x, max_x, min_y, max_y),
        interpolation="nearest",
    )
    if terrain is not None:
        _draw_terrain(ax, terrain)
    if levels is not None:
        _draw_levels(ax, levels)
    for i, o in enumerate(obstacles):
        ax.plot(
            *o.waypoints.T,
            ls=":",
            color="purple",
            lw=2,
            label="moving obstacle track" if i == 0 else None,
        )
    for i, p in enumerate(planned_paths):
        ax.plot(
            p[:, 0],
            p[:, 1],
            color="tab:blue",
            lw=0.8,
            alpha=0.35,
            label="planned paths" if i == 0 else None,
        )
    if len(true_poses):
        t = np.asarray(true_poses)
        ax.plot(t[:, 1], t[:, 2], color="black", lw=1.6, label="true trajectory")
    if len(estimated_poses):
        e = np.asarray(estimated_poses)
        ax.plot(e[:, 1], e[:, 2], color="tab:orange", lw=1.2, ls="--", label="EasyNav estimate")
    if start_pose is not None:
        ax.plot(*start_pose[:2], marker="s", color="tab:blue", ms=9, ls="none", label="start")
    for w in waypoints:
        color = "tab:green" if w.achieved else "tab:red"
        ax.plot(w.x, w.y, marker="o", ms=13, color=color, mec="black", ls="none")
        ax.annotate(
            str(w.index),
            (w.x, w.y),
            ha="center",
            va="center",
            fontsize=8,
            color="white",
            weight="bold",
        )
        ax.arrow(w.x, w.y, 0.4 * math.cos(w.yaw), 0.4 * math.sin(w.yaw), width=0.03, color=color)
    for i, c in enumerate(collisions):
        ax.plot(
            c["x"],
            c["y"],
            marker="X",
            ms=14,
            color="red",
            mec="black",
            ls="none",
            label="collision" if i == 0 else None,
        )
    if progress_legend:
        ax.plot([], [], marker="o", color="tab:green", ls="none", label="waypoint reached")
        ax.plot([], [], marker="o", color="tab:red", ls="none", label="waypoint not reached")
    elif waypoints:
        ax.plot([], [], marker="o", color="tab:green", ls="none", label="demo waypoint")
    ax.set_xlim(min_x, max_x)
    ax.set_ylim(min_y, max_y)
    ax.set_aspect("equal")
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    if title:
        ax.set_title(title, fontsize=10)
    ax.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize=8)
    fig.savefig(str(path), bbox_inches="tight")


_LABEL_BOX = {"fc": "white", "alpha": 0.8, "lw": 0, "pad": 1}


def _draw_levels(ax, levels: MultiLevelWorld) -> None:
    """Outline the higher floors and the ramps of a multi-level world on ``ax``."""
    from matplotlib.patches import Rectangle

    base = min(f.z for f in levels.floors)
    for i, f in enumerate(f for f in levels.floors if f.z > base):
        x0, y0, x1, y1 = f.area
        ax.add_patch(Rectangle((x0, y0), x1 - x0, y1 - y0, fill=False, ec="tab:purple", lw=2,
                               ls="--", label="upper floor" if i == 0 else None))
        ax.annotate(f"{f.name} ({f.z:g} m)", (0.5 * (x0 + x1), y0), ha="center", va="bottom",
                    fontsize=8, color="tab:purple", bbox=_LABEL_BOX)
    for i, r in enumerate(levels.ramps):
        x0, y0, x1, y1 = r.area
        ax.add_patch(Rectangle((x0, y0), x1 - x0, y1 - y0, fill=False, ec="tab:brown",
                               hatch="//", lw=1.2,
                               label="ramp (arrow: up)" if i == 0 else None))
        mid = 0.5 * (y0 + y1) if r.axis == 0 else 0.5 * (x0 + x1)
        (fx, fy), (tx, ty) = (((r.foot, mid), (r.top, mid)) if r.axis == 0
                              else ((mid, r.foot), (mid, r.top)))
        ax.annotate("", (tx, ty), (fx, fy),
                    arrowprops={"arrowstyle": "->", "color": "tab:brown", "lw": 1.5})
        ax.annotate(f"{r.name} {math.degrees(r.slope):.1f} deg", (0.5 * (fx + tx), mid
                    if r.axis == 0 else 0.5 * (fy + ty)), ha="center", va="bottom",
                    fontsize=8, color="tab:brown", bbox=_LABEL_BOX)


def _draw_terrain(ax, terrain: Terrain) -> None:
    """Heights, contours and the too-steep ground of ``terrain`` on ``ax``."""
    from easynav.maps.gridmap.grid_map import slope_layer

    z = terrain.elevation
    h, w = z.shape
    r = terrain.resolution
    extent = (terrain.origin_x, terrain.origin_x + w * r, terrain.origin_y,
              terrain.origin_y + h * r)
    ax.imshow(z, origin="lower", cmap="YlOrBr", alpha=0.55, extent=extent,
              interpolation="nearest", vmin=0.0, vmax=max(float(z.max()), 1e-6) * 1.2)
    xs = terrain.origin_x + (np.arange(w) + 0.5) * r
    ys = terrain.origin_y + (np.arange(h) + 0.5) * r
    top = float(z.max())
    if top > float(z.min()):
        levels = np.arange(math.floor(float(z.min()) / 0.2) * 0.2 + 0.2, top, 0.2)
        if len(levels):
            ax.contour(xs, ys, z, levels=levels, colors="saddlebrown", linewidths=0.4,
                       alpha=0.7)
    steep = (slope_layer(z, r) > terrain.max_climb_slope).astype(float)
    if steep.any():
        ax.contourf(xs, ys, steep, levels=[0.5, 1.5], colors="none", hatches=["////"])
        ax.contour(xs, ys, steep, levels=[0.5], colors="firebrick", linewidths=0.6)
        ax.plot([], [], color="firebrick", lw=0.6,
                label=f"steeper than {terrain.max_climb_slope_deg:g} deg (cannot climb)")


def plot_world(world_spec: str, path: str | Path) -> None:
    """Draw a world with its start pose, default waypoints and obstacle tracks (no run)."""
    from easynav.playground.world_description import WorldDescription, load_waypoints

    description = WorldDescription.resolve(world_spec)
    waypoints = []
    if description.waypoints_path is not None:
        waypoints = [
            WaypointResult(i, *w)
            for i, w in enumerate(load_waypoints(description.waypoints_path), 1)
        ]
    for w in waypoints:
        w.reached_at = 0.0  # drawn green: these are the demo's stops, not a failed run
    plot_run(
        path,
        description.world,
        waypoints,
        description.start_pose,
        obstacles=description.make_obstacles(),
        title=f"world '{description.world.name}': start, demo waypoints, moving obstacle tracks",
        progress_legend=False,
        terrain=description.make_terrain(),
        levels=description.make_levels(),
    )

"""``python -m easynav.playground.world_picture WORLD OUTPUT.png``: draw a world (for docs)."""

import sys

from easynav.playground.demo.run_plot import plot_world

if __name__ == "__main__":
    if len(sys.argv) != 3:
        sys.exit("usage: python -m easynav.playground.world_picture WORLD OUTPUT.png")
    plot_world(sys.argv[1], sys.argv[2])

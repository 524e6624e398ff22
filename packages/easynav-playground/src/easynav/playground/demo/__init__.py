"""The playground demo: ``run_demo(...)`` and the ``easynav demo`` entry point ``main(argv)``."""

from easynav.playground.demo.demo import build_parser, main, run_demo

__all__ = ["build_parser", "main", "run_demo"]

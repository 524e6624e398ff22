"""The rclpy executor EasyNav's processes spin: the EventsExecutor where this rclpy has it."""

from __future__ import annotations

import os

import rclpy
from rclpy.executors import SingleThreadedExecutor

#: ``EASYNAV_EXECUTOR=single``: rclpy's SingleThreadedExecutor instead of its EventsExecutor.
EXECUTOR_ENV = "EASYNAV_EXECUTOR"


def make_executor(context: rclpy.Context | None = None):
    """An executor for one thread's nodes (each loop of ``easynav run``, the playground's
    simulator, its demo's monitor): rclpy's EventsExecutor (``rclpy.experimental``, C++), else
    its SingleThreadedExecutor (an rclpy without it, or ``EASYNAV_EXECUTOR=single``).
    ``context``: the rclpy context of the nodes (None: the default one).

    Why (issue #21): the SingleThreadedExecutor builds a new wait set in Python at every
    ``spin_once`` (every entity of every node: 72 services and 16-41 QoS event handlers for the
    non-RT loop's six lifecycle nodes), 0.3-1 ms each, and the loops call it at least once per
    cycle (200 Hz each): measured with ``easynav demo`` (home, simple stack) on an idle machine,
    ``easynav run`` 37 % of a core with it, 14 % with the EventsExecutor, which keeps its
    entities between calls and is woken by the middleware's events. Same loops, same rates,
    same callbacks in the same threads; the RT loop's timing (bench_rt_loop.py) meets its goal
    with both.

    With the EventsExecutor (rclpy 7.1), shut it down before destroying any entity it serves
    from another thread: it sets a callback on every entity, and when an entity was destroyed
    under it (a lifecycle shutdown in the main thread while a loop spins) its bookkeeping
    breaks ("Couldn't find sub-entities entry for removed Waitable") and, freed with callbacks
    left, it aborts the process ("Destroying callback manager with callbacks remaining").
    ``shutdown()`` clears every callback at once, the entities still alive.
    """
    if os.environ.get(EXECUTOR_ENV, "").strip().lower() != "single":
        try:
            from rclpy.experimental import EventsExecutor
        except ImportError:
            pass
        else:
            return EventsExecutor(context=context)
    return SingleThreadedExecutor(context=context)

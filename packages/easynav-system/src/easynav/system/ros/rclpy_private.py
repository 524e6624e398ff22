"""The one place EasyNav reaches into rclpy's private attributes.

rclpy (Jazzy, 7.x) has no public API for what these functions do; each says why and what it
touches, so an rclpy upgrade is checked here and nowhere else. Everything else in EasyNav uses
rclpy's public API (``has_parameter``, ``get_parameter_or``, ``list_parameters``,
``declare_parameter``, ``set_parameters``...).
"""

from __future__ import annotations

import threading
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from typing import Any

from rclpy.lifecycle import LifecycleNode
from rclpy.node import Node
from rclpy.parameter import Parameter
from rclpy.time_source import TimeSource


def parameter_override(node: Node, name: str) -> Parameter | None:
    """The value given to ``name`` before it is declared (params file, ``-p``, the node's
    ``parameter_overrides`` argument), or None.

    Why private: rclpy reads a node's overrides once, in ``Node.__init__``, into
    ``Node._parameter_overrides`` (by full parameter name) and hands them out only through
    ``declare_parameter``; it has no counterpart of rclcpp's ``get_parameter_overrides()``.
    EasyNav needs them before declaring (an empty YAML list, an integer for a double, whether
    the user set a value) and for parameters it does not declare (the ``*_types`` lists).
    """
    return node._parameter_overrides.get(name)


def set_parameter_override(node: Node, name: str, value: Any) -> None:
    """Make ``value`` the override of ``name``, a parameter the node has not declared (yet):
    its next declaration (the next configure) takes it, as it would a params file's value.

    Why private: rclpy's overrides can only be given to the node's constructor (see
    :func:`parameter_override`); ``set_parameters`` refuses undeclared parameters. The runtime
    reconfiguration changes such parameters (e.g. ``<alias>.plugin``, read at configure).
    """
    node._parameter_overrides[name] = Parameter(name, value=value)


def lifecycle_state_label(node: LifecycleNode) -> str:
    """The label of ``node``'s current lifecycle state (unconfigured, inactive, active,
    finalized...).

    Why private: rclpy's ``LifecycleNode`` keeps its state machine in ``_state_machine`` and
    exposes the current state only through its ``~/get_state`` service, not through a method.
    """
    return node._state_machine.current_state[1]


#: Threads in :func:`clock_subscriptions_deferred`, and rclpy's own subscribing method.
_deferring_threads: set[int] = set()
_rclpy_subscribe_to_clock_topic = TimeSource._subscribe_to_clock_topic


def _subscribe_unless_deferred(source: TimeSource) -> None:
    if threading.get_ident() in _deferring_threads:
        return  # left to take_over_clock_subscription's caller
    _rclpy_subscribe_to_clock_topic(source)


@contextmanager
def clock_subscriptions_deferred() -> Iterator[None]:
    """Nodes constructed in this block by this thread do not subscribe to ``/clock`` (on
    ``use_sim_time``): :func:`take_over_clock_subscription` then has none to destroy.

    Why: a participant whose eight ``/clock`` subscriptions were created and destroyed at once
    (each node's own, replaced by the shared one) was missing, for another participant, every
    subscription it had afterwards (``/clock``, ``tf``...) for as long as it was watched:
    measured with rclpy alone (Fast DDS 2.14, two participants in one process), 4 starts in
    100 with the churn, 0 in 150 without it. A system started that way never received the
    simulator's clock or transforms.

    Why private: rclpy subscribes in ``Node.__init__`` (``TimeSource._subscribe_to_clock_topic``,
    run when ``use_sim_time`` is true), before any caller could intervene. That method is
    replaced once, for good, by one that defers only for the threads inside this block; every
    other thread's nodes subscribe as rclpy does. Thread contract: any thread; the block
    affects the calling thread only.
    """
    TimeSource._subscribe_to_clock_topic = _subscribe_unless_deferred
    ident = threading.get_ident()
    _deferring_threads.add(ident)
    try:
        yield
    finally:
        _deferring_threads.discard(ident)


def take_over_clock_subscription(node: Node, subscribe: Callable[[], None]) -> TimeSource:
    """Remove ``node``'s own ``/clock`` subscription and make its time source call
    ``subscribe`` wherever it would subscribe again (``use_sim_time`` set to true later);
    returns the time source, whose public ``ros_time_is_active`` and ``clock_callback`` the
    caller uses to feed it (see :class:`~easynav.system.shared_clock.SharedClockSubscription`).

    Why private: rclpy creates one ``TimeSource`` per node (``Node._time_source``) and each one
    subscribes to ``/clock`` by itself (``TimeSource._clock_sub``, created by
    ``_subscribe_to_clock_topic``); no public API lets several nodes share one subscription.
    """
    source = node._time_source
    if source._clock_sub is not None:
        node.destroy_subscription(source._clock_sub)
        source._clock_sub = None
    source._subscribe_to_clock_topic = subscribe
    return source

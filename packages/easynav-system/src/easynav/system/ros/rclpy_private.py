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


#: How deep the calling thread is in :func:`clock_subscriptions_deferred` blocks.
_deferral = threading.local()
_rclpy_subscribe_to_clock_topic = TimeSource._subscribe_to_clock_topic


def _subscribe_unless_deferred(source: TimeSource) -> None:
    if getattr(_deferral, "depth", 0) > 0:
        return  # left to take_over_clock_subscription's caller
    _rclpy_subscribe_to_clock_topic(source)


# Installed once, when EasyNav's system is imported: it defers only inside the blocks below,
# and every other call goes to rclpy's own method.
TimeSource._subscribe_to_clock_topic = _subscribe_unless_deferred


@contextmanager
def clock_subscriptions_deferred() -> Iterator[None]:
    """Nodes constructed in this block by this thread do not subscribe to ``/clock`` (on
    ``use_sim_time``): :func:`take_over_clock_subscription` then has none to destroy. Each such
    node must be taken over: on simulated time it has no subscription of its own, and its
    clock would stay at zero. Blocks nest.

    Why: it works around a discovery fault whose cause is not known (Fast DDS 2.14 under rclpy):
    a participant whose eight ``/clock`` subscriptions were created and destroyed at once (each
    node's own, replaced by the shared one) was missing, for another participant, every
    subscription it had afterwards (``/clock``, ``tf``...) for as long as it was watched.
    Measured with rclpy alone, two participants in one process: 9 starts in 250 with the churn,
    0 in 300 without it. A system started that way never received the simulator's clock or
    transforms. Other creations and destructions at a participant's start may trigger it too.

    Why private: rclpy subscribes in ``Node.__init__`` (``TimeSource._subscribe_to_clock_topic``,
    run when ``use_sim_time`` is true), before any caller could intervene; that method is
    replaced (see above). Thread contract: any thread; a block affects the calling thread only.
    """
    _deferral.depth = getattr(_deferral, "depth", 0) + 1
    try:
        yield
    finally:
        _deferral.depth -= 1


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

"""SharedClockSubscription: one /clock subscription for all of EasyNav's nodes in a process."""

from __future__ import annotations

import rosgraph_msgs.msg
from rclpy.node import Node
from rclpy.qos import QoSProfile, ReliabilityPolicy
from rclpy.time_source import CLOCK_TOPIC, TimeSource

from easynav.system.ros.rclpy_private import take_over_clock_subscription


class SharedClockSubscription:
    """Feeds the clocks of several nodes on simulated time from a single ``/clock`` subscription.

    rclpy gives every node its own ``TimeSource``, and each one on ``use_sim_time`` subscribes to
    ``/clock``: EasyNav's eight nodes took eight copies of every clock message (200 Hz from the
    playground), and each copy woke an executor that rebuilds its wait set in Python (0.5-1 ms
    for the non-RT executor's six lifecycle nodes). Measured: most of the non-RT loop's CPU
    (issue #21). Here the nodes' time sources keep their role (``use_sim_time`` read at start
    and changed at run time, each node's clock switched accordingly) but not their subscription:
    one subscription on ``host`` (its executor serves it) hands each message to every time
    source whose node is on simulated time, exactly as its own subscription did
    (``TimeSource.clock_callback``). The subscription is created when the first node is on
    simulated time (same QoS as rclpy's: depth 1, best effort). Nodes constructed inside
    ``clock_subscriptions_deferred()`` (SystemNode constructs its nodes so) never had their own;
    others have theirs destroyed here.

    Thread contract: construct before the executors spin (the nodes' constructors have run);
    the callback runs in the thread that spins ``host`` (sensors_node: the RT loop), which
    updates the clocks the other threads read (as sensors_node's clock already was). The
    subscription goes with ``host`` (``destroy_node``).
    """

    def __init__(self, host: Node, nodes: list[Node]) -> None:
        self._host = host
        self._sources: list[TimeSource] = []
        self.subscription = None
        for node in nodes:
            # A later use_sim_time=true subscribes the shared subscription, not the node's own.
            source = take_over_clock_subscription(node, self._subscribe)
            self._sources.append(source)
            if source.ros_time_is_active:
                self._subscribe()

    def _subscribe(self) -> None:
        if self.subscription is None:
            self.subscription = self._host.create_subscription(
                rosgraph_msgs.msg.Clock,
                CLOCK_TOPIC,
                self._on_clock,
                QoSProfile(depth=1, reliability=ReliabilityPolicy.BEST_EFFORT),
            )

    def _on_clock(self, msg: rosgraph_msgs.msg.Clock) -> None:
        for source in self._sources:
            if source.ros_time_is_active:
                source.clock_callback(msg)

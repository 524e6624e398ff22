"""FusedCloudPublisher: sensors_node's ``~/perceptions``, the fused cloud the navigation sees."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from easynav.system.sensors.converters.point_cloud2 import point_cloud2_from_points

PERCEPTIONS_TOPIC = "~/perceptions"


class FusedCloudPublisher:
    """Publishes the fused point cloud (for RViz and tools) only while someone subscribes and
    only when the point perceptions changed: fusing costs a transform of every point, too much
    to spend every non-RT cycle for nobody.

    The RT thread calls :meth:`points_changed` when a point perception is stored fresh or
    expires; the version it bumps is compared with the one last published.

    Thread contract: :meth:`create` and :meth:`destroy` in the configuring thread with no loop
    running; :meth:`points_changed` in the RT thread (under the manager's lock); :meth:`publish`
    in the non-RT thread. Exceptions: :meth:`create` raises what ``node.create_publisher``
    raises; :meth:`publish` what the ``fuse`` callable raises; the others do not raise.
    """

    def __init__(self) -> None:
        self._publisher: Any = None
        self._version = 0
        self._published_version = -1

    def create(self, node: Any) -> None:
        """Create the publisher on ``node`` (reliable, depth 1). Configuring thread."""
        self._publisher = node.create_publisher(
            _point_cloud2_class(), PERCEPTIONS_TOPIC, _reliable_qos(1)
        )

    def destroy(self, node: Any) -> None:
        """Destroy the publisher (``node`` None: nothing to destroy). Configuring thread."""
        if self._publisher is not None and node is not None:
            node.destroy_publisher(self._publisher)
        self._publisher = None
        self._published_version = -1

    def points_changed(self) -> None:
        """A point perception was stored or expired. RT thread, the manager's lock held."""
        self._version += 1

    def publish(self, fuse: Callable[[], tuple[Any, str, float | None]]) -> None:
        """Publish ``fuse()`` (``(points, frame, stamp)``) when subscribed and the points changed
        since the last publication. Non-RT thread."""
        publisher = self._publisher
        if publisher is None or publisher.get_subscription_count() == 0:
            self._published_version = -1  # a new subscriber gets a cloud at once
            return
        version = self._version
        if version == self._published_version:
            return
        points, frame, stamp = fuse()
        publisher.publish(point_cloud2_from_points(points, frame, stamp or 0.0))
        self._published_version = version


def _reliable_qos(depth: int) -> Any:
    from rclpy.qos import QoSProfile, ReliabilityPolicy

    return QoSProfile(depth=depth, reliability=ReliabilityPolicy.RELIABLE)


def _point_cloud2_class() -> type:
    from sensor_msgs.msg import PointCloud2

    return PointCloud2

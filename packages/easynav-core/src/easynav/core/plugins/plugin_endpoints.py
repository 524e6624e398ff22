"""PluginEndpoints: the publishers, subscriptions and services a plugin made on its node.

A plugin hosted by a node makes its ROS endpoints under ``<node fqn>/<alias>/`` when it is
configured and must destroy each of them on cleanup (a reconfiguration makes them again). Kept
by name in one object, they are made in a line each and destroyed together, in one place.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any


def latched_qos(depth: int = 1) -> Any:
    """Reliable, transient-local QoS: a late subscriber still gets the last ``depth`` messages
    (what the original's map topics use)."""
    from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy

    return QoSProfile(depth=depth, reliability=ReliabilityPolicy.RELIABLE,
                      durability=DurabilityPolicy.TRANSIENT_LOCAL)


class PluginEndpoints:
    """Named ROS endpoints of one plugin on one node, under ``<node fqn>/<alias>/<topic>``.

    ``PluginEndpoints()`` (no node) holds nothing: :meth:`get` answers None, :meth:`destroy`
    does nothing, so a plugin outside ROS uses the same code.
    Thread contract: make and destroy from the configuring thread; :meth:`get` from any thread
    (a dict read).
    """

    def __init__(self, node: Any = None, alias: str = "") -> None:
        self._node = node
        self._base = "" if node is None else (
            f"{node.get_fully_qualified_name().rstrip('/')}/{alias}"
        )
        self._entities: dict[str, tuple[str, Any]] = {}

    def topic(self, name: str) -> str:
        """The full name of the plugin's topic or service ``name``."""
        return f"{self._base}/{name}"

    def publisher(self, name: str, msg_type: Any, qos: Any, topic: str | None = None) -> Any:
        """A publisher on ``topic`` (default ``name``), kept as ``name``."""
        entity = self._node.create_publisher(msg_type, self.topic(topic or name), qos)
        return self._keep(name, "publisher", entity)

    def subscription(self, name: str, msg_type: Any, callback: Callable[[Any], None], qos: Any,
                     topic: str | None = None) -> Any:
        """A subscription to ``topic`` (default ``name``), kept as ``name``."""
        entity = self._node.create_subscription(msg_type, self.topic(topic or name), callback,
                                                qos)
        return self._keep(name, "subscription", entity)

    def service(self, name: str, srv_type: Any, callback: Callable[[Any, Any], Any],
                topic: str | None = None) -> Any:
        """A service server at ``topic`` (default ``name``), kept as ``name``."""
        entity = self._node.create_service(srv_type, self.topic(topic or name), callback)
        return self._keep(name, "service", entity)

    def __len__(self) -> int:
        """How many endpoints are kept (0 after :meth:`destroy`)."""
        return len(self._entities)

    def get(self, name: str) -> Any:
        """The endpoint kept as ``name``, or None."""
        kept = self._entities.get(name)
        return None if kept is None else kept[1]

    def destroy(self) -> None:
        """Destroy every endpoint on its node; the object then holds nothing."""
        entities, self._entities = self._entities, {}
        node = self._node
        if node is None:
            return
        for kind, entity in entities.values():
            getattr(node, f"destroy_{kind}")(entity)

    def _keep(self, name: str, kind: str, entity: Any) -> Any:
        if name in self._entities:
            raise ValueError(f"endpoint {name!r} made twice")
        self._entities[name] = (kind, entity)
        return entity

"""PluginEndpoints: a plugin's endpoints under <node>/<alias>/, made by name, destroyed together."""

from __future__ import annotations

import pytest

from easynav.core.plugins.plugin_endpoints import PluginEndpoints


class FakeNode:
    """Records what is made and destroyed, as rclpy's Node API names it."""

    def __init__(self) -> None:
        self.made, self.destroyed = [], []

    def get_fully_qualified_name(self) -> str:
        return "/robot/maps_manager_node"

    def create_publisher(self, msg_type, topic, qos):
        self.made.append(("publisher", topic))
        return ("publisher", topic)

    def create_subscription(self, msg_type, topic, callback, qos):
        self.made.append(("subscription", topic))
        return ("subscription", topic)

    def create_service(self, srv_type, topic, callback):
        self.made.append(("service", topic))
        return ("service", topic)

    def destroy_publisher(self, entity):
        self.destroyed.append(entity)

    def destroy_subscription(self, entity):
        self.destroyed.append(entity)

    def destroy_service(self, entity):
        self.destroyed.append(entity)


def test_endpoints_are_named_under_the_plugin_and_destroyed_by_kind():
    node = FakeNode()
    ros = PluginEndpoints(node, "costmap")
    ros.publisher("cloud", object, 1, topic="map")
    ros.subscription("incoming_map", object, print, 1)
    ros.service("savemap", object, print)
    assert node.made == [
        ("publisher", "/robot/maps_manager_node/costmap/map"),
        ("subscription", "/robot/maps_manager_node/costmap/incoming_map"),
        ("service", "/robot/maps_manager_node/costmap/savemap"),
    ]
    assert ros.get("cloud") == ("publisher", "/robot/maps_manager_node/costmap/map")
    assert len(ros) == 3
    ros.destroy()
    assert sorted(node.destroyed) == sorted(node.made)
    assert len(ros) == 0 and ros.get("cloud") is None


def test_without_a_node_nothing_is_kept_and_destroy_does_nothing():
    ros = PluginEndpoints()
    assert ros.get("map") is None
    ros.destroy()
    assert len(ros) == 0


def test_a_name_made_twice_is_an_error_naming_it():
    ros = PluginEndpoints(FakeNode(), "simple")
    ros.publisher("map", object, 1)
    with pytest.raises(ValueError, match="'map' made twice"):
        ros.publisher("map", object, 1)

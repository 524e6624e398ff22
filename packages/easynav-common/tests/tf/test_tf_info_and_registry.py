"""TFInfo (frame names, multi-robot prefixes) and the process-wide buffers."""

from __future__ import annotations

import dataclasses

import pytest

from easynav.common.tf import (
    TFInfo,
    get_tf_buffer,
    reset_tf_buffers,
    set_default_tf_namespace,
)


@pytest.fixture(autouse=True)
def fresh_registry():
    reset_tf_buffers()
    yield
    reset_tf_buffers()


def test_defaults_are_the_reference_frames():
    info = TFInfo()
    assert (info.map_frame, info.odom_frame, info.robot_frame) == ("map", "odom", "base_link")
    assert (info.robot_footprint_frame, info.world_frame, info.tf_prefix) == (
        "base_footprint",
        "earth",
        "",
    )


def test_prefix_is_prepended_to_every_frame():
    info = TFInfo.from_parameters(tf_prefix="r1", robot_frame="chassis")
    assert info.map_frame == "r1/map"
    assert info.odom_frame == "r1/odom"
    assert info.robot_frame == "r1/chassis"
    assert info.robot_footprint_frame == "r1/base_footprint"
    assert info.world_frame == "r1/earth"
    assert info.tf_prefix == "r1"


def test_prefix_is_applied_once_even_when_copied():
    info = TFInfo.from_parameters(tf_prefix="/r2/")
    again = dataclasses.replace(info, odom_frame="r2/odom")
    assert info.map_frame == "r2/map" and again.odom_frame == "r2/odom"
    assert TFInfo(map_frame="r2/map", tf_prefix="r2").map_frame == "r2/map"


def test_empty_frame_name_is_an_error_naming_the_parameter():
    with pytest.raises(ValueError, match="system_node.map_frame"):
        TFInfo.from_parameters(map_frame="")


def test_tf_info_is_immutable():
    with pytest.raises(dataclasses.FrozenInstanceError):
        TFInfo().map_frame = "x"  # type: ignore[misc]


def test_one_buffer_per_namespace_and_the_same_object_every_time():
    assert get_tf_buffer() is get_tf_buffer()
    assert get_tf_buffer("r1") is get_tf_buffer("/r1/")
    assert get_tf_buffer("r1") is not get_tf_buffer("r2")
    assert get_tf_buffer("") is get_tf_buffer()


def test_buffer_holds_tf_info_as_a_snapshot():
    buffer = get_tf_buffer()
    info = TFInfo.from_parameters(tf_prefix="r1")
    buffer.set_tf_info(info)
    assert buffer.get_tf_info() == info
    with pytest.raises(TypeError):
        buffer.set_tf_info({"map_frame": "map"})  # type: ignore[arg-type]


def test_default_buffer_follows_the_namespace_system_node_configured():
    """Plugins call get_tf_buffer() without a namespace; in a robot namespace they must still
    get the buffer system_node configured (and the listener fills)."""
    configured = get_tf_buffer("r1")
    configured.set_tf_info(TFInfo.from_parameters(tf_prefix="r1"))
    assert get_tf_buffer() is configured
    assert get_tf_buffer().get_tf_info().map_frame == "r1/map"


def test_default_namespace_can_be_set_explicitly():
    get_tf_buffer("r1").set_tf_info(TFInfo.from_parameters(tf_prefix="r1"))
    get_tf_buffer("r2").set_tf_info(TFInfo.from_parameters(tf_prefix="r2"))
    assert get_tf_buffer() is get_tf_buffer("")  # ambiguous: the root namespace
    set_default_tf_namespace("/r2")
    assert get_tf_buffer() is get_tf_buffer("r2")

"""Tests of the messages built by easynav-interfaces (run against the installed wheel).

Message types, constants and fields; the installed ROS layout (ament index, type
hashes of the upstream definitions); and real rclpy topics in one process, with
DDS discovery limited to this process (ROS_AUTOMATIC_DISCOVERY_RANGE=OFF).
"""

from __future__ import annotations

import json
import math
import sys
from pathlib import Path

import pytest

try:
    import tomllib
except ModuleNotFoundError:  # Python 3.10
    tomllib = pytest.importorskip("tomli")

PACKAGE_DIR = Path(__file__).resolve().parents[1]
TIMEOUT = 10.0  # s, for a message to arrive


# --------------------------------------------------------------------------- types


def test_navigation_control_constants_and_fields():
    from easynav_interfaces.msg import NavigationControl

    constants = [
        "REQUEST",
        "REJECT",
        "ACCEPT",
        "FEEDBACK",
        "FINISHED",
        "FAILED",
        "CANCEL",
        "CANCELLED",
        "ERROR",
        "PAUSE",
        "RESUME",
        "PAUSED",
        "RESUMED",
    ]
    assert [getattr(NavigationControl, name) for name in constants] == list(range(13))
    assert NavigationControl.get_fields_and_field_types() == {
        "type": "uint8",
        "header": "std_msgs/Header",
        "seq": "int64",
        "user_id": "string",
        "nav_current_user_id": "string",
        "goals": "nav_msgs/Goals",
        "status_message": "string",
        "current_pose": "geometry_msgs/PoseStamped",
        "navigation_time": "builtin_interfaces/Duration",
        "estimated_time_remaining": "builtin_interfaces/Duration",
        "distance_covered": "float",
        "distance_to_goal": "float",
    }
    # Field order is part of the wire format.
    assert list(NavigationControl.get_fields_and_field_types())[:3] == ["type", "header", "seq"]


def test_goal_manager_info_constants_and_fields():
    from easynav_interfaces.msg import GoalManagerInfo

    assert (GoalManagerInfo.IDLE, GoalManagerInfo.ACTIVE) == (0, 1)
    assert list(GoalManagerInfo.get_fields_and_field_types().items()) == [
        ("status", "uint8"),
        ("goals", "nav_msgs/Goals"),
        ("position_distance", "double"),
        ("angle_distance", "double"),
        ("position_tolerance", "double"),
        ("angle_tolerance", "double"),
    ]


def test_heartbeat_constants_and_fields():
    from easynav_interfaces.msg import Heartbeat

    assert (Heartbeat.RT_OK, Heartbeat.RT_LATE, Heartbeat.RT_ERROR) == (0, 1, 2)
    assert list(Heartbeat.get_fields_and_field_types().items()) == [
        ("header", "std_msgs/Header"),
        ("sequence", "uint64"),
        ("rt_status", "uint8"),
        ("late_cycles", "uint64"),
        ("safety_mode", "boolean"),
        ("configuration_hash", "string"),
    ]
    heartbeat = Heartbeat(sequence=2**64 - 1, late_cycles=2**64 - 1)
    assert heartbeat.sequence == 2**64 - 1


def test_safety_status_fields():
    from easynav_interfaces.msg import SafetyStatus

    assert list(SafetyStatus.get_fields_and_field_types().items()) == [
        ("header", "std_msgs/Header"),
        ("protective_stop", "boolean"),
        ("speed_limited", "boolean"),
        ("max_linear_vel", "double"),
        ("max_angular_vel", "double"),
        ("active_field", "string"),
        ("muting", "boolean"),
    ]
    status = SafetyStatus()
    assert not status.protective_stop and not status.speed_limited and not status.muting


def test_tf2_msgs():
    from tf2_msgs.msg import TF2Error, TFMessage

    assert TFMessage.get_fields_and_field_types() == {
        "transforms": "sequence<geometry_msgs/TransformStamped>"
    }
    assert [
        TF2Error.NO_ERROR,
        TF2Error.LOOKUP_ERROR,
        TF2Error.CONNECTIVITY_ERROR,
        TF2Error.EXTRAPOLATION_ERROR,
        TF2Error.INVALID_ARGUMENT_ERROR,
        TF2Error.TIMEOUT_ERROR,
        TF2Error.TRANSFORM_ERROR,
    ] == list(range(7))
    assert list(TF2Error.get_fields_and_field_types()) == ["error", "error_string"]


def test_vision_msgs():
    from vision_msgs.msg import (
        BoundingBox3D,
        Detection3D,
        Detection3DArray,
        ObjectHypothesis,
        ObjectHypothesisWithPose,
    )

    assert list(Detection3DArray.get_fields_and_field_types().items()) == [
        ("header", "std_msgs/Header"),
        ("detections", "sequence<vision_msgs/Detection3D>"),
    ]
    assert list(Detection3D.get_fields_and_field_types().items()) == [
        ("header", "std_msgs/Header"),
        ("results", "sequence<vision_msgs/ObjectHypothesisWithPose>"),
        ("bbox", "vision_msgs/BoundingBox3D"),
        ("id", "string"),
    ]
    assert list(ObjectHypothesisWithPose.get_fields_and_field_types().items()) == [
        ("hypothesis", "vision_msgs/ObjectHypothesis"),
        ("pose", "geometry_msgs/PoseWithCovariance"),
    ]
    assert list(ObjectHypothesis.get_fields_and_field_types().items()) == [
        ("class_id", "string"),
        ("score", "double"),
    ]
    assert list(BoundingBox3D.get_fields_and_field_types().items()) == [
        ("center", "geometry_msgs/Pose"),
        ("size", "geometry_msgs/Vector3"),
    ]


# ------------------------------------------------------------ installed ROS layout

# RIHS01 type hashes of the upstream ROS 2 Jazzy definitions (tf2_msgs 0.36,
# vision_msgs 4.1.1). DDS peers compare them: equal hashes mean these types
# interoperate with nodes built from the upstream packages.
UPSTREAM_TYPE_HASHES = {
    "tf2_msgs/msg/TF2Error": (
        "RIHS01_db2485e7d6a0ec75bf087e058ee45df682acc3a621ca7780503d10aac141809a"
    ),
    "tf2_msgs/msg/TFMessage": (
        "RIHS01_e369d0f05a23ae52508854b66f6aa0437f3449d652e8cbf22d5abe85d020f087"
    ),
    "vision_msgs/msg/BoundingBox3D": (
        "RIHS01_bbb73a65c163d7f9bb29009c7bde9f7faa576bd2d23299c4511d19230dab4698"
    ),
    "vision_msgs/msg/Detection3D": (
        "RIHS01_ddd703be132ab0b69d33121f1bb034132bfbb3b0ac5f9fb1516005ba1c8a265b"
    ),
    "vision_msgs/msg/Detection3DArray": (
        "RIHS01_793f5eab9595ac1c0da07873cc859db42eae51f0ee76056db8562515d830e018"
    ),
    "vision_msgs/msg/ObjectHypothesis": (
        "RIHS01_51da43cec11c01957a64d1e05a24acd18aae7745ec30b74348ad5f6d634f7f90"
    ),
    "vision_msgs/msg/ObjectHypothesisWithPose": (
        "RIHS01_41c12344c0396c48b81df12467c192d99b2a0eb1463c5c37194e4223251c80bc"
    ),
}


@pytest.fixture
def ament_index(monkeypatch):
    """The ament index of this environment only (the ROS wheels set no AMENT_PREFIX_PATH)."""
    monkeypatch.setenv("AMENT_PREFIX_PATH", sys.prefix)


INTERFACES = {
    "easynav_interfaces": ["GoalManagerInfo", "Heartbeat", "NavigationControl", "SafetyStatus"],
    "tf2_msgs": ["TF2Error", "TFMessage"],
    "vision_msgs": [
        "BoundingBox3D",
        "Detection3D",
        "Detection3DArray",
        "ObjectHypothesis",
        "ObjectHypothesisWithPose",
    ],
}


@pytest.mark.parametrize("package", sorted(INTERFACES))
def test_ament_index(ament_index, package):
    """What `ros2 interface list/show` and the type support loaders look up."""
    from ament_index_python.packages import get_package_share_directory, get_resource

    share = Path(get_package_share_directory(package))
    for name in INTERFACES[package]:
        assert (share / "msg" / f"{name}.msg").is_file()
        assert (share / "msg" / f"{name}.idl").is_file()
    content, _ = get_resource("rosidl_interfaces", package)
    listed = {line.split(";")[0] for line in content.splitlines() if line.endswith(".idl")}
    assert listed == {f"msg/{name}.idl" for name in INTERFACES[package]}


@pytest.mark.parametrize("type_name", sorted(UPSTREAM_TYPE_HASHES))
def test_type_hash_matches_upstream(ament_index, type_name):
    from ament_index_python.packages import get_package_share_directory

    package, _, name = type_name.split("/")
    description = Path(get_package_share_directory(package)) / "msg" / f"{name}.json"
    hashes = json.loads(description.read_text())["type_hashes"]
    assert hashes[0] == {"type_name": type_name, "hash_string": UPSTREAM_TYPE_HASHES[type_name]}


def test_easynav_msg_files_keep_the_spec_comments(ament_index):
    from ament_index_python.packages import get_package_share_directory

    share = Path(get_package_share_directory("easynav_interfaces")) / "msg"
    heartbeat = (share / "Heartbeat.msg").read_text()
    assert "uint64 sequence            # +1 per heartbeat: a gap means lost heartbeats" in heartbeat
    safety = (share / "SafetyStatus.msg").read_text()
    assert "float64 max_linear_vel   #   m/s, either direction (>= 0)" in safety


def test_no_second_metadata_directory():
    """The ament Python install writes *.egg-info dirs; the wheel must not ship them."""
    import easynav_interfaces
    import tf2_msgs
    import vision_msgs

    for module in (easynav_interfaces, tf2_msgs, vision_msgs):
        site_packages = Path(module.__file__).resolve().parents[1]
        assert not list(site_packages.glob(f"{module.__name__}-*.egg-info"))


def test_build_requirements_match_pyproject():
    pyproject = tomllib.loads((PACKAGE_DIR / "pyproject.toml").read_text())
    declared = set(pyproject["build-system"]["requires"])
    listed = {
        line.strip()
        for line in (PACKAGE_DIR / "tools" / "build_requirements.txt").read_text().splitlines()
        if line.strip() and not line.lstrip().startswith("#")
    }
    assert listed == declared


# ------------------------------------------------------------------ rclpy topics


@pytest.fixture(scope="module")
def ros():
    """A private rclpy context with one node and a SingleThreadedExecutor.

    Discovery is limited to this process, so other processes on the machine
    (other test runs) cannot cross-talk. Shut down in the safe order: the
    executor first, then the context.
    """
    with pytest.MonkeyPatch.context() as patch:
        patch.setenv("ROS_AUTOMATIC_DISCOVERY_RANGE", "OFF")
        import rclpy
        from rclpy.context import Context
        from rclpy.executors import SingleThreadedExecutor

        context = Context()
        rclpy.init(context=context)
        node = rclpy.create_node("easynav_interfaces_test", context=context)
        executor = SingleThreadedExecutor(context=context)
        executor.add_node(node)
        try:
            yield node, executor
        finally:
            executor.shutdown()
            node.destroy_node()
            rclpy.shutdown(context=context)


def spin_until(executor, predicate, timeout=TIMEOUT):
    import time

    deadline = time.monotonic() + timeout
    while not predicate():
        if time.monotonic() > deadline:
            raise AssertionError(f"nothing received within {timeout} s")
        executor.spin_once(timeout_sec=0.05)


def publish_until_received(node, executor, msg_type, topic, message, qos=10):
    """Publish (again every 0.1 s, until matched) and return what was received."""
    import time

    received = []
    subscription = node.create_subscription(msg_type, topic, received.append, qos)
    publisher = node.create_publisher(msg_type, topic, qos)
    try:
        deadline = time.monotonic() + TIMEOUT
        while not received:
            assert time.monotonic() < deadline, f"nothing received on {topic}"
            publisher.publish(message)
            end = time.monotonic() + 0.1
            while not received and time.monotonic() < end:
                executor.spin_once(timeout_sec=0.02)
        return received[0]
    finally:
        node.destroy_publisher(publisher)
        node.destroy_subscription(subscription)


@pytest.mark.ros
def test_navigation_control_over_a_topic(ros):
    from builtin_interfaces.msg import Duration
    from easynav_interfaces.msg import NavigationControl
    from geometry_msgs.msg import PoseStamped

    node, executor = ros
    sent = NavigationControl(
        type=NavigationControl.FEEDBACK,
        seq=42,
        user_id="easynav_system",
        nav_current_user_id="commander",
        status_message="navigating",
        navigation_time=Duration(sec=3, nanosec=500),
        estimated_time_remaining=Duration(sec=7),
        distance_covered=1.5,
        distance_to_goal=2.25,
    )
    sent.header.frame_id = "map"
    goal = PoseStamped()
    goal.header.frame_id = "map"
    goal.pose.position.x = 4.0
    goal.pose.orientation.z = math.sin(0.25)
    goal.pose.orientation.w = math.cos(0.25)
    sent.goals.header.frame_id = "map"
    sent.goals.goals = [goal]
    sent.current_pose.pose.position.y = -1.0

    received = publish_until_received(node, executor, NavigationControl, "easynav_control", sent)
    assert received == sent
    assert received.type == NavigationControl.FEEDBACK
    assert received.goals.goals[0].pose.position.x == 4.0
    assert received.distance_to_goal == pytest.approx(2.25)


@pytest.mark.ros
def test_heartbeat_over_a_topic(ros):
    from easynav_interfaces.msg import Heartbeat

    node, executor = ros
    sent = Heartbeat(
        sequence=123456789012,
        rt_status=Heartbeat.RT_LATE,
        late_cycles=3,
        safety_mode=True,
        configuration_hash="1c161c031f71" + "0" * 52,
    )
    sent.header.stamp.sec = 17
    received = publish_until_received(node, executor, Heartbeat, "easynav_heartbeat", sent)
    assert received == sent
    assert received.rt_status == Heartbeat.RT_LATE and received.safety_mode


@pytest.mark.ros
def test_safety_status_over_a_topic(ros):
    from easynav_interfaces.msg import SafetyStatus

    node, executor = ros
    sent = SafetyStatus(
        protective_stop=False,
        speed_limited=True,
        max_linear_vel=0.3,
        max_angular_vel=0.5,
        active_field="warning_field_2",
        muting=True,
    )
    received = publish_until_received(node, executor, SafetyStatus, "easynav_safety_status", sent)
    assert received == sent


@pytest.mark.ros
def test_latched_tf_static_reaches_a_late_subscriber(ros):
    from geometry_msgs.msg import TransformStamped
    from rclpy.qos import DurabilityPolicy, HistoryPolicy, QoSProfile, ReliabilityPolicy
    from tf2_msgs.msg import TFMessage

    node, executor = ros
    latched = QoSProfile(
        depth=1,
        history=HistoryPolicy.KEEP_LAST,
        reliability=ReliabilityPolicy.RELIABLE,
        durability=DurabilityPolicy.TRANSIENT_LOCAL,
    )
    transform = TransformStamped()
    transform.header.frame_id = "base_footprint"
    transform.child_frame_id = "laser"
    transform.transform.translation.x = 0.2
    transform.transform.rotation.w = 1.0
    sent = TFMessage(transforms=[transform])

    publisher = node.create_publisher(TFMessage, "/tf_static", latched)
    publisher.publish(sent)  # once, before anyone subscribes
    for _ in range(5):
        executor.spin_once(timeout_sec=0.02)

    received = []
    subscription = node.create_subscription(TFMessage, "/tf_static", received.append, latched)
    try:
        spin_until(executor, lambda: bool(received))
        assert received[0] == sent
        assert received[0].transforms[0].child_frame_id == "laser"
    finally:
        node.destroy_subscription(subscription)
        node.destroy_publisher(publisher)


def make_detections():
    from vision_msgs.msg import Detection3D, Detection3DArray, ObjectHypothesisWithPose

    array = Detection3DArray()
    array.header.frame_id = "base_footprint"
    array.header.stamp.sec = 5
    for index, (class_id, score) in enumerate((("person", 0.9), ("pallet", 0.6))):
        detection = Detection3D(id=f"track-{index}")
        detection.header = array.header
        hypothesis = ObjectHypothesisWithPose()
        hypothesis.hypothesis.class_id = class_id
        hypothesis.hypothesis.score = score
        hypothesis.pose.pose.position.x = 1.0 + index
        hypothesis.pose.pose.orientation.w = 1.0
        hypothesis.pose.covariance[0] = 0.01
        hypothesis.pose.covariance[35] = 0.5
        detection.results = [hypothesis]
        detection.bbox.center.position.x = 1.0 + index
        detection.bbox.center.orientation.w = 1.0
        detection.bbox.size.x, detection.bbox.size.y, detection.bbox.size.z = 0.5, 0.4, 1.8
        array.detections.append(detection)
    return array


def test_detection3d_array_serialization_round_trip():
    from rclpy.serialization import deserialize_message, serialize_message
    from vision_msgs.msg import Detection3DArray

    sent = make_detections()
    data = serialize_message(sent)
    assert deserialize_message(data, Detection3DArray) == sent


@pytest.mark.ros
def test_detection3d_array_over_a_topic(ros):
    from vision_msgs.msg import Detection3DArray

    node, executor = ros
    sent = make_detections()
    received = publish_until_received(node, executor, Detection3DArray, "detections_3d", sent)
    assert received == sent
    assert [d.results[0].hypothesis.class_id for d in received.detections] == ["person", "pallet"]
    assert received.detections[1].results[0].pose.covariance[35] == 0.5
    assert received.detections[0].bbox.size.z == pytest.approx(1.8)

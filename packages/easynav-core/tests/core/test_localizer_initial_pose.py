"""Every localizer accepts ``initialpose`` (PoseWithCovarianceStamped) to reset its pose, as in
the original EasyNav, through LocalizerMethodBase."""

from __future__ import annotations

import itertools
import math

import pytest

from easynav.core.nav_state import NavState
from easynav.core.plugins import DictParameters, LocalizerMethodBase, PluginContext
from easynav.core.types import Odometry

_namespaces = itertools.count()


class RecordingLocalizer(LocalizerMethodBase):
    """A localizer that only records the poses it is told to continue from."""

    def __init__(self) -> None:
        super().__init__()
        self.poses: list[Odometry] = []

    def update_rt(self, nav_state: NavState) -> None:
        pass

    def update(self, nav_state: NavState) -> None:
        pass

    def on_last_known_pose(self, pose: Odometry) -> None:
        self.poses.append(pose)


def initial_pose_msg(x=2.0, y=-1.0, yaw=0.5, frame="map", variance=0.04):
    from geometry_msgs.msg import PoseWithCovarianceStamped

    msg = PoseWithCovarianceStamped()
    msg.header.frame_id = frame
    msg.header.stamp.sec = 42
    msg.pose.pose.position.x, msg.pose.pose.position.y = x, y
    msg.pose.pose.orientation.z = math.sin(yaw / 2.0)
    msg.pose.pose.orientation.w = math.cos(yaw / 2.0)
    msg.pose.covariance[0] = msg.pose.covariance[7] = variance
    msg.pose.covariance[35] = 0.01
    return msg


def make_localizer() -> RecordingLocalizer:
    localizer = RecordingLocalizer()
    context = PluginContext(
        parameters=DictParameters(), namespace=f"initial_pose_test_{next(_namespaces)}"
    )
    localizer.initialize(context, "loc")
    return localizer


def test_a_map_frame_initial_pose_reaches_the_localizer_as_an_odometry():
    localizer = make_localizer()
    localizer.handle_initial_pose_msg(initial_pose_msg())
    (pose,) = localizer.poses  # by default, as a pose to continue from
    assert (pose.pose.x, pose.pose.y) == pytest.approx((2.0, -1.0))
    assert pose.pose.yaw == pytest.approx(0.5)
    assert pose.header.frame_id == "map" and pose.header.stamp == pytest.approx(42.0)
    assert pose.child_frame_id == "base_footprint"
    assert pose.pose_covariance[0, 0] == pytest.approx(0.04)
    assert pose.pose_covariance[5, 5] == pytest.approx(0.01)
    # An empty frame means the map frame (rviz, ros2 topic pub).
    localizer.handle_initial_pose_msg(initial_pose_msg(x=3.0, frame=""))
    assert localizer.poses[-1].pose.x == pytest.approx(3.0)


@pytest.mark.parametrize(
    "msg_args",
    [{"frame": "odom"}, {"x": math.nan}, {"variance": math.inf}],
    ids=["other_frame", "nan_pose", "inf_covariance"],
)
def test_a_bad_initial_pose_is_ignored(msg_args):
    localizer = make_localizer()
    localizer.handle_initial_pose_msg(initial_pose_msg(**msg_args))
    assert localizer.poses == []


def test_an_exception_in_the_hook_is_logged_not_raised():
    localizer = make_localizer()

    def fail(pose):
        raise RuntimeError("broken")

    localizer.on_initial_pose = fail
    localizer.handle_initial_pose_msg(initial_pose_msg())  # must not raise


@pytest.mark.ros
def test_every_localizer_subscribes_initialpose_on_its_node(ros, params_file, runtime_factory):
    from geometry_msgs.msg import PoseWithCovarianceStamped

    from easynav.core.testing.system_fixtures import system_params

    # The Dummy localizer has no ROS code of its own: the subscription is the base class's.
    rt = runtime_factory(params_file(system_params()))
    assert rt.start(), rt.error
    node = ros.create_node("initial_pose_sender")
    publisher = node.create_publisher(PoseWithCovarianceStamped, "initialpose", 10)
    assert ros.spin_until(lambda: publisher.get_subscription_count() > 0, timeout=5.0)

    def subscribers() -> list[str]:
        return [i.node_name for i in node.get_subscriptions_info_by_topic("/initialpose")]

    # Node names come with discovery a little after the subscription itself.
    assert ros.spin_until(lambda: subscribers() == ["localizer_node"], timeout=5.0), subscribers()
    # Cleaning up releases it.
    rt.system_node.trigger_deactivate()
    rt.system_node.trigger_cleanup()
    assert ros.spin_until(lambda: publisher.get_subscription_count() == 0, timeout=5.0)

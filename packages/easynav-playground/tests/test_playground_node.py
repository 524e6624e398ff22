"""The playground node over real ROS topics (DDS kept inside the test process)."""

from __future__ import annotations

import json
import math
import subprocess
import sys
import time

import pytest

pytestmark = pytest.mark.ros


def wait_for(predicate, timeout=10.0):
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        if predicate():
            return True
        time.sleep(0.01)
    return predicate()


def make_probe(bed, received):
    from geometry_msgs.msg import Twist
    from nav_msgs.msg import OccupancyGrid, Odometry
    from rclpy.node import Node
    from rclpy.qos import DurabilityPolicy, QoSProfile
    from rosgraph_msgs.msg import Clock
    from sensor_msgs.msg import LaserScan
    from std_msgs.msg import String
    from tf2_msgs.msg import TFMessage

    latched = QoSProfile(depth=10, durability=DurabilityPolicy.TRANSIENT_LOCAL)
    probe = Node("probe", context=bed.context)
    for topic, kind, qos in (
        ("/clock", Clock, 10),
        ("/scan", LaserScan, 10),
        ("/odom", Odometry, 10),
        ("/ground_truth", Odometry, 10),
        ("/tf", TFMessage, 10),
        ("/tf_static", TFMessage, latched),
        ("/collisions", String, latched),
        ("/playground/world", OccupancyGrid, latched),
    ):
        received[topic] = []
        probe.create_subscription(kind, topic, lambda m, t=topic: received[t].append(m), qos)
    probe.cmd_pub = probe.create_publisher(Twist, "/cmd_vel", 10)
    return bed.add(probe)


def stamp(msg_header_stamp):
    return msg_header_stamp.sec + msg_header_stamp.nanosec * 1e-9


def test_node_publishes_sensors_clock_tf_and_moves_on_cmd_vel(ros_bed, tmp_path):
    from geometry_msgs.msg import Twist
    from rclpy.parameter import Parameter

    from easynav.playground.ros.playground_node import PlaygroundNode

    received: dict[str, list] = {}
    probe = make_probe(ros_bed, received)
    record = tmp_path / "truth.json"
    node = PlaygroundNode(
        context=ros_bed.context,
        parameter_overrides=[
            Parameter("speed_up", value=2.0),
            Parameter("record", value=str(record)),
        ],
    )
    ros_bed.add(node)
    node.start()
    try:
        assert wait_for(lambda: len(received["/scan"]) >= 3 and len(received["/odom"]) >= 10)
        # Static frames and the latched world reach a late subscriber too.
        assert wait_for(lambda: received["/tf_static"] and received["/playground/world"])
        static = {
            (t.header.frame_id, t.child_frame_id)
            for m in received["/tf_static"]
            for t in m.transforms
        }
        assert static == {("base_footprint", "base_link"), ("base_link", "base_laser")}
        world = received["/playground/world"][-1]
        assert (world.info.width, world.info.height) == (200, 160)
        assert json.loads(received["/collisions"][-1].data)["count"] == 0

        scan = received["/scan"][-1]
        assert scan.header.frame_id == "base_laser" and len(scan.ranges) == 360
        assert all(math.isfinite(r) for r in scan.ranges)  # indoors: every beam hits a wall
        odom = received["/odom"][-1]
        assert (odom.header.frame_id, odom.child_frame_id) == ("odom", "base_footprint")
        tf_pairs = {
            (t.header.frame_id, t.child_frame_id) for m in received["/tf"] for t in m.transforms
        }
        assert tf_pairs == {("odom", "base_footprint")}
        truth = received["/ground_truth"][-1]
        assert truth.header.frame_id == "map"
        assert truth.pose.pose.position.x == pytest.approx(5.6)

        # Everything is stamped in simulated time, and /clock keeps up with the stamps: the
        # step's /clock goes out before its data, but the probe's executor takes the ready
        # subscriptions in its own order (a scan of t=0.300 was once handled before the /clock
        # of 0.300 was, the latest then being 0.275): wait for the clock of the scan's step.
        assert wait_for(
            lambda: stamp(received["/clock"][-1].clock) >= stamp(scan.header.stamp) - 1e-9, 5.0
        ), (stamp(scan.header.stamp), stamp(received["/clock"][-1].clock))
        assert stamp(received["/clock"][-1].clock) < 100.0  # simulated time starts at zero

        start_x = truth.pose.pose.position.x
        command = Twist()
        command.linear.x = 0.3
        # Keep commanding until the base has sped up and moved (simulated time runs slower than
        # intended on a loaded machine: wait for the effect, not for a wall-clock time).
        def moved() -> bool:
            probe.cmd_pub.publish(command)
            return (
                received["/ground_truth"][-1].pose.pose.position.x > start_x + 0.2
                and received["/odom"][-1].pose.pose.position.x > 0.2
                and received["/odom"][-1].twist.twist.linear.x > 0.2
            )

        assert wait_for(moved, 20.0)
    finally:
        node.stop()
    data = json.loads(record.read_text())
    assert data["commands_received"] >= 10
    assert data["true_poses"][-1][1] > start_x + 0.2
    assert data["collisions"] == []


def test_non_finite_cmd_vel_stops_the_base_and_is_counted(ros_bed):
    from geometry_msgs.msg import Twist

    from easynav.playground.ros.playground_node import PlaygroundNode

    node = ros_bed.add(PlaygroundNode(context=ros_bed.context))
    bad = Twist()
    bad.linear.x = math.nan
    node.sim.set_command(0.3, 0.0)
    node._on_cmd_vel(bad)  # the callback the subscription calls
    node.sim.step()
    assert node.sim.robot.command == (0.0, 0.0)
    assert node._rejected_commands == 1


class StallingStepper:
    """Steps ``sim``, stalls once for ``stall`` wall seconds at step ``at`` (the machine was
    busy elsewhere), and records ``(wall time, simulated time)`` after every step."""

    def __init__(self, sim, at: int, stall: float) -> None:
        self.sim, self.at, self.stall = sim, at, stall
        self.samples: list[tuple[float, float]] = []
        self.stall_ended: float | None = None

    def step(self) -> None:
        if len(self.samples) == self.at:
            time.sleep(self.stall)
            self.stall_ended = time.monotonic()
        self.sim.step()
        self.samples.append((time.monotonic(), self.sim.time))


#: What the playground's README promises: a late simulation catches up at most this much.
CATCH_UP = 0.05  # s, simulated


@pytest.mark.parametrize("stall", [0.03, 0.2])
def test_a_stalled_simulation_goes_on_from_where_it_stopped_without_jumping_ahead(
    ros_bed, stall
):
    # A stall of the simulation thread (the machine is loaded) pauses the world; it must not
    # make up for it by running the lost time in a burst: the stack, slowed by the same load,
    # would see a person walk half a second in one look. (A short stall, 120 ms simulated at
    # x4, and one longer than any catch-up: both end in a restart of the schedule.)
    from rclpy.parameter import Parameter

    from easynav.playground.ros.playground_node import PlaygroundNode

    speed_up = 4.0
    node = ros_bed.add(PlaygroundNode(
        context=ros_bed.context,
        parameter_overrides=[Parameter("speed_up", value=speed_up)],
    ))
    stepper = StallingStepper(node.sim, at=50, stall=stall)
    node._stepper = stepper
    node.start()
    try:
        assert wait_for(lambda: stepper.stall_ended is not None
                        and stepper.samples[-1][0] > stepper.stall_ended + 0.1)
    finally:
        node.stop()
    stall_end = stepper.stall_ended
    at_stall = stepper.samples[stepper.at][1] - node.sim.step_size  # before the stalled step
    after = [(wall, sim) for wall, sim in stepper.samples if wall <= stall_end + 0.05]
    wall, sim = after[-1]
    # Steps after a restart keep to the schedule: at most the catch-up beyond it (a load that
    # slows the steps only lowers the jump).
    allowed = CATCH_UP + (wall - stall_end) * speed_up + 2 * node.sim.step_size
    assert sim - at_stall <= allowed, (
        f"the world jumped {sim - at_stall:.3f} s in {wall - stall_end:.3f} s of wall time")
    assert node.schedule_restarts >= 1


def test_command_line_reports_an_unknown_world_and_exits_2():
    result = subprocess.run(
        [sys.executable, "-m", "easynav.playground", "--world", "atlantis"],
        capture_output=True,
        text=True,
        timeout=30,
        env={**__import__("os").environ, "ROS_AUTOMATIC_DISCOVERY_RANGE": "OFF"},
    )
    assert result.returncode == 2
    assert "atlantis" in result.stderr and "home" in result.stderr


def test_node_takes_the_worlds_robot_unless_a_parameter_overrides_it(ros_bed):
    from rclpy.parameter import Parameter

    from easynav.playground.ros.playground_node import PlaygroundNode

    node = ros_bed.add(
        PlaygroundNode(
            context=ros_bed.context,
            parameter_overrides=[
                Parameter("world", value="tb3_sandbox"),
                Parameter("laser.beams", value=90),
            ],
        )
    )
    assert node.sim.checker.robot_radius == pytest.approx(0.15)
    assert node.get_parameter("laser.max_range").value == pytest.approx(3.5)
    assert node.get_parameter("base.max_linear_vel").value == pytest.approx(0.5)
    assert node.get_parameter("laser.beams").value == 90  # the explicit parameter wins


def test_two_robots_have_their_own_topics_frames_and_record(ros_bed, tmp_path):
    from geometry_msgs.msg import Twist
    from nav_msgs.msg import Odometry
    from rclpy.node import Node
    from rclpy.parameter import Parameter
    from rclpy.qos import DurabilityPolicy, QoSProfile
    from sensor_msgs.msg import LaserScan
    from tf2_msgs.msg import TFMessage

    from easynav.playground.ros.playground_node import PlaygroundNode

    latched = QoSProfile(depth=10, durability=DurabilityPolicy.TRANSIENT_LOCAL)
    received: dict[str, list] = {}
    probe = Node("probe", context=ros_bed.context)
    topics = [("/scan", LaserScan, 10), ("/odom", Odometry, 10), ("/tf", TFMessage, 10)]
    for robot in ("r1", "r2"):
        topics += [
            (f"/{robot}/scan", LaserScan, 10),
            (f"/{robot}/odom", Odometry, 10),
            (f"/{robot}/ground_truth", Odometry, 10),
            (f"/{robot}/tf", TFMessage, 10),
            (f"/{robot}/tf_static", TFMessage, latched),
        ]
    for topic, kind, qos in topics:
        received[topic] = []
        probe.create_subscription(kind, topic, lambda m, t=topic: received[t].append(m), qos)
    r1_cmd = probe.create_publisher(Twist, "/r1/cmd_vel", 10)
    ros_bed.add(probe)
    record = tmp_path / "truth.json"
    node = PlaygroundNode(
        context=ros_bed.context,
        parameter_overrides=[
            Parameter("world", value="crossing"),
            Parameter("robots", value=2),
            Parameter("speed_up", value=2.0),
            Parameter("record", value=str(record)),
        ],
    )
    ros_bed.add(node)
    node.start()
    try:
        assert wait_for(lambda: all(len(received[f"/{r}/scan"]) >= 2 for r in ("r1", "r2")))
        assert wait_for(lambda: received["/r1/tf_static"] and received["/r2/tf_static"])
        for robot in ("r1", "r2"):
            static = {
                (t.header.frame_id, t.child_frame_id)
                for m in received[f"/{robot}/tf_static"]
                for t in m.transforms
            }
            assert static == {
                (f"{robot}/base_footprint", f"{robot}/base_link"),
                (f"{robot}/base_link", f"{robot}/base_laser"),
            }
            assert received[f"/{robot}/scan"][-1].header.frame_id == f"{robot}/base_laser"
            odom = received[f"/{robot}/odom"][-1]
            assert (odom.header.frame_id, odom.child_frame_id) == (
                f"{robot}/odom", f"{robot}/base_footprint"
            )
            assert received[f"/{robot}/ground_truth"][-1].header.frame_id == f"{robot}/map"
            tf_frames = {
                t.header.frame_id for m in received[f"/{robot}/tf"] for t in m.transforms
            }
            assert tf_frames == {f"{robot}/odom"}
        # Nothing on the single-robot names.
        assert received["/scan"] == [] and received["/odom"] == [] and received["/tf"] == []
        truth = {r: received[f"/{r}/ground_truth"][-1].pose.pose.position for r in ("r1", "r2")}
        assert (truth["r1"].x, truth["r1"].y) == pytest.approx((1.5, 2.0))
        assert (truth["r2"].x, truth["r2"].y) == pytest.approx((3.0, 6.0))
        # r2 faces -y, its laser 0.1 m ahead at (3.0, 5.9): the beam towards r1's centre ends
        # on r1's disc (radius 0.2; the map has nothing there; noise 0.01 m).
        scan = received["/r2/scan"][-1]
        bearing = math.atan2(2.0 - 5.9, 1.5 - 3.0) - (-1.5708)
        beam = round((bearing - scan.angle_min) / scan.angle_increment) % len(scan.ranges)
        assert scan.ranges[beam] == pytest.approx(math.hypot(1.5, 3.9) - 0.2, abs=0.05)

        command = Twist()
        command.linear.x = 0.3

        def r1_moved() -> bool:
            r1_cmd.publish(command)
            return received["/r1/ground_truth"][-1].pose.pose.position.x > 1.7

        assert wait_for(r1_moved, 20.0)
    finally:
        node.stop()
    data = json.loads(record.read_text())
    assert set(data["robots"]) == {"r1", "r2"}
    assert data["robots"]["r1"]["commands_received"] >= 1
    assert data["robots"]["r2"]["commands_received"] == 0
    assert data["robots"]["r2"]["true_poses"][-1][1:3] == pytest.approx([3.0, 6.0])
    assert data["robots"]["r1"]["collisions"] == [] and data["world"] == "crossing"


def test_robots_beyond_the_worlds_list_are_refused(ros_bed):
    from rclpy.parameter import Parameter

    from easynav.playground.ros.playground_node import PlaygroundNode

    with pytest.raises(ValueError, match="declares 2 robot"):
        PlaygroundNode(
            context=ros_bed.context,
            parameter_overrides=[
                Parameter("world", value="crossing"), Parameter("robots", value=3)
            ],
        )
    with pytest.raises(ValueError, match="declares 0 robot"):
        PlaygroundNode(context=ros_bed.context, parameter_overrides=[Parameter("robots", value=2)])

"""Repository-wide pytest set-up: every test process gets a ROS domain of its own."""

from easynav.core.testing.dds_isolation import isolate_dds

isolate_dds()

pytest_plugins = [
    "easynav.core.testing.ros_fixtures",
    "easynav.core.testing.system_fixtures",
]

"""Repository-wide pytest set-up: every test process gets a ROS domain of its own."""

import os
import tempfile

from easynav.core.testing.dds_isolation import isolate_dds

isolate_dds()
# Saved configurations and ROS logs of test runs stay out of the user's ~/.ros/log.
os.environ.setdefault("ROS_LOG_DIR", tempfile.mkdtemp(prefix="easynav-test-logs-"))

pytest_plugins = [
    "easynav.core.testing.ros_fixtures",
    "easynav.core.testing.system_fixtures",
]

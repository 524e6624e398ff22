"""Repository-wide pytest set-up: every test process gets a ROS domain of its own.

Where the runtime (easynav-system) is not installed (the kernel or a plugin distribution tested
alone, without ROS), there is no ROS to isolate and no ROS fixture to offer.
"""

import importlib.util
import os
import tempfile

if importlib.util.find_spec("easynav.system") is not None:
    from easynav.system.testing.dds_isolation import isolate_dds

    isolate_dds()
    # Saved configurations and ROS logs of test runs stay out of the user's ~/.ros/log.
    os.environ.setdefault("ROS_LOG_DIR", tempfile.mkdtemp(prefix="easynav-test-logs-"))

    pytest_plugins = [
        "easynav.system.testing.ros_fixtures",
        "easynav.system.testing.system_fixtures",
    ]

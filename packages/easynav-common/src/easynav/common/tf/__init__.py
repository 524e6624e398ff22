"""The TF buffer of EasyNav (tf2 has no PyPI wheel: this package replaces tf2's buffer).

``get_tf_buffer()`` is the process-wide buffer that also holds the robot's :class:`TFInfo`. It is
plain Python and works without ROS: a script fills it with ``set_transform``. In a running
system the runtime's listener (``easynav.system.tf``) fills it from ``tf``/``tf_static``.
"""

from easynav.common.tf.errors import (
    ConnectivityError,
    ExtrapolationError,
    FrameLookupError,
    TransformError,
)
from easynav.common.tf.tf_buffer import TFBuffer
from easynav.common.tf.tf_buffer_registry import (
    get_tf_buffer,
    reset_tf_buffers,
    set_default_tf_namespace,
)
from easynav.core.robot.tf_info import TFInfo

__all__ = [
    "ConnectivityError",
    "ExtrapolationError",
    "FrameLookupError",
    "TFBuffer",
    "TFInfo",
    "TransformError",
    "get_tf_buffer",
    "reset_tf_buffers",
    "set_default_tf_namespace",
]

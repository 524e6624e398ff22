"""The TF buffer of EasyNav (tf2 has no PyPI wheel: this package replaces tf2 / tf2_ros).

``get_tf_buffer()`` is the process-wide buffer that also holds the robot's :class:`TFInfo`;
:class:`TFListener` fills it from ``tf``/``tf_static``; :class:`TFBroadcaster` and
:class:`StaticTFBroadcaster` publish. ROS messages are imported lazily, so the buffer itself
works (and is tested) without ROS.
"""

from easynav.core.tf.errors import (
    ConnectivityError,
    ExtrapolationError,
    FrameLookupError,
    TransformError,
)
from easynav.core.tf.static_tf_broadcaster import StaticTFBroadcaster
from easynav.core.tf.tf_broadcaster import TFBroadcaster
from easynav.core.tf.tf_buffer import TFBuffer
from easynav.core.tf.tf_buffer_registry import (
    get_tf_buffer,
    reset_tf_buffers,
    set_default_tf_namespace,
)
from easynav.core.tf.tf_info import TFInfo
from easynav.core.tf.tf_listener import TFListener

__all__ = [
    "ConnectivityError",
    "ExtrapolationError",
    "FrameLookupError",
    "StaticTFBroadcaster",
    "TFBroadcaster",
    "TFBuffer",
    "TFInfo",
    "TFListener",
    "TransformError",
    "get_tf_buffer",
    "reset_tf_buffers",
    "set_default_tf_namespace",
]

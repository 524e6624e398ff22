"""TF over ROS: the listener that fills the kernel's TF buffer from ``tf``/``tf_static``, and the
broadcasters that publish (and also store locally) transforms."""

from easynav.system.tf.static_tf_broadcaster import StaticTFBroadcaster
from easynav.system.tf.tf_broadcaster import TFBroadcaster
from easynav.system.tf.tf_listener import TFListener

__all__ = ["StaticTFBroadcaster", "TFBroadcaster", "TFListener"]

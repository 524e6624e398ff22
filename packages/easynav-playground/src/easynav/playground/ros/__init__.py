"""The playground's ROS side: the node, its entry point and message building."""

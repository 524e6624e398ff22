"""The ROS boundary: converters between ROS messages and EasyNav's native types."""

"""Test helpers shared by every EasyNav package: DDS isolation and rclpy fixtures."""

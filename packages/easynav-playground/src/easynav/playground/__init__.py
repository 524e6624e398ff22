"""EasyNav playground: a 2D differential-drive robot simulator (laser, odometry, /clock) and the
demo that drives it through waypoints with EasyNav."""

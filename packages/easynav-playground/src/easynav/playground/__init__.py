"""EasyNav playground: a 2D differential-drive simulator with a laser scanner, odometry and /clock, plus the demo."""

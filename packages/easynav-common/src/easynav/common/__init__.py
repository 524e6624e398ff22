"""What EasyNav's plugins share besides the kernel's contracts: the TF buffer and the
perceptions (sensor data in NavState) with their point operations. Plain Python on numpy; the
runtime (``easynav.system``) fills both from ROS topics, a script fills them directly."""

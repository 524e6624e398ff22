"""EasyNav core: NavState, plugin bases and discovery, lifecycle system, RT/non-RT loops, velocity
output, safety, sensors, goal manager, TF buffer, Dummy plugins, the easynav command.
"""

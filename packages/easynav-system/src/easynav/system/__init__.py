"""The ROS node layer: system_node, its six lifecycle sub-nodes and the RT / non-RT loops."""

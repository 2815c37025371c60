"""The recorder (python -m miro_ball.record): topics into a rosbag2 (MCAP) bag.

bag.py writes the bag in finished splits, selection.py holds the pure parts (which
topics, at what time), node.py is the ROS node and its command line.
"""

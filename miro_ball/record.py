"""python -m miro_ball.record -o DIR [TOPIC ...]: record topics into a rosbag2 (MCAP) bag.

The recorder lives in miro_ball/recording/node.py; this module is its short name.
"""
import sys

from miro_ball.recording.node import main

if __name__ == '__main__':
    sys.exit(main())

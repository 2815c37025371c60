"""Maps MiRo builds from what it senses: floor_map paints the floor from its eyes.

Pure numpy (and OpenCV for resampling images); no rclpy, no PyBullet.
"""

"""The PyBullet world: static bodies, movable objects, MiRo robots and their sensors."""

"""Grading a controller: episodes from seeded placements, scored (python -m miro_ball.grade)."""

"""python -m miro_ball.animal: MiRo's demo mode (node.py)."""
import sys

from miro_ball.animal.demo_mode import main

sys.exit(main())

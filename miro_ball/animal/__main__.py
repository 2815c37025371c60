"""python -m miro_ball.animal: MiRo's demo mode (node.py)."""
import sys

from miro_ball.animal.node import main

sys.exit(main())

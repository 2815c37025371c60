"""The controller's own names, for those who watch it (the lab run, the GUI, tests)."""
from miro_ball.miro.interface import check_name

NODE_NAME = 'kick_blue_ball'
DEBUG_TOPIC = '~/debug/{eye}/compressed'  # private: under the node, in the robot's namespace


def debug_topic(robot, eye):
    """Absolute name of one eye's annotated frames of robot's controller."""
    return f'/{check_name(robot)}/{NODE_NAME}/' + DEBUG_TOPIC[2:].format(eye=eye)

"""What is learnt in an environment behaves the same on the ROS simulator: one seeded
KickBall episode, the same controller class, in the environment and as the controller node
on the stepped ROS simulator (the grader's placement of the seed in both): kick_blue_ball's
improved controller, and the policy `python -m miro_ball.learn.train kick_ball` trained (the
bundled one)."""
import pytest

from miro_ball.controller.behaviour import BehaviourParams, make_behaviour
from miro_ball.learn.controllers import run_controller
from miro_ball.learn.env import MiroEnv
from miro_ball.learn.policy_controller import PolicyController
from miro_ball.learn.tasks import KickBall
from miro_ball.run.episode import run_episode
from miro_ball.run.placements import placements
from miro_ball.run.stepped_rig import SteppedRig

LIMIT_S = 20.0
EYES = (160, 90)
# The ROS simulator's eyes are 640x360 JPEGs at 15 Hz; the environment's are drawn every
# tick: the kick may come a few ticks apart, never more.
SAME_KICK_WITHIN_S = 0.5
CONTROLLERS = {
    'improved': ('improved', lambda: make_behaviour('improved', BehaviourParams(seed=1)), 2),
    'trained policy': ('miro_ball.learn.policy_controller:PolicyController',
                       PolicyController, 9),
}


@pytest.mark.parametrize('name', CONTROLLERS)
def test_the_environment_and_the_ros_simulator_agree_on_a_seeded_kick(ros_context, name):
    mode, make, seed = CONTROLLERS[name]
    on_ros = run_episode(SteppedRig(ros_context, mode=mode, seed=1, quiet=True),
                         placements(1, seed=seed)[0], limit_s=LIMIT_S)
    env = MiroEnv(KickBall(limit_s=LIMIT_S), eyes=EYES)
    _, _, here = run_controller(env, make(), seed=seed)
    env.close()
    assert on_ros.kicked and here['kicked'], (on_ros, here)
    assert not on_ros.fell and not here['fell']
    assert abs(on_ros.time_to_kick - here['kick_time']) <= SAME_KICK_WITHIN_S, (on_ros, here)

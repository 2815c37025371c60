"""A trained KickBall policy as a controller of the contract (controller/contract.py), so
that it runs wherever a controller runs: in an environment (learn.controllers.run_controller)
and as the controller node on the ROS simulator::

    python -m miro_ball --ros-args -p mode:=miro_ball.policy.controller:PolicyController
    MIRO_POLICY=DIR python -m miro_ball --ros-args -p mode:=...   # a policy train wrote to DIR

The policy comes from the folder ``$MIRO_POLICY`` names, else the class's ``folder`` (a
subclass may name its own), else the one bundled in policy/bundled/kick_ball. Its input is
made from the Percepts by policy.observation, the very conversion the environment's
observation goes through, and it decides once every ``frame_skip`` platform ticks, as it
was trained, holding the wheels in between (the node calls act() every tick). It loads
neither Gymnasium nor PyBullet: a controller node has no use for them.
"""
import dataclasses
import os

from miro_ball.common.files import MAX_PATH
from miro_ball.controller.contract import Action
from miro_ball.miro.constants import PLATFORM_TICK_S
from miro_ball.policy.linear import load
from miro_ball.policy.observation import observation

POLICY_ENV = 'MIRO_POLICY'
BUNDLED = os.path.join(os.path.dirname(os.path.abspath(__file__)), 'bundled', 'kick_ball')
# What an unknown reading (None: none yet, or stale) becomes: the policy reads only the
# ball and the sonar, but the observation has every entry.
UNKNOWN = {'cliff': (1.0, 1.0), 'light': (0.0,) * 4, 'joints': (0.0,) * 4}


class PolicyController:
    """``PolicyController(params)``: params (the behaviour parameters) are not used; the
    policy's folder is ``$MIRO_POLICY``, else ``folder``, else the bundled policy."""

    detectors = ('ball',)
    folder = None

    def __init__(self, params=None):
        folder = os.environ.get(POLICY_ENV) or self.folder or BUNDLED
        if len(folder) > MAX_PATH:
            raise ValueError(f'{POLICY_ENV}: a folder\'s name of {len(folder)} characters; '
                             f'at most {MAX_PATH}')
        self.policy = load(folder)  # ValueError (one line) for a folder of no policy
        self.hold_s = self.policy.settings['frame_skip'] * PLATFORM_TICK_S
        self._decided = None  # when the wheels were last decided
        self._wheels = (0.0, 0.0)

    def act(self, percepts):
        t = percepts.t
        if self._decided is not None and t < self._decided:
            self._decided = None  # time went back (a reset): a new episode
            self.policy.reset()
        # Half a tick of slack: node times are not exact multiples of the tick.
        if self._decided is None or t - self._decided >= self.hold_s - PLATFORM_TICK_S / 2:
            known = dataclasses.replace(percepts, **{
                name: value for name, value in UNKNOWN.items()
                if getattr(percepts, name) is None})
            self._wheels = tuple(float(v) for v in self.policy.act(
                observation(known, self.detectors)))
            self._decided = t
        return Action(wheels=self._wheels, state='policy')

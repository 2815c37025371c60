"""A small numpy policy for KickBall: the ball detector's readings (and the sonar) to the
wheels, through a linear layer and tanh. No deep-learning library: twelve numbers in all.

The observation is the environment's (policy.observation): ``ball`` (2, 4) rows
[seen, x, y, r] per eye (left, right), ``sonar`` (1,) metres. The policy keeps two numbers
of memory: on which side the ball was last seen, so that a ball lost from view is searched
for on the side it left by (a policy without it can only spin one way), and how big it was
then, so that a ball lost because it is close (below the eyes' view) is driven at, not
searched for. Its outputs are a forward and a turn command, each -1..1, mixed into the two
wheel speeds.

A policy is saved as a folder: ``policy.npz`` (its weights) and ``policy.json`` (the
settings it was trained with: eyes, frame_skip, what it was trained on), read back by
``load`` for evaluation and for the controller node (policy.controller), through
policy.files: the folder may come from anyone, so its files are checked and bounded
before they are read.
"""
import json
import os

import numpy as np

from miro_ball.miro.constants import WHEEL_MAX_SPEED_M_PER_S
from miro_ball.policy.files import read_numbers, read_settings
from miro_ball.policy.observation import SONAR_FAR_M

# MiRo is symmetric, so is the policy: what it does with a ball on the left it does,
# mirrored, with the ball on the right. The forward command reads features that a mirror
# leaves alone, the turn command features that a mirror negates: half the weights of a
# policy free to be lopsided, and no lopsided policy to weed out.
FORWARD_FEATURES = ('bias', 'seen', 'x_spread', 'size', 'lost', 'lost_size', 'near')
TURN_FEATURES = ('seen_side', 'x', 'size_side', 'lost_side', 'lost_side_size')
FEATURES = FORWARD_FEATURES + TURN_FEATURES
OBSERVED = ('ball', 'sonar')  # the observation entries the policy reads
WEIGHTS_FILE = 'policy.npz'
SETTINGS_FILE = 'policy.json'
X_SCALE = 2.0  # the detector's x (-0.5..0.5 of the frame's width) to -1..1
R_SCALE = 10.0  # its radius (a fraction of the width, 0.1 when close) to about 1
SEARCH_SIDE = -1.0  # before the ball is first seen: search clockwise, as the tutorial
# The remembered size fades by this each decision the ball is out of view: close up, the
# ball drops below the eyes' view and the last metres are driven blind.
SIZE_FADE = 0.8


class LinearPolicy:
    """forward = tanh(w_f . forward features), turn = tanh(w_t . turn features), mixed
    into the wheels; ``weights``: the len(FEATURES) weights, w_f then w_t."""

    def __init__(self, weights, settings=None):
        self.weights = np.asarray(weights, np.float64).reshape(len(FEATURES))
        self.settings = dict(settings or {})
        self.reset()

    @staticmethod
    def size():
        return len(FEATURES)

    def reset(self):
        """A new episode: nothing seen yet."""
        self.side = SEARCH_SIDE  # +1: the ball was last seen on the left, -1: on the right
        self.seen_size = 0.0  # how big it was then, fading while it is out of view

    def features(self, observation):
        """(forward features, turn features) of one observation; updates the memory of
        where the ball was last seen and how big."""
        (seen_l, x_l, _, r_l), (seen_r, x_r, _, r_r) = np.asarray(observation['ball'],
                                                                   np.float64)
        x_l, x_r, r_l, r_r = X_SCALE * x_l, X_SCALE * x_r, R_SCALE * r_l, R_SCALE * r_r
        lost = 0.0 if seen_l or seen_r else 1.0
        if lost:
            self.seen_size *= SIZE_FADE
        else:
            # Seen by the left eye only, or towards the left of the frames: on the left.
            self.side = 1.0 if seen_l - seen_r - (x_l + x_r) > 0 else -1.0
            self.seen_size = r_l + r_r
        near = 1.0 - float(observation['sonar'][0]) / SONAR_FAR_M
        remembered = lost * self.seen_size
        return (np.array([1.0, seen_l + seen_r, x_l - x_r, r_l + r_r, lost, remembered, near]),
                np.array([seen_l - seen_r, x_l + x_r, r_l - r_r, lost * self.side,
                          remembered * self.side]))

    def act(self, observation):
        """The wheel speeds (left, right) m/s for one observation."""
        ahead, turning = self.features(observation)
        split = len(FORWARD_FEATURES)
        forward = np.tanh(self.weights[:split] @ ahead)
        turn = np.tanh(self.weights[split:] @ turning)  # > 0: to the left
        left, right = forward - turn, forward + turn
        biggest = max(abs(left), abs(right), 1.0)  # keep the turn when both would saturate
        return np.array([left, right], np.float32) * (WHEEL_MAX_SPEED_M_PER_S / biggest)

    # -- files --------------------------------------------------------------------------------
    def save(self, folder):
        os.makedirs(folder, exist_ok=True)
        np.savez(os.path.join(folder, WEIGHTS_FILE), weights=self.weights)
        with open(os.path.join(folder, SETTINGS_FILE), 'w') as out:
            json.dump({**self.settings, 'features': FEATURES}, out, indent=1)


def load_settings(folder):
    """The settings a policy folder was saved with; ValueError (one line) if unreadable."""
    return read_settings(os.path.join(folder, SETTINGS_FILE))


def load(folder):
    """The LinearPolicy saved in ``folder``; ValueError (one line) when it is not one."""
    settings = load_settings(folder)
    if settings.get('features') != list(FEATURES):
        raise ValueError(f'{folder}: a policy of other features ({_show(settings.get("features"))}'
                         f'), not {", ".join(FEATURES)}')
    path = os.path.join(folder, WEIGHTS_FILE)
    weights = read_numbers(path, 'weights', LinearPolicy.size())
    if not np.all(np.isfinite(weights)):
        raise ValueError(f'{path}: weights that are not finite numbers')
    eyes = settings.get('eyes')
    if not (isinstance(eyes, list) and len(eyes) == 2 and all(
            isinstance(v, int) and 8 <= v <= 1280 for v in eyes)):
        raise ValueError(f'{folder}: eyes must be [width, height], got {_show(eyes)}')
    skip = settings.get('frame_skip')
    if not isinstance(skip, int) or not 1 <= skip <= 1000:
        raise ValueError(f'{folder}: frame_skip must be 1..1000, got {_show(skip)}')
    return LinearPolicy(weights, settings)


def _show(value, limit=80):
    """A value of the settings as a message shows it: at most ``limit`` characters."""
    text = repr(value)
    return text if len(text) <= limit else text[:limit - 3] + '...'

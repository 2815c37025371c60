"""Wrappers that pick parts of the contract's Dict spaces, for learners that want a Box.

``PickActions(env, 'wheels')`` lets a policy set the wheels only (a Box of the two wheel
speeds); the parts it leaves out are never sent, so the robot keeps what it was last told.
``PickObservations(env, ('ball', 'cliff'))`` keeps those entries of the observation.
Gymnasium's own ``FlattenObservation`` makes the Dict one flat Box; ``FlattenActions`` does
the same for the action, for learners that take a Box only (Stable-Baselines3).
"""
import gymnasium as gym
from gymnasium import spaces


class PickActions(gym.ActionWrapper):
    """Only the action ``parts`` (one name: that part's own space; several: a Dict)."""

    def __init__(self, env, parts):
        super().__init__(env)
        self.parts = (parts,) if isinstance(parts, str) else tuple(parts)
        full = env.action_space
        unknown = [part for part in self.parts if part not in full.spaces]
        if unknown or not self.parts:
            raise ValueError(f'no action part {", ".join(unknown) or "given"} '
                             f'(parts: {", ".join(full.spaces)})')
        self.action_space = (full[self.parts[0]] if len(self.parts) == 1 else
                             spaces.Dict({part: full[part] for part in self.parts}))

    def action(self, action):
        return {self.parts[0]: action} if len(self.parts) == 1 else dict(action)


class PickObservations(gym.ObservationWrapper):
    """Only the observation entries ``keys`` (a Dict of them)."""

    def __init__(self, env, keys):
        super().__init__(env)
        self.keys = (keys,) if isinstance(keys, str) else tuple(keys)
        full = env.observation_space
        unknown = [key for key in self.keys if key not in full.spaces]
        if unknown or not self.keys:
            raise ValueError(f'no observation entry {", ".join(unknown) or "given"} '
                             f'(entries: {", ".join(full.spaces)})')
        self.observation_space = spaces.Dict({key: full[key] for key in self.keys})

    def observation(self, observation):
        return {key: observation[key] for key in self.keys}


class FlattenActions(gym.ActionWrapper):
    """The (Dict) action as one flat Box, in Gymnasium's flatten order (parts by name)."""

    def __init__(self, env):
        super().__init__(env)
        self.action_space = spaces.flatten_space(env.action_space)

    def action(self, action):
        return spaces.unflatten(self.env.action_space, action)

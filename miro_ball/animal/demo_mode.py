"""miro_animal: MiRo's demo mode for one robot, a ROS 2 node in the robot's namespace.

Demo mode is a controller (animal.py) run by the controller host (controller/host.py: eyes
decoded and the detectors run per eye, the percepts, the tick on simulated time, the control
topics). This module tells the host what it needs (DEMO_MODE): its parameters, one group per
part under a dotted name (``affect.*``, ``sleep.*``, ...), how a change reaches the animal,
and its own topics as a part of the node (core_topics.CoreTopics).
"""
from miro_ball.animal.actions import ACTIONS
from miro_ball.animal.animal import Animal
from miro_ball.animal.core_topics import CoreTopics
from miro_ball.animal.params import AnimalNodeParams, Config, FlagParams, letters_on, PART_PARAMS
from miro_ball.controller.command_line import host_main
from miro_ball.controller.hosted import Hosted

NODE_NAME = 'miro_animal'


def config_of(values):
    """Demo mode's Config from the host's parameter values ({dataclass: values})."""
    return Config(*(values[group.cls] for group in PART_PARAMS))


def _build(values):
    node = values[AnimalNodeParams]
    return Animal(config_of(values), node.selector, node.seed)


def _update(animal, old, new):
    """A new selector or seed starts the animal afresh; any part's change reaches it at the
    next tick with its state kept."""
    before, now = old[AnimalNodeParams], new[AnimalNodeParams]
    if (before.selector, before.seed) != (now.selector, now.seed):
        return _build(new)
    animal.configure(config_of(new))
    return animal


def _describe(values):
    return "demo mode (selector '%s', switches '%s')" % (
        values[AnimalNodeParams].selector, letters_on(values[FlagParams]))


DEMO_MODE = Hosted(
    node_name=NODE_NAME, prog='miro_animal',
    about="MiRo's demo mode for ROS 2: an animal that notices balls, faces, tags, motion and "
          "sounds, chooses what to do, feels, sleeps and shows it (docs/demo_mode.md). Ctrl+C "
          "stops it with a zero twist.",
    groups=(AnimalNodeParams,) + PART_PARAMS, build=_build, update=_update,
    describe=_describe, parts=(CoreTopics,),
    help_lines=('', 'actions: ' + ', '.join(ACTIONS),
                '-p sleep.fast_sleep:=true runs the sleep cycle 25 times faster.'))


def main(argv=None):
    return host_main(DEMO_MODE, argv)

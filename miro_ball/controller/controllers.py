"""Controllers by name: the `mode` parameter picks one.

A built-in name (tutorial, improved, wag) or ``package.module:Class`` of your own: a
class built as ``Class(BehaviourParams)`` that implements the contract (contract.py).
"""
from miro_ball.common.plugins import named_class
from miro_ball.controller.behaviour import BehaviourParams, MODES
from miro_ball.controller.detectors import DETECTORS

BUILT_IN = dict({name: 'miro_ball.controller.behaviour:%s' % cls.__name__
                 for name, cls in MODES.items()},
                wag='miro_ball.examples.controller_wag:Wag')


def controller_class(mode):
    """The class `mode` names; ValueError (one line) when it names none."""
    cls = named_class('mode', mode, BUILT_IN, 'act', 'controller')
    # Checked here, with the mode, so a set_parameters change to it is refused with the reason
    # (detectors that depend on the instance's settings, a property, are checked when made).
    names = getattr(cls, 'detectors', ())
    unknown = [name for name in names if name not in DETECTORS] \
        if isinstance(names, (tuple, list)) else []
    if unknown:
        raise ValueError("mode '%s': no detector named %s (known: %s)"
                         % (mode, ', '.join(map(repr, unknown)), ', '.join(sorted(DETECTORS))))
    return cls


def make_controller(mode, params: BehaviourParams):
    return controller_class(mode)(params)

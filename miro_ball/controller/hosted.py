"""What the controller host needs to know of a kind of controller, free of ROS.

The host (host.py) is one ROS node that runs any controller of the contract (contract.py):
it reads MiRo's sensors into Percepts, runs the detectors the controller names, ticks it
and publishes its Action. A kind of controller tells the host, through a ``Hosted``:

    node_name, prog, about   the node's name, its command's name and its --help summary
    groups                   its parameter groups (common.ros_params: dataclasses or Groups):
                             the first is the host's own and has the fields HOST_FIELDS
    parts                    extra topics of its own, each a class built as Part(host)
                             (e.g. demo mode's core/... topics), with ``topics()`` for
                             --help and optional ``on_tick(now)``, ``on_change(values)``
    build(values)            a new controller from the groups' values ({class: dataclass})
    update(controller, old, new)  the controller to use after a live parameter change:
                             the same one reconfigured, or a new one
    describe(values)         a few words for the start-up log line

kick_blue_ball's family (controller/kick_blue_ball.py) and demo mode (animal/demo_mode.py)
are both kinds hosted this way; the learning environments build the same controllers without
a host.
"""
from dataclasses import dataclass, fields
from typing import Any, Callable, Tuple

from miro_ball.common.ros_params import group_of

# What the host itself reads from a kind's first group.
HOST_FIELDS = ('tick', 'stale_s', 'head_hold_s', 'head_lift_deg', 'save_debug_keep')


@dataclass(frozen=True)
class Hosted:
    node_name: str
    prog: str
    about: str
    groups: Tuple[Any, ...]
    build: Callable[[dict], Any]
    update: Callable[[Any, dict, dict], Any]
    describe: Callable[[dict], str]
    parts: Tuple[type, ...] = ()
    help_lines: Tuple[str, ...] = ()

    def __post_init__(self):
        host = group_of(self.groups[0]).cls
        missing = [name for name in HOST_FIELDS if name not in {f.name for f in fields(host)}]
        if missing:
            raise TypeError(f'{self.prog}: its first parameter group {host.__name__} lacks the '
                            f"host's fields {', '.join(missing)}")

    @property
    def host_group(self):
        """The dataclass of the host's own parameters (the first group)."""
        return group_of(self.groups[0]).cls

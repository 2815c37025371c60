"""A contract Action as the parts a robot takes: the learning door's one step of its own.

The robot's checks are the simulator's (miro_sim_bullet.physics.commands), the same as its
control topics make: the rig hands an Action's parts to them, and an environment asks them
before it steps.
"""

# The Action's fields that command the robot, named as physics.commands names its parts.
PARTS = ('wheels', 'head', 'cosmetic', 'illum', 'tone', 'stream')


def parts(action):
    """{part: values} of each part of ``action`` (a contract Action) that is set; a part
    left None is not sent (the robot keeps what it was told)."""
    return {part: getattr(action, part) for part in PARTS if getattr(action, part) is not None}


def said(refused):
    """Refusals ({part: why}) in one line."""
    return '; '.join(f'action {part}: {why}' for part, why in refused.items())

"""What an episode is for: the tasks, one module each in this package, each declared once.

A task is a Task subclass with a ``name``, in a module of this package: that is all it takes.
The catalogue (catalogue(), named()) finds it by listing the package, and everything reads
its declaration from the class: learn/__init__ registers its Gymnasium id
(registry.register_tasks), learn.train and learn.evaluate train and score it with its
``training``, rollouts runs its episodes. docs/learning.md, "Adding a task", shows one.

A task sees the world only through the WorldRig, as the episode core (learn.core) calls it
(Task says the contract). Kicks and falls are the one judge's (run/judge.py), fed from the
world as the grading host feeds it, so both decide an episode alike.
"""
import importlib
import pkgutil

SETTLE_S = 0.2  # simulated s for robot and ball to come to rest where they were placed


class Task:
    """The base: no reward, never over but at ``limit_s`` simulated seconds.

    Its declaration (class attributes): ``name``, how train, evaluate and rollouts call it
    (None: a base, not in the catalogue); ``gym_id``, registered as miro_ball/<gym_id>
    (None: not registered); ``wrapper``, a Gymnasium wrapper the registered environment is
    made in (e.g. a Discrete action); ``training``, how learn.train trains it and
    learn.evaluate scores it (learn.trainers says what it has; None: neither). Its options
    are its ``__init__``'s keywords (gymnasium.make passes them to it, the rest to MiroEnv).
    And what its environment has unless told otherwise: the ``world``, the ``eyes``, the
    image ``detectors`` whose results the observation carries (with eyes), ``frame_skip``
    and ``limit_s``.

    The contract, as the episode core (learn.core) calls it: ``build_world`` once, then each
    episode ``start`` after the world is restored, ``physics_step`` after every physics step
    and ``tick`` after every platform tick (these three may change the task's state), and
    ``terminated`` after every tick; ``measure`` at the start and the end of each step, and
    ``reward(before, after)`` between two measures: per agent (robot name) its reward terms,
    from the two measures alone (no state changes; asked twice, it says the same). An agent
    it leaves out gets no reward."""

    name = None
    gym_id = None
    wrapper = None
    training = None
    world = 'miro'
    eyes = (64, 48)  # (width, height) of each eye's image, or None for none
    detectors = ()  # image detectors whose results the observation carries (e.g. 'ball')
    frame_skip = 1  # platform ticks one step lasts
    limit_s = 20.0

    def build_world(self, world):
        """What the rig loads, given the environment's ``world`` (None: not given)."""
        return self.world if world is None else world

    def start(self, rig, rng):
        """Place the world for an episode (``rng``: a seeded random.Random)."""

    def physics_step(self, sim):
        """After each physics step."""

    def tick(self, rig):
        """After each platform tick."""

    def measure(self, rig):
        """What the reward is measured from, now: any value."""
        return None

    def reward(self, before, after):
        """{agent: {term: reward}} for the step from measure ``before`` to ``after``."""
        return {}

    def terminated(self):
        return False

    def info(self):
        return {}


def settle(rig, seconds=SETTLE_S):
    """Let what was placed come to rest (ticks, none of them judged)."""
    for _ in range(round(seconds / (rig.sim.dt * rig.sim.ticks_per_platform_tick))):
        rig.tick()


_found = {}  # the catalogue, once listed


def catalogue(again=False):
    """{name: Task subclass} of every task declared in a module of this package, as listed
    first (``again``: listed anew, for a module added since)."""
    if again:
        _found.clear()
    if not _found:
        for module in pkgutil.iter_modules(__path__, f'{__name__}.'):
            for value in vars(importlib.import_module(module.name)).values():
                if isinstance(value, type) and issubclass(value, Task) and \
                        value.__module__ == module.name and value.name is not None:
                    _found[value.name] = value
    return _found


def named(name):
    """The task called ``name``; ValueError (one line) naming those there are. A name not
    yet listed lists the package again (a module added since)."""
    if name not in catalogue() and name not in catalogue(again=True):
        raise ValueError(f"unknown task '{name}' (tasks: {', '.join(sorted(catalogue()))})")
    return catalogue()[name]

"""The numbers of the standard simulation_interfaces (Jazzy 1.5.1) that the control logic
uses, named as in its .msg and .srv files, grouped by the message that defines them (the
same name means different numbers in different messages: SpawnEntity's NO_RESOURCE is
104, LoadWorld's 102). Plain ints (SimulationState an IntEnum: the simulator keeps its
state as one), so the logic needs no ROS; test_sim_control checks each against the built
messages."""
import enum


class Result:  # msg/Result.msg (RESULT_ prefix dropped)
    FEATURE_UNSUPPORTED = 0
    OK = 1
    NOT_FOUND = 2
    INCORRECT_STATE = 3
    OPERATION_FAILED = 4


class SpawnResult:  # srv/SpawnEntity.srv, msg/SpawnResult.msg
    NAME_NOT_UNIQUE = 101
    NAME_INVALID = 102
    UNSUPPORTED_FORMAT = 103
    NO_RESOURCE = 104
    NAMESPACE_INVALID = 105
    RESOURCE_PARSE_ERROR = 106
    MISSING_ASSETS = 107
    UNSUPPORTED_ASSETS = 108
    INVALID_POSE = 109


class EntityCategory:  # msg/EntityCategory.msg (CATEGORY_ prefix dropped)
    OBJECT = 0
    ROBOT = 1
    HUMAN = 2
    DYNAMIC_OBJECT = 4
    STATIC_OBJECT = 5


CATEGORIES = {EntityCategory.OBJECT: 'object', EntityCategory.ROBOT: 'robot',
              EntityCategory.HUMAN: 'human', EntityCategory.DYNAMIC_OBJECT: 'dynamic object',
              EntityCategory.STATIC_OBJECT: 'static object'}


class SimulationState(enum.IntEnum):  # msg/SimulationState.msg (STATE_ prefix dropped)
    """What the simulator is doing: the one value the simulator keeps of it."""
    STOPPED = 0
    PLAYING = 1
    PAUSED = 2
    QUITTING = 3
    NO_WORLD = 4
    LOADING_WORLD = 5


STATES = {SimulationState.STOPPED: 'stopped', SimulationState.PLAYING: 'playing',
          SimulationState.PAUSED: 'paused', SimulationState.QUITTING: 'quitting',
          SimulationState.NO_WORLD: 'no world', SimulationState.LOADING_WORLD: 'loading a world'}


class SetSimulationState:  # srv/SetSimulationState.srv
    ALREADY_IN_TARGET_STATE = 101
    STATE_TRANSITION_ERROR = 102
    INCORRECT_TRANSITION = 103


class TagsFilter:  # msg/TagsFilter.msg (FILTER_MODE_ prefix dropped)
    ANY = 0
    ALL = 1


class Bounds:  # msg/Bounds.msg (TYPE_ prefix dropped)
    EMPTY = 0
    BOX = 1
    CONVEX_HULL = 2
    SPHERE = 3


class LoadWorld:  # srv/LoadWorld.srv
    UNSUPPORTED_FORMAT = 101
    NO_RESOURCE = 102
    RESOURCE_PARSE_ERROR = 103
    MISSING_ASSETS = 104
    UNSUPPORTED_ASSETS = 105
    UNSUPPORTED_ELEMENTS = 106


class GetAvailableWorlds:  # srv/GetAvailableWorlds.srv
    DEFAULT_SOURCES_FAILED = 101


class Refused(Exception):
    """A request refused: ``code`` is the standard's result code for the response, str()
    the one-line error message."""

    def __init__(self, code, message):
        super().__init__(' '.join(str(message).split()))  # one line, whatever it quotes
        self.code = code

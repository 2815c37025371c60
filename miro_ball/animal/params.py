"""Demo mode's ROS parameters, one dataclass per part (the MDK's pars.py groups).

Numbers are the MDK demo's where it has one (the MDK's ``miro2.core`` demo controller and its
``pars.py``; described publicly in Consequential Robotics' "Biomimetic core" page,
https://consequential.bitbucket.io/Technical_Biomimetic_Core.html), restated in seconds and SI
units: the MDK counts 50 Hz ticks, we count seconds so a change of tick keeps the behaviour. Where the MDK has no number (or its model is not
ours) the value is our own and its help says what it does.
"""
import math
from dataclasses import dataclass, field, fields, make_dataclass, replace

from miro_ball.common.ros_params import check_ranges, Group
from miro_ball.miro.constants import LIFT_RAD_CALIB, PLATFORM_TICK_S


def knob(default, help, low, high):
    """A tunable number: its default, what it does and the range it may take."""
    return field(default=default, metadata={'help': help, 'range': (low, high)})


def switch(default, help):
    return field(default=default, metadata={'help': help})


@dataclass(frozen=True)
class AnimalNodeParams:
    tick: float = knob(PLATFORM_TICK_S, 'control period, s (node clock)', 0.005, 0.2)
    stale_s: float = knob(0.5, 'forget detections and readings older than this, s', 0.05, 10.0)
    seed: int = knob(0, 'seed of the selection noise and the blinks', 0, 2 ** 31 - 1)
    selector: str = field(default='basal_ganglia', metadata={
        'help': "the action selector: basal_ganglia or module:Class of your own "
                "(docs/demo_mode.md)"})
    # The controller node's start pose hold (demo mode does not hold by default).
    head_hold_s: float = knob(0.0, 'hold the start head pose this long first, s', 0.0, 60.0)
    head_lift_deg: float = knob(round(math.degrees(LIFT_RAD_CALIB), 6),
                                'lift of the start head pose, deg', 8.0, 60.0)
    save_debug_keep: int = knob(500, '--save-debug keeps only the newest this many frames',
                                1, 1000000)

    def __post_init__(self):
        from miro_ball.animal.selection import selector_class

        selector_class(self.selector)  # ValueError (one line) when it names none
        check_ranges(self)


# The MDK's demo_flags letters, each a switch of ours: (letter, parameter, what it does).
FLAG_LETTERS = (
    ('v', 'voice', 'vocalise through the speaker'),
    ('t', 'translation', 'drive forwards and backwards'),
    ('r', 'rotation', 'turn the body'),
    ('n', 'neck', 'move the head'),
    ('s', 'sleep', 'tire and sleep'),
    ('c', 'cliff_reflex', 'stop at a drop ahead'),
    ('u', 'shun_cliffs', 'back away and turn from a drop'),
    ('d', 'affect_from_sound', 'loud sounds change emotion'),
    ('M', 'salience_motion', 'motion draws attention'),
    ('S', 'salience_sound', 'sounds draw attention'),
    ('F', 'salience_faces', 'faces draw attention'),
    ('B', 'salience_ball', 'the ball draws attention'),
    ('T', 'tail', 'move the tail'),
    ('h', 'negative_valence', 'can be unhappy (else valence stays >= 0)'),
    ('a', 'move_away', 'avert, flee and retreat'),
    ('H', 'halt_on_stall', 'halt when stuck'),
    ('m', 'sonar_modulation', 'slow down near obstacles ahead'),
)


# Parts of demo mode on or off: a switch per letter, all on by default.
FlagParams = make_dataclass('FlagParams', [
    (name, bool, switch(True, f'{what} [{letter}]')) for letter, name, what in FLAG_LETTERS],
    frozen=True)


@dataclass(frozen=True)
class SpatialParams:
    """The attention (priority) map around MiRo."""
    map_tau_s: float = knob(0.3, 'the map fades with this time constant, s', 0.01, 10.0)
    peak_threshold: float = knob(0.15, 'a peak this high is a target', 0.0, 10.0)
    gain_ball: float = knob(0.75, 'salience of the ball', 0.0, 10.0)
    gain_face: float = knob(1.0, 'salience of a face', 0.0, 10.0)
    gain_tag: float = knob(0.5, 'salience of an AprilTag', 0.0, 10.0)
    gain_motion: float = knob(0.6, 'salience of motion (times its size, up to 1)', 0.0, 10.0)
    gain_sound: float = knob(5.0, 'salience of a sound at full loudness', 0.0, 20.0)
    gain_sound_self: float = knob(0.0, 'salience of sounds while MiRo itself vocalises (the '
                                       'MDK: 1; its own voice is the loudest sound it hears)',
                                  0.0, 20.0)
    sound_range_m: float = knob(2.0, 'a sound is taken to be this far', 0.1, 20.0)
    sound_height_m: float = knob(0.6, 'and this high', 0.0, 5.0)
    quiet_db: float = knob(-45.0, 'sounds below this level (dBFS) are not attended', -90.0, 0.0)
    loud_db: float = knob(-15.0, 'a sound this loud (dBFS) counts fully', -90.0, 0.0)
    habituation_s: float = knob(20.0, 'time to get used to a kind of thing in view, s',
                                0.1, 3600.0)
    habituation_depth: float = knob(0.5, 'how much salience getting used to it takes away',
                                    0.0, 1.0)
    motion_still_s: float = knob(0.4, 'motion counts only after MiRo kept still this long, s',
                                 0.0, 10.0)

    def __post_init__(self):
        check_ranges(self)
        if self.quiet_db >= self.loud_db:
            raise ValueError('need quiet_db < loud_db')


@dataclass(frozen=True)
class ActionParams:
    """Action selection and the actions' motor patterns."""
    hysteresis: float = knob(0.05, 'the running action\'s priority bonus', 0.0, 1.0)
    selection_noise: float = knob(0.01, 'noise added to each priority', 0.0, 1.0)
    min_duration_s: float = knob(0.6, 'an action runs at least this long (a reflex or an '
                                      'uninterruptable priority 1 excepted), s', 0.0, 10.0)
    priority_idle: float = knob(0.1, 'priority of mull (idle)', 0.0, 1.0)
    priority_search: float = knob(0.25, 'priority of search after a while with nothing seen',
                                  0.0, 1.0)
    search_after_s: float = knob(8.0, 'search after this long with no target, s', 0.0, 600.0)
    fixation_deg: float = knob(15.0, 'a target this close to straight ahead is fixated, deg',
                               1.0, 90.0)
    orient_base: float = knob(0.5, 'orient: priority per unit salience', 0.0, 1.0)
    orient_s_per_rad: float = knob(2.0, 'orient: time per radian to turn, s', 0.1, 10.0)
    orient_min_s: float = knob(0.5, 'orient: shortest, s', 0.02, 10.0)
    orient_max_s: float = knob(2.0, 'orient: longest, s', 0.02, 20.0)
    turn_rate: float = knob(2.0, 'fastest body turn, rad/s', 0.1, 5.0)
    approach_base: float = knob(0.2, 'approach: base priority', -1.0, 1.0)
    approach_size_gain: float = knob(0.5, 'approach: priority per radian the target spans',
                                     0.0, 5.0)
    approach_arousal_gain: float = knob(1.0, 'approach: priority per unit of arousal',
                                        0.0, 5.0)
    approach_valence_gain: float = knob(0.2, 'approach: priority per unit of valence',
                                        0.0, 5.0)
    approach_fixation_gain: float = knob(1.5, 'approach: priority when the target is fixated',
                                         0.0, 5.0)
    approach_speed: float = knob(0.2, 'approach: speed, m/s', 0.0, 0.4)
    approach_min_s: float = knob(1.0, 'approach: shortest, s', 0.02, 20.0)
    approach_max_s: float = knob(6.0, 'approach: longest, s', 0.02, 60.0)
    approach_stop_m: float = knob(0.3, 'approach: stop this far from the target, m', 0.05, 2.0)
    value_ball: float = knob(1.0, 'how much MiRo wants the ball ("my toy")', 0.0, 2.0)
    value_face: float = knob(0.5, 'how much MiRo wants a face', 0.0, 2.0)
    value_other: float = knob(0.2, 'how much MiRo wants anything else', 0.0, 2.0)
    ball_size_m: float = knob(0.2, 'the ball\'s diameter, for its range', 0.01, 2.0)
    face_size_m: float = knob(0.3, 'a face\'s width, for its range', 0.01, 2.0)
    flee_base: float = knob(-0.2, 'flee: base priority', -1.0, 1.0)
    flee_arousal_gain: float = knob(0.25, 'flee: priority per unit of arousal', 0.0, 5.0)
    flee_valence_gain: float = knob(0.5, 'flee: priority per unit of negative valence',
                                    0.0, 5.0)
    flee_size_gain: float = knob(0.75, 'flee: priority per radian the target spans', 0.0, 5.0)
    flee_speed: float = knob(0.3, 'flee: speed, m/s', 0.0, 0.4)
    flee_s: float = knob(2.0, 'flee: how long, s', 0.02, 20.0)
    avert_base: float = knob(0.0, 'avert: base priority', -1.0, 1.0)
    avert_valence_gain: float = knob(0.6, 'avert: priority per unit of negative valence',
                                     0.0, 5.0)
    avert_s: float = knob(1.5, 'avert: how long, s', 0.02, 20.0)
    retreat_priority: float = knob(0.75, 'retreat: priority when something is too close',
                                   0.0, 1.0)
    retreat_near_m: float = knob(0.08, 'retreat: the sonar range that is too close, m',
                                 0.0, 1.0)
    retreat_distance_m: float = knob(0.6, 'retreat: how far back, m', 0.0, 5.0)
    retreat_speed: float = knob(0.2, 'retreat: speed, m/s', 0.01, 0.4)
    halt_priority: float = knob(0.75, 'halt: priority when stuck', 0.0, 1.0)
    stall_s: float = knob(1.5, 'stuck: driving on while the sonar range stays put this long, '
                               's', 0.1, 20.0)
    halt_s: float = knob(0.4, 'halt: how long, s', 0.02, 10.0)

    def __post_init__(self):
        check_ranges(self)
        for short, long in (('orient_min_s', 'orient_max_s'),
                            ('approach_min_s', 'approach_max_s')):
            if getattr(self, short) > getattr(self, long):
                raise ValueError(f'need {short} <= {long}')


@dataclass(frozen=True)
class AffectParams:
    """Emotion (fast) and mood (slow), each a valence and an arousal in -1..1."""
    emotion_tau_s: float = knob(4.0, 'emotion relaxes to mood with this time constant, s',
                                0.1, 600.0)
    mood_tau_s: float = knob(60.0, 'mood follows emotion with this time constant, s',
                             1.0, 36000.0)
    valence_relax_awake_s: float = knob(600.0, 'mood\'s valence returns to neutral over this, '
                                               'awake, s', 1.0, 36000.0)
    valence_relax_asleep_s: float = knob(120.0, '... and asleep, s', 1.0, 36000.0)
    arousal_nominal: float = knob(0.0, 'mood\'s arousal in ordinary light, awake', -1.0, 1.0)
    light_offset: float = knob(0.2, 'light level (0..1) below which arousal sinks', 0.0, 1.0)
    light_gain: float = knob(1.0, 'arousal per unit of light above light_offset', 0.0, 5.0)
    sleep_arousal: float = knob(1.0, 'arousal lost when fully asleep', 0.0, 2.0)
    stroke_valence: float = knob(0.05, 'valence per stroke (a hand moving two pads along)',
                                 0.0, 1.0)
    stroke_pads: int = knob(2, 'a stroke: the hand moves this many pads along the line', 1, 6)
    pet_valence: float = knob(0.05, 'valence per second of a still hand (a pet)', 0.0, 1.0)
    hit_pads: int = knob(5, 'a hit: this many pads touched at once from none (a fingertip '
                            'covers one or two)', 2, 14)
    hit_valence: float = knob(-0.2, 'valence per hit', -1.0, 0.0)
    hit_arousal: float = knob(0.2, 'arousal per hit', 0.0, 1.0)
    loud_valence: float = knob(-0.1, 'valence per second of full loudness', -2.0, 0.0)
    loud_arousal: float = knob(1.0, 'arousal per second of full loudness', 0.0, 5.0)
    startle_arousal: float = knob(0.1, 'arousal when motion appears', 0.0, 1.0)
    body_pads: int = knob(0x3F7E, 'body pads that count (bits; the front ones are where MiRo '
                                  'touches itself with its head)', 0, 0x3FFF)
    head_pads: int = knob(0x3FFF, 'head pads that count (bits)', 0, 0x3FFF)

    def __post_init__(self):
        check_ranges(self)


@dataclass(frozen=True)
class SleepParams:
    """Wakefulness and sleep pressure, a relaxation oscillator."""
    fast_sleep: bool = switch(False, 'run the sleep dynamics fast_sleep_factor times faster '
                                     '(the MDK\'s developer flag)')
    fast_sleep_factor: float = knob(25.0, 'how much faster with fast_sleep', 1.0, 1000.0)
    pressure_rate: float = knob(0.0005, 'sleep pressure builds at this rate awake and '
                                        'unstimulated, /s', 0.0, 1.0)
    recovery_rate: float = knob(0.0005, 'and falls at this rate asleep, /s', 0.0, 1.0)
    stimulation_relief: float = knob(0.9, 'stimulation slows the build-up by up to this '
                                          'fraction', 0.0, 1.0)
    sleep_at: float = knob(0.8, 'pressure at which MiRo falls asleep', 0.0, 1.0)
    wake_at: float = knob(0.2, 'pressure at which it wakes by itself', 0.0, 1.0)
    fall_rate: float = knob(0.01, 'wakefulness falls at this rate when tired, /s', 0.0, 10.0)
    rise_rate: float = knob(0.5, 'and rises at this rate waking (not sped up), /s', 0.0, 10.0)
    wake_relief: float = knob(0.3, 'a touch or loud sound takes this much pressure away',
                              0.0, 1.0)
    asleep_below: float = knob(0.2, 'wakefulness below this is asleep', 0.0, 1.0)

    def __post_init__(self):
        check_ranges(self)
        if self.wake_at >= self.sleep_at:
            raise ValueError('need wake_at < sleep_at')


@dataclass(frozen=True)
class ExpressParams:
    """How the state shows: tail, eyelids, ears, LEDs, head and voice."""
    wag_base_hz: float = knob(0.5, 'tail wags (back and forth) per second, neutral', 0.0, 10.0)
    wag_valence_hz: float = knob(3.0, 'more per unit of valence', 0.0, 20.0)
    wag_amplitude: float = knob(0.5, 'largest wag (cosmetic units)', 0.0, 0.5)
    blink_mean_s: float = knob(10.0, 'a blink every this long on average, s', 0.1, 600.0)
    blink_refractory_s: float = knob(2.0, 'no blink sooner than this after one, s', 0.0, 60.0)
    blink_s: float = knob(0.16, 'a blink lasts, s', 0.02, 2.0)
    double_blink: float = knob(0.2, 'chance that a blink is double', 0.0, 1.0)
    touch_eyelids: float = knob(0.5, 'eyelids droop this much while touched', 0.0, 1.0)
    led_rgb: tuple = field(default=(128, 64, 0), metadata={
        'help': 'the LEDs\' colour, content (R, G, B)', 'range': (0, 255)})
    led_unhappy_rgb: tuple = field(default=(40, 30, 140), metadata={
        'help': 'the LEDs\' colour, unhappy (R, G, B)', 'range': (0, 255)})
    led_pulse_hz: float = knob(0.3, 'LED pulse rate, calm, Hz', 0.0, 10.0)
    led_pulse_arousal_hz: float = knob(1.0, 'more per unit of arousal, Hz', 0.0, 10.0)
    breathe_hz: float = knob(0.2, 'asleep, the head rises and falls this often, Hz', 0.0, 5.0)
    breathe_rad: float = knob(0.05, 'by this much (pitch), rad', 0.0, 0.5)
    voice_via: str = field(default='stream', metadata={
        'help': 'vocalise through control/stream or control/tone'})
    voice_volume: float = knob(0.5, 'vocalisation loudness, 0..1 of full scale', 0.0, 1.0)
    voice_refractory_s: float = knob(3.0, 'at most one vocalisation in this long, s',
                                     0.1, 600.0)

    def __post_init__(self):
        check_ranges(self)
        for name in ('led_rgb', 'led_unhappy_rgb'):
            if len(getattr(self, name)) != 3:
                raise ValueError(f'{name} must be three values (R, G, B)')
        if self.voice_via not in ('stream', 'tone'):
            raise ValueError(f"voice_via must be stream or tone, not '{self.voice_via}'")


PART_GROUPS = (FlagParams, SpatialParams, ActionParams, AffectParams, SleepParams,
               ExpressParams)
# Each part's parameters under its own dotted name, the ROS 2 way: flags.tail,
# attention.peak_threshold, sleep.fast_sleep, ... (one namespace per part: two parts may use
# one field name without a clash).
PART_PARAMS = tuple(Group(prefix, cls) for prefix, cls in zip(
    ('flags', 'attention', 'action', 'affect', 'sleep', 'express'), PART_GROUPS))
PREFIX = {group.cls: group.prefix for group in PART_PARAMS}


@dataclass(frozen=True)
class Config:
    """Every part's parameters together: what the Animal is built from."""
    flags: FlagParams = FlagParams()
    spatial: SpatialParams = SpatialParams()
    action: ActionParams = ActionParams()
    affect: AffectParams = AffectParams()
    sleep: SleepParams = SleepParams()
    express: ExpressParams = ExpressParams()

    def with_part(self, values):
        """This config with one part's parameters (a PART_GROUPS value) replaced."""
        return replace(self, **{SLOTS[type(values)]: values})


SLOTS = {f.type: f.name for f in fields(Config)}  # each part's class: its name in Config


def letters_on(flags):
    """The MDK's demo_flags string of the switches that are on ('vtrn...')."""
    return ''.join(letter for letter, name, _ in FLAG_LETTERS if getattr(flags, name))


def config_command(text):
    """The switch a core/config/command toggles ('f<letter>': its parameter name), None for
    'ping'; ValueError in one line for anything else."""
    if text == 'ping':
        return None
    names = {letter: name for letter, name, _ in FLAG_LETTERS}
    if len(text) == 2 and text[0] == 'f' and text[1] in names:
        return names[text[1]]
    shown = text if len(text) <= 40 else text[:40] + '...'
    raise ValueError(f"core/config/command {shown!r}: expected 'ping' or 'f' and one of "
                     f"{''.join(names)}")

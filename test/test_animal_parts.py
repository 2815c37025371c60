"""Demo mode's parts, each on its own, without ROS: time passed in, properties asserted."""
import math

import numpy as np
import pytest

from miro_ball.animal.actions import ACTIONS
from miro_ball.animal.affect import adjust, AffectModel, Events
from miro_ball.animal.animal import Animal
from miro_ball.animal.attention import PriorityMap
from miro_ball.animal.express import Expression
from miro_ball.animal.feel import Feel
from miro_ball.animal.params import (ActionParams, AffectParams, Config, config_command,
                                     ExpressParams, FlagParams, letters_on, SleepParams,
                                     SpatialParams, AnimalNodeParams)
from miro_ball.animal.selection import BasalGanglia, selector_class
from miro_ball.animal.map_view import map_in_eye
from miro_ball.animal.own_motion import KEEP_S, OwnMotion
from miro_ball.animal.senses import Senses, Stimulus
from miro_ball.animal.sleep import SleepModel
from miro_ball.animal.voice import length_s, pitch_hz, vocalise
from miro_ball.controller.behaviour import DEFAULT_CAMERAS
from miro_ball.controller.contract import Eye, Percepts
from miro_ball.controller.detection import Ball
from miro_ball.miro.constants import KIN_CALIB_RAD, SPEAKER_SAMPLE_RATE_HZ, YAW
from miro_ball.miro.kc import CAML, CAMR, KinematicChain

DT = 0.02


def stroke_masks(seconds, pads_per_s=10):
    """Body masks of a hand moving front to back and round again along both rows."""
    ticks = int(seconds / DT)
    return [(1 << col) | (1 << (col + 7))
            for col in (int(i * DT * pads_per_s) % 7 for i in range(ticks))]


# -- feel -------------------------------------------------------------------------------------
def test_a_moving_hand_strokes_a_still_one_pets_a_slap_hits():
    feel = Feel(AffectParams())
    felt = [feel.feel(0, mask) for mask in stroke_masks(2.0)]
    assert sum(t.strokes for t in felt) >= 5 and not any(t.hits for t in felt)
    feel = Feel(AffectParams())
    still = [feel.feel(0, 0b110 << 7) for _ in range(50)]
    assert all(t.pet and not t.strokes for t in still)
    feel = Feel(AffectParams())
    assert feel.feel(0, 0).hits == 0 and feel.feel(0x3FFF, 0).hits == 1
    assert feel.feel(0x3FFF, 0).hits == 0  # held on: one hit, not one a tick


def test_the_body_pads_at_the_front_do_not_count():
    # MiRo touches them itself with its head (the MDK masks its first body pads too).
    feel = Feel(AffectParams())
    assert not feel.feel(0, 1 | 1 << 7).touched
    assert feel.feel(0, 1 << 3).touched


# -- affect -----------------------------------------------------------------------------------
def test_strokes_please_hits_hurt_and_both_fade_back_towards_mood():
    model = AffectModel(AffectParams(), FlagParams())
    for i in range(250):
        model.step(DT, Events(strokes=int(i % 10 == 0)), 1.0)
    pleased = model.emotion.valence
    assert pleased >= 0.1
    for _ in range(1000):
        model.step(DT, Events(), 1.0)
    assert 0 <= model.emotion.valence < pleased / 2  # relaxed towards mood
    model.step(DT, Events(hits=2), 1.0)
    assert model.emotion.valence < 0 and model.emotion.arousal > 0


def test_loud_sounds_arouse_darkness_and_sleep_calm():
    loud = AffectModel(AffectParams(), FlagParams())
    for _ in range(100):
        loud.step(DT, Events(loudness=1.0), 1.0)
    assert loud.emotion.arousal > 0.3 and loud.emotion.valence < 0
    deaf = AffectModel(AffectParams(), FlagParams(affect_from_sound=False))
    deaf.step(DT, Events(loudness=1.0), 1.0)
    assert deaf.emotion.arousal == 0
    bright, dark = (AffectModel(AffectParams(), FlagParams()) for _ in range(2))
    for _ in range(3000):
        bright.step(DT, Events(light=0.9), 1.0)
        dark.step(DT, Events(light=0.0), 0.0)
    assert bright.mood.arousal > 0.3 > -0.3 > dark.mood.arousal


def test_valence_stays_non_negative_when_unhappiness_is_switched_off():
    model = AffectModel(AffectParams(), FlagParams(negative_valence=False))
    model.step(DT, Events(hits=3), 1.0)
    assert model.emotion.valence == 0


def test_adjust_adds_moves_part_way_or_leaves_alone():
    assert adjust(0.2, 0.3, -1) == pytest.approx(0.5)
    assert adjust(0.2, 1.0, 0.5) == pytest.approx(0.6)
    assert adjust(0.2, 1.0, 0.0) == 0.2 and adjust(0.2, 1.0, 7.0) == 0.2


# -- sleep ------------------------------------------------------------------------------------
def time_to_sleep(params, stimulation=0.0, limit_s=20000.0):
    model, t = SleepModel(params), 0.0
    while not model.asleep and t < limit_s:
        model.step(0.1, stimulation, woken=False)
        t += 0.1
    return t


def test_left_alone_it_sleeps_and_fast_sleep_is_25_times_faster():
    slow, fast = time_to_sleep(SleepParams()), time_to_sleep(SleepParams(fast_sleep=True))
    assert fast < 180.0 < slow
    assert slow / fast == pytest.approx(25.0, rel=0.05)
    assert time_to_sleep(SleepParams(fast_sleep=True), stimulation=1.0) > 3 * fast


def test_sleep_cycles_with_hysteresis_and_a_touch_wakes_it():
    model, asleep = SleepModel(SleepParams(fast_sleep=True)), []
    for _ in range(int(600 / 0.1)):
        model.step(0.1, 0.0, woken=False)
        asleep.append(model.asleep)
    changes = sum(a != b for a, b in zip(asleep, asleep[1:]))
    assert 2 <= changes <= 12  # slept and woke a few times, never flickering
    while not model.asleep:
        model.step(0.1, 0.0, woken=False)
    model.step(0.1, 1.0, woken=True)
    for _ in range(30):
        model.step(0.1, 0.0, woken=False)
    assert model.state.wakefulness > 0.9


# -- attention --------------------------------------------------------------------------------
def ball_ahead(azimuth=0.0, kind='ball'):
    return Stimulus(kind, azimuth, -0.2, 0.2, 0.8)


def test_the_peak_is_where_the_most_salient_thing_is_and_fades_when_it_goes():
    attention = PriorityMap(SpatialParams())
    peak = attention.update(DT, [ball_ahead(0.3), Stimulus('sound', -2.0, 0.1, 0.1, 2.0, 1.0)])
    assert peak.kind == 'sound' and abs(peak.azimuth + 2.0) < math.radians(4)
    peak = attention.update(DT, [ball_ahead(0.3)])
    assert peak.kind == 'sound'  # a sound just heard still holds attention for a moment
    for _ in range(50):
        peak = attention.update(DT, [ball_ahead(0.3)])
    assert peak.kind == 'ball' and abs(peak.azimuth - 0.3) < math.radians(4)
    assert peak.range == pytest.approx(0.8)
    for _ in range(100):
        peak = attention.update(DT, [])
    assert attention.target(peak) is None


def test_the_same_sight_each_tick_holds_its_salience_and_habituation_lowers_it():
    attention = PriorityMap(SpatialParams())
    first = attention.update(DT, [ball_ahead()]).height
    again = attention.update(DT, [ball_ahead()]).height
    assert again == pytest.approx(first, rel=0.05)  # the larger, not the sum
    for _ in range(int(60 / DT)):
        late = attention.update(DT, [ball_ahead()]).height
    assert late < 0.7 * first


def test_the_attention_view_of_an_older_frame_shows_the_map_where_it_was_then():
    """The map is the body's now; a frame taken before the body turned 16 degrees left (four
    of the map's cells) saw each thing 16 degrees further left: its view shows the map so."""
    turned_since, now = PriorityMap(SpatialParams()), PriorityMap(SpatialParams())
    turned_since.update(DT, [ball_ahead(math.radians(10))])
    now.update(DT, [ball_ahead(math.radians(26))])
    full = 4 * SpatialParams().peak_threshold
    then = map_in_eye(turned_since.values, DEFAULT_CAMERAS[0], KC, CAML, full,
                      turned=math.radians(16))
    assert then.max() > 100
    assert np.abs(then.astype(int) - map_in_eye(now.values, DEFAULT_CAMERAS[0], KC, CAML,
                                                full)).max() <= 1


# -- selection --------------------------------------------------------------------------------
def test_hysteresis_and_the_minimum_duration_keep_the_choice_steady():
    def flips(params):
        bg = BasalGanglia(params, np.random.default_rng(1))
        choices = [bg.select(i * DT, [0.5 + 0.01 * (-1) ** i, 0.5 - 0.01 * (-1) ** i])
                   for i in range(500)]
        return sum(a != b for a, b in zip(choices, choices[1:]))
    assert flips(ActionParams()) == 0
    assert flips(ActionParams(hysteresis=0.0, min_duration_s=0.0)) > 100  # what they prevent
    bg = BasalGanglia(ActionParams(hysteresis=0.0, selection_noise=0.0),
                      np.random.default_rng(1))
    bg.select(0.0, [0.6, 0.5])
    assert bg.select(0.1, [0.5, 0.6]) == 0  # not before min_duration_s
    assert bg.select(0.1, [0.5, 1.0]) == 1  # uninterruptable wins at once
    assert bg.select(1.0, [0.6, 0.5]) == 0


def test_a_selector_of_ones_own_is_found_and_bad_names_are_refused_in_one_line():
    assert selector_class('basal_ganglia') is BasalGanglia
    assert selector_class('test_animal_parts:FirstAlways') is FirstAlways
    for name, said in [('bg', 'selector must be one of basal_ganglia or module:Class'),
                       ('no_such_module:X', 'cannot import'),
                       ('test_animal_parts:Nope', 'no selector class')]:
        with pytest.raises(ValueError, match=said) as err:
            AnimalNodeParams(selector=name)
        assert '\n' not in str(err.value)


class FirstAlways:
    """The smallest selector: always the first action (mull)."""

    def __init__(self, params, rng):
        pass

    def select(self, t, priorities):
        return 0


# -- expression and voice ---------------------------------------------------------------------
def wag_crossings_per_s(valence, seconds=10.0):
    shown = Expression(ExpressParams(), FlagParams(), np.random.default_rng(0))
    wags = [shown.step(i * DT, DT, valence, 0.0, 1.0, False).cosmetic[1]
            for i in range(int(seconds / DT))]
    return sum((a - 0.5) * (b - 0.5) < 0 for a, b in zip(wags, wags[1:])) / seconds


def test_a_happier_tail_wags_faster_asleep_the_eyelids_close_and_the_leds_change():
    assert wag_crossings_per_s(0.5) > 2 * wag_crossings_per_s(0.0) > 0
    shown = Expression(ExpressParams(), FlagParams(), np.random.default_rng(0))
    asleep = shown.step(0.0, DT, 0.0, 0.0, 0.0, False)
    assert asleep.cosmetic[2] >= 0.8 and asleep.cosmetic[3] >= 0.8
    happy, sad = shown.leds(0.0, 1.0, 0.0, 1.0), shown.leds(0.0, -1.0, 0.0, 1.0)
    assert happy[0] & 0xFFFFFF == 0x804000 and sad[0] & 0xFFFFFF == 0x281E8C
    assert all(0 <= value <= 0xFFFFFFFF for value in happy + sad)


def test_it_blinks_now_and_then():
    shown = Expression(ExpressParams(), FlagParams(), np.random.default_rng(3))
    lids = [shown.step(i * DT, DT, 0.0, 0.0, 1.0, False).cosmetic[2] for i in range(3000)]
    blinks = sum(a < 1 <= b for a, b in zip(lids, lids[1:]))
    assert 2 <= blinks <= 12  # 60 s, one every ~10 s


def spectrum_peak_hz(samples):
    spectrum = np.abs(np.fft.rfft(samples * np.hanning(len(samples))))
    return np.fft.rfftfreq(len(samples), 1 / SPEAKER_SAMPLE_RATE_HZ)[np.argmax(spectrum)]


def test_the_voice_rises_with_arousal_lengthens_with_valence_and_roughens_when_unhappy():
    rng = np.random.default_rng(0)
    calm, alert = vocalise(0.0, -0.8, 0.5, rng), vocalise(0.0, 0.8, 0.5, rng)
    assert spectrum_peak_hz(alert) > 1.5 * spectrum_peak_hz(calm)
    assert spectrum_peak_hz(calm) == pytest.approx(pitch_hz(-0.8), rel=0.15)
    happy, sad = vocalise(0.9, 0.0, 0.5, rng), vocalise(-0.9, 0.0, 0.5, rng)
    assert len(happy) > 2 * len(sad)
    assert len(sad) == int(length_s(-0.9) * SPEAKER_SAMPLE_RATE_HZ)

    def flatness(samples):
        power = np.abs(np.fft.rfft(samples.astype(float))) ** 2 + 1e-9
        return np.exp(np.mean(np.log(power))) / np.mean(power)
    assert flatness(sad) > 10 * flatness(vocalise(0.3, 0.0, 0.5, rng))
    assert happy.dtype == np.int16 and np.max(np.abs(happy)) <= 0.5 * 32767 + 1


# -- switches ---------------------------------------------------------------------------------
def test_config_commands_toggle_the_mdk_letters_and_typos_are_refused():
    assert config_command('ping') is None
    assert config_command('fv') == 'voice' and config_command('fM') == 'salience_motion'
    assert letters_on(FlagParams()) == 'vtrnscudMSFBThaHm'
    assert letters_on(FlagParams(voice=False, tail=False)) == 'trnscudMSFBhaHm'
    for bad in ('fz', 'f', 'hello', 'fvv', 'x' * 500):
        with pytest.raises(ValueError, match='expected') as err:
            config_command(bad)
        assert len(str(err.value)) < 200


def test_part_parameters_are_checked_in_one_line():
    for make, said in [(lambda: SleepParams(wake_at=0.9), 'wake_at < sleep_at'),
                       (lambda: SpatialParams(quiet_db=-10.0), 'quiet_db < loud_db'),
                       (lambda: ExpressParams(voice_via='radio'), 'stream or tone'),
                       (lambda: ActionParams(orient_min_s=5.0), 'orient_min_s <= orient_max_s'),
                       (lambda: AffectParams(hit_pads=99), 'hit_pads must be in')]:
        with pytest.raises(ValueError, match=said):
            make()
    assert Config().with_part(SleepParams(fast_sleep=True)).sleep.fast_sleep


# -- the whole animal, percepts made by hand ---------------------------------------------------
KC = KinematicChain(KIN_CALIB_RAD)


def ball_at(x, y):
    """What each eye sees of the ball at (x, y) m from MiRo (body frame, head at rest)."""
    seen = []
    for camera, frame in zip(DEFAULT_CAMERAS, (CAML, CAMR)):
        pixel = camera.point_to_pixel(KC, frame, (x, y, 0.1))
        edge = camera.point_to_pixel(KC, frame, (x, y + 0.1, 0.1))
        if pixel is None or edge is None or not camera.in_frame(*pixel):
            seen.append(None)
            continue
        (u, v), w = pixel, camera.width
        seen.append(Ball(u / w - 0.5, (camera.height / 2 - v) / w, abs(edge[0] - u) / w))
    return seen


def percepts(t, balls=(None, None), **more):
    eyes = tuple(Eye(camera, None, {'ball': ball})
                 for camera, ball in zip(DEFAULT_CAMERAS, balls))
    return Percepts(t, eyes, sonar=1.0, light=(0.5,) * 4, **more)


def test_a_ball_ahead_is_approached_and_a_rolling_one_does_not_make_it_dither():
    animal = Animal()
    ahead = ball_at(0.8, 0.0)
    assert all(ahead)
    acts = [animal.act(percepts(i * DT, ahead)) for i in range(50)]
    assert acts[-1].state == 'approach'
    assert all(min(a.wheels) > 0.1 and abs(a.wheels[0] - a.wheels[1]) < 0.05
               for a in acts[10:])  # straight at it
    # A ball rolling across in front and back, for a minute: two switches a second at most.
    animal, chosen = Animal(seed=4), []
    for i in range(int(60 / DT)):
        balls = ball_at(0.7, 1.2 * math.sin(2 * math.pi * i * DT / 7.0))
        chosen.append(animal.act(percepts(i * DT, balls)).state)
    flips = [i for i, (a, b) in enumerate(zip(chosen, chosen[1:])) if a != b]
    for start in range(0, len(chosen), 50):
        assert sum(start <= i < start + 50 for i in flips) <= 2
    assert len(set(chosen)) >= 2


def test_a_sight_from_an_older_frame_is_placed_from_where_head_and_body_were_then():
    """Issue 48: the face detector looks at one frame in six; what it found 0.4 s ago, with
    the head then at rest, was placed from the head's pose now (turned 0.5 rad left), so it
    landed 0.5 rad further left, while the body's own turn since was not taken off either:
    orient chased it past the face."""
    senses, motion = Senses(SpatialParams(), ActionParams()), OwnMotion()
    ball = ball_at(0.5, 0.4)[0]  # the left eye's, with the head at rest
    then = percepts(0.0, (ball, None))
    motion.tick(0.0, KIN_CALIB_RAD)
    fresh = senses.sights(then, include_motion=False, motion=motion)[0].azimuth
    assert fresh == pytest.approx(math.atan2(0.4, 0.5), abs=0.1)
    turning = list(KIN_CALIB_RAD)
    for i in range(1, 21):  # 0.4 s turning left at 1 rad/s, the head yawing left
        motion.told(1.0)
        turning[YAW] = 0.025 * i
        motion.tick(i * DT, turning)
    eyes = (Eye(DEFAULT_CAMERAS[0], None, {'ball': ball}, 0.4, {'ball': 0.0}), then.eyes[1])
    now = Percepts(0.4, eyes, joints=tuple(turning))
    placed = senses.sights(now, include_motion=False, motion=motion)[0].azimuth
    assert placed == pytest.approx(fresh - 0.4, abs=1e-6)
    # From the head's pose now, as before: over 0.8 rad off, the wrong way.
    assert senses.sights(now, include_motion=False)[0].azimuth > fresh + 0.4
    # A stamp of another clock, or older than what is kept: the pose now is all there is.
    assert motion.then(0.4 + 1e9) is None and motion.then(-KEEP_S) is None
    assert motion.then(0.0).turned == pytest.approx(0.4)


def test_asleep_the_wheels_stop_and_the_head_hangs():
    animal = Animal(Config().with_part(SleepParams(fast_sleep=True)))
    t = 0.0
    while not animal.asleep:
        t += DT
        action = animal.act(percepts(t))
        assert t < 180
    for _ in range(200):
        t += DT
        action = animal.act(percepts(t))
    assert action.wheels == (0.0, 0.0)
    assert action.cosmetic[2] >= 0.8 and action.head[1] > math.radians(50)
    assert animal.priorities and len(animal.priorities) == len(ACTIONS)


def test_every_parameter_is_in_the_docs_and_a_part_can_be_replaced():
    from pathlib import Path

    from miro_ball.animal.params import PART_PARAMS
    from miro_ball.common.ros_params import table
    from miro_ball.controller.behaviour import BehaviourParams
    from miro_ball.controller.controllers import make_controller

    text = (Path(__file__).resolve().parent.parent / 'docs' / 'demo_mode.md').read_text()
    # Each by its full (dotted) name; the detectors' own are the controller's
    # (docs/controller.md).
    missing = [name for name, _, _ in table(AnimalNodeParams, *PART_PARAMS)
               if f'`{name}`' not in text]
    assert not missing
    # The docs' own example selector, as -p selector:= names it: it dithers where the basal
    # ganglia hold one action.
    greedy = Animal(selector='miro_ball.examples.selector_greedy:Greedy')
    assert greedy.act(percepts(0.0, ball_at(0.8, 0.0))).state
    close = [[0.5 + 0.01 * (-1) ** i, 0.5 - 0.01 * (-1) ** i] for i in range(100)]
    picks = [greedy.selector.select(i * DT, each) for i, each in enumerate(close)]
    assert sum(a != b for a, b in zip(picks, picks[1:])) == 99
    # The whole animal as a mode of kick_blue_ball, which has none of demo mode's
    # parameters: refused in one line, never run on defaults nobody chose.
    with pytest.raises(ValueError, match='python -m miro_ball.animal') as refused:
        make_controller('miro_ball.animal.animal:Animal', BehaviourParams())
    assert '\n' not in str(refused.value)


def test_reflexes_have_the_last_word_a_drop_backs_it_off_a_wall_slows_it():
    animal = Animal()
    ahead = ball_at(0.8, 0.0)
    for i in range(30):  # approaching the ball
        wheels = animal.act(percepts(i * DT, ahead)).wheels
    assert min(wheels) > 0.1
    left, right = animal.act(percepts(0.62, ahead, cliff=(0.2, 1.0))).wheels
    assert left + right < 0 and left > right  # backs off, turning right: away from the drop
    near = Percepts(0.64, percepts(0.64, ahead).eyes, sonar=0.12, light=(0.5,) * 4)
    slowed = animal.act(near).wheels
    assert 0 <= sum(slowed) / 2 < 0.25 * sum(wheels) / 2 + 1e-6
    stopped = Animal(Config().with_part(FlagParams(translation=False, rotation=False)))
    assert stopped.act(percepts(0.0, ahead)).wheels == (0.0, 0.0)

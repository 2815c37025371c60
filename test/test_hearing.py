"""MiRo's ears in the simulated world (no ROS): what three MiRos on an empty floor hear of
each other's speakers and of a world's sounds, block by block, and where the direction
library says a sound comes from."""
import dataclasses
import math

import numpy as np
import pytest

from miro_ball.miro.constants import (KIN_CALIB_RAD, MIC_BLOCK_SAMPLES, MIC_L, MIC_R,
                                      MIC_SAMPLE_RATE_HZ, SPEAKER_SAMPLE_RATE_HZ, YAW)
from miro_ball.miro.hearing import level_db, locate, mic_window
from miro_sim_bullet.physics import model as rb
from miro_sim_bullet.physics.world import SimWorld
from miro_sim_bullet.scene.sounds import bundled_sound, Sound
from miro_sim_bullet.scene.world_file import load_world
from miro_sim_bullet.scene.world_model import RobotSpec

FS = MIC_SAMPLE_RATE_HZ
EMPTY = dataclasses.replace(load_world('empty'), ball=None)
# a speaks; b listens 1 m in front of it, c 3 m, both facing it: the acceptance scene.
THREE = dataclasses.replace(EMPTY, robots=(RobotSpec('a', (0.0, 0.0, 0.0)),
                                           RobotSpec('b', (1.0, 0.0, math.pi)),
                                           RobotSpec('c', (3.0, 0.3, math.pi))))


def hear(world, seconds):
    """{robot: (4, samples) of full scale} heard over the next ``seconds``; the blocks
    follow each other with no gap, 40 a simulated second."""
    first = world.acoustics.next_block
    heard = world.listen(seconds)
    for blocks in heard.values():
        assert [block.index for block in blocks] == list(range(first, first + len(blocks)))
        assert abs(len(blocks) - seconds * 40) <= 1
    return {name: mic_window(np.concatenate([block.samples for block in blocks], axis=1))
            for name, blocks in heard.items()}


def band_db(signal, low, high):
    """Level (dB of full scale) of the part of ``signal`` between low and high Hz."""
    spectrum = np.fft.rfft(signal * np.hanning(len(signal)))
    freqs = np.fft.rfftfreq(len(signal), 1 / FS)
    power = np.abs(spectrum) ** 2
    return 10 * math.log10(power[(freqs >= low) & (freqs <= high)].sum() / power.sum()
                           + 1e-30) + level_db(signal)


@pytest.fixture(scope='module')
def three():
    world = SimWorld(THREE)
    world.run(0.3)  # settled on the floor
    yield world
    world.close()


def test_a_tone_from_one_miro_is_heard_by_another_1_m_away_far_above_silence_and_clean(three):
    silence = hear(three, 0.5)['b']
    three.robots['a'].play_tone(1000, 255, 50)  # 1 s
    heard = hear(three, 0.5)['b']
    for mic in range(4):
        assert level_db(heard[mic]) - level_db(silence[mic]) >= 20
        # Clean: the tone's band holds all but a thousandth of the power.
        assert band_db(heard[mic], 950, 1050) - level_db(heard[mic]) > -0.01
    spectrum = np.abs(np.fft.rfft(heard[MIC_L] * np.hanning(heard.shape[1])))
    assert np.fft.rfftfreq(heard.shape[1], 1 / FS)[np.argmax(spectrum)] == pytest.approx(1000, abs=5)
    hear(three, 0.5)  # the tone ends


def test_a_sound_3_m_away_is_about_9_5_db_below_the_same_sound_1_m_away(three):
    three.robots['a'].play_tone(600, 200, 25)
    heard = hear(three, 0.5)
    near = np.mean([level_db(heard['b'][mic]) for mic in range(4)])
    far = np.mean([level_db(heard['c'][mic]) for mic in range(4)])
    assert near - far == pytest.approx(20 * math.log10(3), abs=1.0)


def test_what_a_miro_streams_is_what_another_hears(three):
    rng = np.random.default_rng(3)
    sent = (rng.standard_normal(SPEAKER_SAMPLE_RATE_HZ) * 6000).astype(np.int16)  # 1 s
    assert three.robots['a'].stream(sent) == 0
    heard = hear(three, 1.5)['b'][MIC_L]
    # The sent samples at the microphones' rate (what the speaker plays), against what b's
    # left ear heard: one clear peak of correlation at the delay of the speaker and the air.
    up = np.interp(np.arange(int(1.0 * FS)) * SPEAKER_SAMPLE_RATE_HZ / FS,
                   np.arange(len(sent)), sent.astype(float))
    scores = [np.corrcoef(up, heard[lag:lag + len(up)])[0, 1] for lag in range(0, 400)]
    assert max(scores) > 0.9
    # Late by the speaker's filter (1.5 ms) and the air (1 m: 2.9 ms).
    assert 0.003 * FS < np.argmax(scores) < 0.006 * FS


def test_noise_from_the_left_reaches_the_left_ear_first_and_louder_less_so_facing_it():
    sound = Sound('radio', (0.0, 1.5, 0.3), 'noise', -30.0)
    world = SimWorld(dataclasses.replace(EMPTY, sounds=(sound,)))
    try:
        world.run(0.3)
        ears = hear(world, 0.5)[world.robot.name]
        lead = locate(ears).lags[0]  # samples the right ear hears it after the left
        assert 3 <= lead <= 9
        assert level_db(ears[MIC_L]) - level_db(ears[MIC_R]) >= 1
        turned = list(KIN_CALIB_RAD)
        turned[YAW] = math.radians(55)  # the head turned to the left, towards it
        world.robot.set_kinematic_targets(turned)
        world.run(1.0)
        ears = hear(world, 0.5)[world.robot.name]
        assert 0 < locate(ears).lags[0] < lead - 1
    finally:
        world.close()


def test_a_short_sound_is_heard_once_not_again_a_ring_later(three):
    """A quarter-second chirp from a's speaker: b hears it, then nothing but its own noise
    floor for the next two seconds (the ring's old samples came back 0.82 s later once)."""
    three.robots['a'].speaker.append(
        (8000 * np.sin(np.arange(2000) * 2 * np.pi * 600 / 8000)).astype(np.int16))
    ears = hear(three, 2.5)['b']
    levels = [max(level_db(channel) for channel in ears[:, i:i + MIC_BLOCK_SAMPLES])
              for i in range(0, ears.shape[1], MIC_BLOCK_SAMPLES)]
    loud = [i for i, level in enumerate(levels) if level > -50]
    assert loud and max(loud) - min(loud) <= 12, levels  # 0.25 s and the way: ~11 blocks
    assert all(level < -55 for level in levels[max(loud) + 2:]), levels


TUNE = str(bundled_sound('radio_tune.ogg'))


@pytest.mark.parametrize('distance, kind', [(1.0, 'noise'), (3.0, 'noise'), (2.0, 'file')])
def test_the_direction_library_finds_a_sound_within_15_degrees(distance, kind):
    angles = (0, 60, 90, 150, 180, -120, -90)  # in front, to the sides, behind
    for angle in angles:
        a = math.radians(angle)
        sound = Sound('s', (distance * math.cos(a), distance * math.sin(a), 0.3), kind, -35.0,
                      file=TUNE if kind == 'file' else '', loop=kind == 'file')
        world = SimWorld(dataclasses.replace(EMPTY, sounds=(sound,)))
        try:
            world.run(0.2)
            found = locate(hear(world, 0.1)[world.robot.name])
            head, rotation = world.robot.link_frame(rb.HEAD)
            x, y, _ = rotation.T @ (np.array(sound.position) - head)
            error = (found.azimuth - math.atan2(y, x) + math.pi) % (2 * math.pi) - math.pi
            assert abs(math.degrees(error)) < 15, angle
        finally:
            world.close()


def test_the_same_world_gives_the_same_samples_and_a_moving_speaker_no_clicks():
    def run():
        world = SimWorld(THREE)
        try:
            world.robots['a'].play_tone(500, 255, 100)
            world.robots['a'].set_cmd_vel(0.3, 1.0)  # driving in a circle while it sounds
            return hear(world, 1.0)['b']
        finally:
            world.close()

    first, second = run(), run()
    assert np.array_equal(first, second)
    # A 500 Hz tone changes by at most 2 pi 500 / 20000 of its amplitude a sample; a jump
    # (a click where two blocks meet) would change it by far more.
    tone = first[MIC_L, int(0.1 * FS):int(0.9 * FS)]
    amplitude = np.max(np.abs(tone))
    assert np.max(np.abs(np.diff(tone))) < 1.3 * amplitude * 2 * math.pi * 500 / FS


def test_blocks_are_heard_only_for_robots_someone_listens_to_and_stay_aligned(three):
    heard = three.listen(0.1, listening=['c'])
    assert set(heard) == {'c'}
    assert all(block.samples.shape == (4, MIC_BLOCK_SAMPLES) for block in heard['c'])
    # Block k covers samples 500 k .. 500 k + 499 of simulated time, whoever listens: the
    # last is the one that ended at the last platform tick.
    assert heard['c'][-1].index == int(three.time * MIC_SAMPLE_RATE_HZ) // MIC_BLOCK_SAMPLES - 1


def test_echoes_and_wheels_are_heard_when_the_world_asks_for_them():
    """The ground's echo (and the walls', in a room) adds to what a microphone hears, a few
    samples after the sound itself; turning wheels whirr."""
    from miro_sim_bullet.scene.sounds import Hearing

    sound = Sound('s', (2.0, 0.0, 0.3), 'noise', -30.0)

    def heard(hearing, sounds=(sound,), drive=False):
        world = SimWorld(dataclasses.replace(EMPTY, sounds=sounds, hearing=hearing))
        try:
            world.run(0.3)
            if drive:
                world.robot.set_cmd_vel(0.3, 0.0)
                world.run(0.3)
            return hear(world, 0.5)[world.robot.name][MIC_L]
        finally:
            world.close()

    free = heard(Hearing())
    echoed = heard(Hearing(reflections=True, absorption=0.2,
                           room=(-3.0, -3.0, 3.0, 3.0, 2.5)))
    assert level_db(echoed) > level_db(free) + 1.0
    # The ground's echo: its path 2 * 0.3 m higher through the floor, ~6 samples later; the
    # echo shows as a second peak in what was heard, after the first.
    correlation = [float(np.dot(echoed[:-20], echoed[k:len(echoed) - 20 + k]))
                   for k in range(20)]
    assert max(correlation[3:12]) > 0.15 * correlation[0]
    wheels = Hearing(wheel_noise=True)
    assert level_db(heard(wheels, (), drive=True)) > level_db(heard(wheels, ())) + 6

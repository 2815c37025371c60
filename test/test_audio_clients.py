"""The audio clients against the simulator, in simulated time (the test steps the world):
each does what its --help promises."""
import math

import numpy as np
import pytest
import soundfile

from miro_ball.examples import client_audio, client_drive_voice, client_hear, client_stream
from miro_ball.miro.constants import MIC_SAMPLE_RATE_HZ
from miro_ball.miro.interface import default_robot_name
from miro_sim_bullet.scene.sounds import Sound
from test_clients import run_client

NAME = default_robot_name()


def place_sound(sim, bearing_deg, distance, level=-30.0):
    """A hiss at ``bearing_deg`` from where the robot faces, ``distance`` away."""
    x, y, yaw = sim.sim.robots[NAME].pose()
    a = yaw + math.radians(bearing_deg)
    sim.sim.acoustics.add_sound(Sound('voice', (x + distance * math.cos(a),
                                                y + distance * math.sin(a), 0.3),
                                      'noise', level))


def test_client_hear_says_where_a_sound_is_and_how_loud(paused_sim, executor, ros_context,
                                                        capsys):
    place_sound(paused_sim, 70, 1.5)
    code = run_client(client_hear, ['--count', '2', '--every', '0.5'], paused_sim, executor,
                      ros_context, limit_s=3.0)
    lines = [line for line in capsys.readouterr().out.splitlines() if 'azimuth' in line]
    assert code == 0 and len(lines) == 2, lines
    azimuth = float(lines[-1].split('azimuth ')[1].split(' deg')[0])
    assert abs(azimuth - 70) < 15 and ' deg left' in lines[-1]
    assert -45 < float(lines[-1].split('), ')[1].split(' dB')[0]) < -25


def test_client_audio_records_the_four_microphones_hearing_its_own_tone(
        paused_sim, executor, ros_context, capsys, tmp_path):
    out = tmp_path / 'mics.wav'
    code = run_client(client_audio, ['--seconds', '1', '--out', str(out), '--tone', '500'],
                      paused_sim, executor, ros_context, limit_s=3.0)
    assert code == 0 and f'wrote {out}' in capsys.readouterr().out
    samples, rate = soundfile.read(str(out))
    assert rate == MIC_SAMPLE_RATE_HZ and samples.shape == (MIC_SAMPLE_RATE_HZ, 4)
    late = samples[MIC_SAMPLE_RATE_HZ // 2:, 0]  # the tone is on by then
    peak = np.fft.rfftfreq(len(late), 1 / rate)[np.argmax(np.abs(np.fft.rfft(late)))]
    assert peak == pytest.approx(500, abs=4)


def test_client_stream_keeps_the_speaker_fed_without_dropping_a_sample(
        paused_sim, executor, ros_context, capsys):
    speaker = paused_sim.sim.robots[NAME].speaker
    code = run_client(client_stream, ['--ahead', '0.3'], paused_sim, executor, ros_context,
                      limit_s=4.0)
    assert code == 0 and 'done' in capsys.readouterr().out
    assert speaker.dropped == 0 and speaker.buffered == 0


def test_client_stream_refuses_a_file_that_is_not_sound(tmp_path, capsys):
    bad = tmp_path / 'notes.txt'
    bad.write_text('la la la')
    with pytest.raises(SystemExit) as done:
        client_stream.main(['client_stream', '--file', str(bad)])
    assert done.value.code == 2
    err = capsys.readouterr().err
    assert 'Traceback' not in err
    assert err.strip().splitlines()[-1] == (f'client_stream: error: {bad}: cannot read it as '
                                            'sound (WAV, FLAC, OGG, ...)')


def test_client_drive_voice_turns_to_a_voice_and_comes_closer(paused_sim, executor,
                                                              ros_context):
    robot = paused_sim.sim.robots[NAME]
    place_sound(paused_sim, 90, 1.2, level=-25.0)
    source = paused_sim.sim.acoustics.source_positions()['voice']
    x0, y0, yaw0 = robot.pose()
    before = math.dist((x0, y0), source[:2])
    code = run_client(client_drive_voice, ['--seconds', '4'], paused_sim, executor,
                      ros_context, limit_s=6.0)
    x, y, yaw = robot.pose()
    assert code == 0
    assert math.dist((x, y), source[:2]) < before - 0.2
    bearing = math.atan2(source[1] - y, source[0] - x) - yaw
    assert abs(math.remainder(bearing, 2 * math.pi)) < math.radians(30)

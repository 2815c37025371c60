"""Sound files: only from the allowed folders, only regular files with a sane header, their
samples finite, held compactly and bounded in all; a refused file leaves nothing behind."""
import os
import re
import struct
import threading
import time
from pathlib import Path

import numpy as np
import pytest

from miro_ball.common.files import folders_parameter
from miro_sim_bullet.acoustics.hearing import Acoustics
from miro_sim_bullet.acoustics.loading import SoundLoads
from miro_sim_bullet.acoustics.sound_files import SoundBank, SoundFileError
from miro_sim_bullet.scene.sounds import MAX_SOUNDS, Sound
from miro_sim_bullet.scene.world_checks import load_sounds
from miro_sim_bullet.scene.world_file import load_world
from miro_sim_bullet.scene.world_model import WorldError


def wav(path, seconds=0.1, rate=8000, samples=None, subtype='PCM_16'):
    import soundfile
    data = np.sin(np.arange(int(seconds * rate)) * 0.3) * 0.5 if samples is None else samples
    soundfile.write(str(path), data, rate, subtype=subtype)
    return path


def with_rate(path, rate):
    """A WAV whose header says ``rate`` samples a second (fields at bytes 24 and 28)."""
    data = bytearray(path.read_bytes())
    data[24:32] = struct.pack('<II', rate, min(rate * 2, 2**32 - 1))
    path.write_bytes(bytes(data))
    return path


def finishes(call):
    """Whether call() returns (or raises) within a guard's time: a FIFO opened for reading
    would wait for a writer for ever. Returns what it raised, or None."""
    import threading

    outcome = []

    def run():
        try:
            call()
            outcome.append(None)
        except Exception as err:  # noqa: BLE001 -- handed to the test to look at
            outcome.append(err)
    thread = threading.Thread(target=run, daemon=True)
    thread.start()
    thread.join(HANG_GUARD_S)
    assert outcome, f'{call} blocked'
    return outcome[0]


HANG_GUARD_S = 10.0


def request(file, folders=()):
    return load_sounds(f'[[sound]]\nfile = "{file}"\n', '/miro_sim/sound', folders)


@pytest.fixture
def outside(tmp_path):
    """A readable sound file in a folder nobody allowed."""
    folder = tmp_path / 'private'
    folder.mkdir()
    return wav(folder / 'secret.wav')


@pytest.fixture
def allowed(tmp_path):
    folder = tmp_path / 'sounds'
    folder.mkdir()
    return folders_parameter('sound_folders', str(folder))


def test_a_request_plays_bundled_sounds_and_files_of_the_allowed_folders(allowed):
    wav(allowed[0] / 'beep.wav')
    (allowed[0] / 'sub').mkdir()
    wav(allowed[0] / 'sub' / 'deep.wav')
    assert request('radio_tune.ogg')[0].file.endswith('radio_tune.ogg')
    assert request('beep.wav', allowed)[0].file == str(allowed[0] / 'beep.wav')
    assert request('sub/deep.wav', allowed)[0].file == str(allowed[0] / 'sub' / 'deep.wav')
    assert request(str(allowed[0] / 'beep.wav'), allowed)[0].file == str(allowed[0] / 'beep.wav')


def test_a_request_for_a_file_outside_the_allowed_folders_is_refused_in_one_line(
        outside, allowed, tmp_path):
    link = allowed[0] / 'link.wav'
    link.symlink_to(outside)
    for name in (str(outside), '../private/secret.wav', 'link.wav', 'secret.wav',
                 '/etc/passwd', '~/.bashrc'):
        with pytest.raises(WorldError, match='no sound file .* in the allowed folders') as err:
            request(name, allowed)
        assert '\n' not in str(err.value)
    with pytest.raises(WorldError, match='no sound file'):
        request(str(outside))  # no folders given: bundled sounds only


@pytest.mark.parametrize('special', ['fifo', 'folder', '/dev/stdin', '/dev/zero'])
def test_a_fifo_a_device_or_a_folder_is_never_opened(allowed, special):
    if special == 'fifo':
        os.mkfifo(allowed[0] / 'pipe.wav')
        name, match = 'pipe.wav', 'not a regular file'
    elif special == 'folder':
        (allowed[0] / 'dir.wav').mkdir()
        name, match = 'dir.wav', 'not a regular file'
    else:
        name, match = special, 'no sound file'  # outside every folder
    refused = finishes(lambda: request(name, allowed))
    assert isinstance(refused, WorldError) and re.search(match, str(refused)), refused


@pytest.mark.parametrize('rate', [2147483647, 999983, 4000, 200000])
def test_a_header_with_an_absurd_sample_rate_is_refused_before_a_sample_is_read(
        allowed, rate):
    with_rate(wav(allowed[0] / 'odd.wav'), rate)
    with pytest.raises(WorldError, match=f'says {rate} samples a second; .* 8000..192000 Hz'):
        request('odd.wav', allowed)


def test_a_world_file_takes_sounds_beside_it_and_refuses_them_elsewhere(tmp_path, outside):
    world_dir = tmp_path / 'world'
    world_dir.mkdir()
    wav(world_dir / 'mine.wav')
    toml = world_dir / 'w.toml'
    toml.write_text('[[sound]]\nfile = "mine.wav"\n')
    assert load_world(str(toml)).sounds[0].file == str(world_dir / 'mine.wav')
    toml.write_text(f'[[sound]]\nfile = "{outside}"\n')
    with pytest.raises(WorldError, match='no sound file'):
        load_world(str(toml))
    assert load_world(str(toml), folders_parameter('sound_folders', str(outside.parent))).sounds


def test_the_sound_folders_parameter_must_name_folders():
    with pytest.raises(ValueError, match="parameter sound_folders: '/no/such' is not a folder"):
        folders_parameter('sound_folders', '/no/such')
    assert folders_parameter('sound_folders', '') == ()


def test_a_file_of_nan_samples_is_refused_not_played_as_silence(allowed):
    wav(allowed[0] / 'nan.wav', samples=np.full(800, np.nan), subtype='FLOAT')
    sound, = request('nan.wav', allowed)
    with pytest.raises(SoundFileError, match='not numbers'):
        SoundBank().samples(sound.file)


def test_samples_are_float32_at_20_khz_and_one_copy_is_shared(allowed):
    sound, = request(str(wav(allowed[0] / 'long.wav', seconds=2.0, rate=44100)), allowed)
    bank = SoundBank()
    first, second = bank.samples(sound.file), bank.samples(sound.file)
    assert first is second and first.dtype == np.float32
    assert len(first) == pytest.approx(40000, abs=2)  # 2 s at 20 kHz, however it was stored
    assert bank.held_bytes() == first.nbytes
    del first, second
    assert bank.held_bytes() == 0  # nothing plays it: gone


def test_files_past_the_memory_bound_are_refused_in_one_line(allowed):
    bank = SoundBank(limit_bytes=300_000)  # room for one 2 s file (160 kB), not two
    one = wav(allowed[0] / 'one.wav', seconds=2.0)
    two = wav(allowed[0] / 'two.wav', seconds=2.0)
    kept = bank.samples(str(one))
    with pytest.raises(SoundFileError, match='would need 0 MB; the sound files playing hold '
                                             '0 MB of at most 0 MB'):
        bank.samples(str(two))
    del kept
    assert bank.samples(str(two)) is not None  # the first no longer plays: room again


def test_forty_failed_files_leave_every_slot_free_and_a_tone_still_plays(allowed):
    broken = allowed[0] / 'broken.wav'
    broken.write_bytes(b'fLaC' + bytes(38))  # a header and nothing more
    world = Acoustics({})
    for index in range(40):
        with pytest.raises(ValueError):
            world.add_sound(Sound(f'bad{index}', (0, 0, 0), 'file', -20.0, file=str(broken)))
    world.add_sound(Sound('tone', (0, 0, 0), 'tone', -20.0, frequency=440.0))
    for index in range(MAX_SOUNDS - 1):
        world.add_sound(Sound(f'more{index}', (0, 0, 0), 'noise', -20.0))
    assert len(world.sounds) == MAX_SOUNDS


class Clock:
    now = 0.0

    def __call__(self):
        return self.now


def wait_ready(loads):
    deadline = time.monotonic() + 20
    while time.monotonic() < deadline:
        done = loads.ready()
        if done:
            return done
        time.sleep(0.01)  # the reading thread's own time: the wait's result is asserted
    raise AssertionError('the file was not read')


def test_files_are_read_off_the_callers_thread_and_a_slow_read_is_given_up(allowed):
    clock = Clock()
    path = wav(allowed[0] / 'ok.wav')
    loads = SoundLoads(bank=SoundBank(), clock=clock, timeout_s=10.0, max_pending=2)
    loads.ask(Sound('ok', (0, 0, 0), 'file', -20.0, file=str(path)))
    (sound, samples, error), = wait_ready(loads)
    assert sound.name == 'ok' and error is None and samples.dtype == np.float32

    release = threading.Event()

    class Stuck(SoundBank):
        def samples(self, path):
            release.wait()
            raise SoundFileError('never')
    loads = SoundLoads(bank=Stuck(), clock=clock, timeout_s=10.0, max_pending=2)
    for name in ('a', 'b'):
        loads.ask(Sound(name, (0, 0, 0), 'file', -20.0, file=str(path)))
    with pytest.raises(SoundFileError, match='2 sound files are being read already'):
        loads.ask(Sound('c', (0, 0, 0), 'file', -20.0, file=str(path)))
    clock.now = 11.0
    given_up = loads.ready()
    assert [(s.name, str(e)) for s, _, e in given_up] == [
        (name, "'ok.wav' was not read within 10 s: given up") for name in ('a', 'b')]
    assert loads.pending == 0
    release.set()



@pytest.mark.parametrize('loop', [False, True])
def test_a_file_plays_at_40_khz_as_the_whole_file_resampled_at_once(allowed, loop):
    """Held at 20 kHz, doubled tick by tick as it plays: the same samples as scipy's
    resample_poly of the whole file (what was held before, at four times the memory)."""
    from scipy.signal import resample_poly

    from miro_sim_bullet.acoustics.sources import WorldSource

    path = wav(allowed[0] / 'tune.wav', seconds=0.5, rate=20000)
    source = WorldSource(Sound('s', (0, 0, 0), 'file', 0.0, file=str(path), loop=loop), (0,))
    ticks = [source.emit(n0, 800) for n0 in range(0, 800 * 30, 800)]
    played = np.concatenate([np.zeros(800) if tick is None else tick for tick in ticks])
    whole = resample_poly(SoundBank().samples(str(path)).astype(np.float64), 2, 1)
    assert np.abs(played[:len(whole)] - whole).max() < 1e-9 if not loop else \
        np.abs(played[100:len(whole) - 100] - whole[100:-100]).max() < 1e-9
    if loop:  # and on again from its start
        assert np.abs(played[len(whole) + 100:len(whole) + 900] - whole[100:900]).max() < 1e-6


@pytest.mark.parametrize('swapped_in', ['fifo', 'link'])
def test_a_file_swapped_after_the_checks_is_refused_not_waited_on(allowed, outside,
                                                                   swapped_in):
    """A FIFO renamed over a checked file blocked the simulator's open for ever."""
    from miro_ball.common.files import open_regular

    path = allowed[0] / 'race.wav'
    if swapped_in == 'fifo':
        os.mkfifo(path)
    else:
        path.symlink_to(outside)
    assert isinstance(finishes(lambda: open_regular(path)), OSError)
    assert isinstance(finishes(lambda: SoundBank().samples(str(path))), SoundFileError)


def test_a_file_of_too_many_frames_is_refused_by_its_header(allowed, monkeypatch):
    from miro_sim_bullet.scene import sounds

    monkeypatch.setattr(sounds, 'MAX_FRAMES', 100)
    wav(allowed[0] / 'long.wav')  # 800 frames
    with pytest.raises(WorldError, match="'long.wav' holds 800 frames; at most 100"):
        request('long.wav', allowed)


def test_files_given_up_are_not_read_later_and_do_not_fill_the_queue(allowed):
    clock = Clock()
    paths = {name: wav(allowed[0] / f'{name}.wav') for name in 'abc'}
    read, release = [], threading.Event()

    class Slow(SoundBank):
        def samples(self, path):
            read.append(Path(path).stem)
            release.wait()  # 'a' is held here while both are given up
            return super().samples(path)
    loads = SoundLoads(bank=Slow(), clock=clock, timeout_s=1.0, max_pending=3)
    for name in 'ab':
        loads.ask(Sound(name, (0, 0, 0), 'file', -20.0, file=str(paths[name])))
    clock.now = 2.0
    assert len(loads.ready()) == 2  # both given up, 'b' still queued behind 'a'
    release.set()
    loads.ask(Sound('c', (0, 0, 0), 'file', -20.0, file=str(paths['c'])))
    (sound, samples, error), = wait_ready(loads)
    assert sound.name == 'c' and error is None
    assert 'b' not in read and read[-1] == 'c'  # 'a' perhaps: it may have been reading

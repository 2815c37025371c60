"""Sound files asked for while the world runs, decoded off the simulator's thread.

Reading a file takes from milliseconds to seconds, and whatever the file is, the simulator's
loop must not wait for it (a FIFO held it, deaf to Ctrl+C, until someone wrote to it; the
checks of scene.sounds now refuse such files, and this keeps even a slow disk off the loop).
The simulator's thread asks (``ask``) and, each tick, takes what is ready (``ready``); a
file not read within TIMEOUT_S is given up, and at most MAX_PENDING wait.
"""
import itertools
import queue
import threading
import time
from pathlib import Path

from miro_sim_bullet.acoustics.sound_files import BANK, SoundFileError

TIMEOUT_S = 10.0  # wall seconds a file may take to be read
MAX_PENDING = 8


class SoundLoads:
    """Files of scene.sounds.Sound decoded by one thread of their own (made at the first
    ask), into ``bank``; ``clock`` is the wall clock (time passed in: a test's own)."""

    def __init__(self, bank=BANK, clock=time.monotonic, timeout_s=TIMEOUT_S,
                 max_pending=MAX_PENDING):
        self.bank, self.clock = bank, clock
        self.timeout_s, self.max_pending = timeout_s, max_pending
        self._asked, self._done = queue.Queue(), queue.Queue()
        self._pending = {}  # ticket -> (sound, when asked)
        self._given_up = set()  # tickets the reading thread skips (one set.add: thread-safe)
        self._tickets = itertools.count()
        self._thread = None

    @property
    def pending(self):
        return len(self._pending)

    def ask(self, sound):
        """Read sound.file; SoundFileError (one line) when MAX_PENDING files wait already."""
        # The queue too: a file given up may still be waiting there.
        if max(len(self._pending), self._asked.qsize()) >= self.max_pending:
            raise SoundFileError(f'{self.max_pending} sound files are being read already: '
                                 f'{Path(sound.file).name!r} not read')
        if self._thread is None:
            # A daemon: a file still being read never holds the simulator's exit.
            self._thread = threading.Thread(target=self._work, name='sound-files', daemon=True)
            self._thread.start()
        ticket = next(self._tickets)
        self._pending[ticket] = (sound, self.clock())
        self._asked.put((ticket, sound.file))

    def ready(self):
        """[(sound, samples, error)] done since the last call, and those given up: the
        samples (the bank's copy, None with an error) stay alive while the caller holds
        them, so the sound's source finds them in the bank; error a SoundFileError."""
        out = []
        while True:
            try:
                ticket, samples, error = self._done.get_nowait()
            except queue.Empty:
                break
            if ticket in self._pending:
                out.append((self._pending.pop(ticket)[0], samples, error))
        now = self.clock()
        for ticket, (sound, asked) in list(self._pending.items()):
            if now - asked > self.timeout_s:
                del self._pending[ticket]
                self._given_up.add(ticket)
                out.append((sound, None, SoundFileError(
                    f'{Path(sound.file).name!r} was not read within {self.timeout_s:g} s: '
                    'given up')))
        return out

    def _work(self):
        while True:
            ticket, path = self._asked.get()
            if ticket in self._given_up:
                self._given_up.discard(ticket)
                continue
            samples = error = None
            try:
                samples = self.bank.samples(path)
            except SoundFileError as err:
                error = err
            except Exception as err:  # noqa: BLE001 -- this thread must outlive any file
                error = SoundFileError(f'cannot read {Path(path).name!r}: '
                                       f'{type(err).__name__}: {str(err)[:80]}')
            self._done.put((ticket, samples, error))
            del samples  # the queue holds it until the simulator's thread takes it

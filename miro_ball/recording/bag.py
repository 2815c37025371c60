"""A rosbag2 directory with MCAP storage and ROS 2 Jazzy types, written with `rosbags`.

An MCAP file is readable only once it is finished (its summary and footer are
written on close), so a recording that is killed, or runs out of disk, would
lose everything. Hence the bag is written in splits, as `ros2 bag record
--max-bag-duration` does: every `split_s` seconds the current file is finished
and metadata.yaml is rewritten (atomically) to list every finished file. A hard
stop loses at most the last split; what came before stays a valid bag.

The split in progress is written by rosbags' Writer in a hidden folder inside the
bag, `.unfinished/` (the Writer makes a fresh folder per bag), and moved up when
finished; metadata.yaml never lists it. So whatever stops the recorder, the bag
folder shows only finished files: after a SIGKILL before the first split it looks
empty, never like a bag. While it records, the recorder holds a lock on the bag
folder; the next recorder given the folder finds the lock free, and so knows an
`.unfinished/` there is a killed recorder's and removes it. A recording that ends
with nothing finished (a full disk in the first split) removes the folder it made.
"""
import fcntl
import os
import shutil
import time
from io import StringIO
from pathlib import Path

from rosbags.interfaces import Qos, QosDurability, QosHistory, QosLiveliness, \
    QosReliability, QosTime
from rosbags.rosbag2 import StoragePlugin, Writer
from ruamel.yaml import YAML

from miro_ball.common.definitions import typestore

TYPESTORE = typestore()  # ROS 2 Jazzy's types and miro2_msg's, when it is built
METADATA = 'metadata.yaml'
INFO = 'rosbag2_bagfile_information'
UNFINISHED = '.unfinished'  # the split being written: hidden, never listed


class BagError(ValueError):
    """The bag can not be created or written; the message says why."""


def offered_qos(reliable, transient_local, depth):
    """The QoS profile recorded with a topic, so `ros2 bag play` offers the same."""
    zero = QosTime(0, 0)
    return Qos(QosHistory.KEEP_LAST, depth,
               QosReliability.RELIABLE if reliable else QosReliability.BEST_EFFORT,
               QosDurability.TRANSIENT_LOCAL if transient_local else QosDurability.VOLATILE,
               zero, zero, QosLiveliness.AUTOMATIC, zero, False)


def _yaml():
    yaml = YAML(typ='safe')
    yaml.default_flow_style = False
    return yaml


def merge_metadata(parts):
    """One bag's metadata from the metadata of each of its files, in order."""
    info = dict(parts[0])
    files = [f for part in parts for f in part['files']]
    timed = [f for f in files if f['message_count']]
    start = min((f['starting_time']['nanoseconds_since_epoch'] for f in timed), default=0)
    end = max((f['starting_time']['nanoseconds_since_epoch'] + f['duration']['nanoseconds']
               for f in timed), default=0)
    topics = {}
    for part in parts:
        for entry in part['topics_with_message_count']:
            name = entry['topic_metadata']['name']
            if name in topics:
                topics[name]['message_count'] += entry['message_count']
            else:
                topics[name] = dict(entry)
    info.update(relative_file_paths=[f['path'] for f in files], files=files,
                starting_time={'nanoseconds_since_epoch': start},
                duration={'nanoseconds': end - start},
                message_count=sum(f['message_count'] for f in files),
                topics_with_message_count=list(topics.values()))
    return {INFO: info}


def describe(path, info):
    """Lines that say what the bag at path holds, from its metadata (None: nothing
    finished): a first line, then each topic's message count."""
    if info is None:
        return [f'{path}: nothing was finished: no bag written']
    counts = sorted((entry['topic_metadata']['name'], entry['message_count'])
                    for entry in info['topics_with_message_count'])
    start = info['starting_time']['nanoseconds_since_epoch'] * 1e-9
    end = start + info['duration']['nanoseconds'] * 1e-9
    span = f', t = {start:.1f} to {end:.1f} s simulated' if info['message_count'] else ''
    width = max((len(topic) for topic, _ in counts), default=0)
    return ([f'{path}: a readable bag of {len(info["files"])} file(s), '
             f'{info["message_count"]} messages on {len(counts)} topics{span}']
            + [f'  {topic:<{width}}  {n}' for topic, n in counts])


class SplitBag:
    """Writes messages (raw CDR bytes) into a new rosbag2 directory at `path`."""

    def __init__(self, path, split_s=10.0, clock=time.monotonic):
        self.path = Path(path)
        self.split_s = split_s
        self.clock = clock
        self.topics = {}  # topic -> (msgtype, offered qos)
        self.parts = []  # metadata of each finished file
        self.writer = None
        self.connections = {}
        self.created, self.lock = self._claim()
        try:
            self._open_split()
        except OSError as err:
            self.abort()
            raise BagError(f'can not write into {self.path}: {err.strerror}') from None

    def _claim(self):
        """Make the folder (or take an empty one) and lock it while we record: (whether
        we made it, the locked descriptor); BagError when it is taken."""
        if self.path.exists() and not self.path.is_dir():
            raise BagError(f'{self.path} exists already (and is not an empty folder)')
        created = not self.path.exists()
        try:
            self.path.mkdir(parents=True, exist_ok=True)
            lock = os.open(self.path, os.O_RDONLY)
        except OSError as err:
            raise BagError(f'can not create {self.path}: {err.strerror}') from None
        try:
            fcntl.flock(lock, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except OSError:
            os.close(lock)
            raise BagError(f'{self.path} is being recorded into by another recorder') from None
        shutil.rmtree(self.path / UNFINISHED, ignore_errors=True)  # a killed recorder's
        if any(self.path.iterdir()):
            os.close(lock)
            raise BagError(f'{self.path} exists already (and is not an empty folder)')
        return created, lock

    @property
    def split_index(self):
        return len(self.parts)

    def _split_dir(self):
        return self.path / UNFINISHED / f'{self.path.name}_{self.split_index}'

    def _open_split(self):
        self.writer = Writer(self._split_dir(), version=Writer.VERSION_LATEST,
                             storage_plugin=StoragePlugin.MCAP)
        self.writer.open()
        self.started = self.clock()
        self.written = 0
        self.connections = {}
        for topic in self.topics:
            self._connect(topic)

    def _connect(self, topic):
        msgtype, qos = self.topics[topic]
        self.connections[topic] = self.writer.add_connection(
            topic, msgtype, typestore=TYPESTORE, offered_qos_profiles=[qos])

    def add_topic(self, topic, msgtype, qos):
        """Start a topic; BagError when ROS 2 Jazzy has no such message type."""
        if msgtype not in TYPESTORE.fielddefs:
            raise BagError(f'{topic}: type {msgtype} is not a ROS 2 Jazzy message type')
        self.topics[topic] = (msgtype, qos)
        self._connect(topic)

    def write(self, topic, log_time_ns, data):
        """Store one message; OSError (a full disk) leaves the finished files readable."""
        self.writer.write(self.connections[topic], log_time_ns, data)
        self.written += 1

    def tick(self):
        """Finish the current file once it is split_s old and holds something."""
        if self.written and self.clock() - self.started >= self.split_s:
            self._finish_split()
            self._open_split()

    def _finish_split(self):
        """Close the file, then list it: the new metadata is written in full (hidden)
        before the file moves up and the metadata replaces the last one, so a full disk
        loses only this split and metadata.yaml never lists a file that is not there."""
        split_dir = self._split_dir()
        self.writer.close()
        self.writer = None
        parts = self.parts + [_yaml().load((split_dir / METADATA).read_text())[INFO]]
        text = StringIO()
        _yaml().dump(merge_metadata(parts), text)
        tmp = self.path / UNFINISHED / METADATA
        tmp.write_text(text.getvalue())
        (split_dir / f'{split_dir.name}.mcap').replace(self.path / f'{split_dir.name}.mcap')
        os.replace(tmp, self.path / METADATA)
        self.parts = parts
        shutil.rmtree(self.path / UNFINISHED)

    def contents(self):
        """The metadata of what the finished files hold; None when nothing was finished."""
        return merge_metadata(self.parts)[INFO] if self.parts else None

    def close(self):
        """Finish the last file (unless it is empty and not the only one) and the metadata;
        OSError (a full disk) as from write."""
        if self.writer is None:
            return
        if self.written or not self.parts:
            self._finish_split()
            self._release()
        else:
            self.abort()

    def abort(self):
        """Drop the unfinished file (after a write error): the finished ones stay a bag,
        and with none finished the folder we made goes too."""
        if self.writer is not None:
            self.writer.abort()
            self.writer = None
        shutil.rmtree(self.path / UNFINISHED, ignore_errors=True)
        if not self.parts and self.created:
            try:
                self.path.rmdir()
            except OSError:
                pass  # someone put something there: not ours to remove
        self._release()

    def _release(self):
        if self.lock is not None:
            os.close(self.lock)
            self.lock = None
